/* Transforms: the order scale -> rotate x -> rotate y -> rotate z -> translate on known
 * points, general angles against hand-written rotation matrices, and the winding
 * flip of mirroring maps (normals stay outward). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "scene/primitives.h"
#include "scene/transform.h"

static void assert_point(const double p[3], double x, double y, double z, double tol)
{
    assert_true(fabs(p[0] - x) < tol);
    assert_true(fabs(p[1] - y) < tol);
    assert_true(fabs(p[2] - z) < tol);
}

static void test_order(void **state)
{
    (void)state;
    const double s[3] = {2, 3, 4}, r[3] = {90, 90, 90}, t[3] = {1, 1, 1};
    scene_transform tf = transform_make(s, r, t);
    double p[3] = {1, 2, 3};
    transform_apply_point(&tf, p, p);
    /* scale (2, 6, 12); rx90 (2, -12, 6); ry90 (6, -12, -2); rz90 (12, 6, -2); +1 */
    assert_point(p, 13, 7, -1, 1e-12);

    /* each step alone */
    const double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    const double rx[3] = {90, 0, 0}, ry[3] = {0, 90, 0}, rz[3] = {0, 0, 90};
    double q[3] = {0, 1, 0};
    tf = transform_make(one, rx, zero);
    transform_apply_point(&tf, q, q);
    assert_point(q, 0, 0, 1, 1e-15); /* y -> z about x */
    double u[3] = {0, 0, 1};
    tf = transform_make(one, ry, zero);
    transform_apply_point(&tf, u, u);
    assert_point(u, 1, 0, 0, 1e-15); /* z -> x about y */
    double w[3] = {1, 0, 0};
    tf = transform_make(one, rz, zero);
    transform_apply_point(&tf, w, w);
    assert_point(w, 0, 1, 0, 1e-15); /* x -> y about z */
}

/* scene-format.md: multiples of 90 degrees are exact. Each angle (any whole turn added,
 * either sign) against its hand-written matrix, bit for bit: cos 90 deg in double is
 * 6e-17, not 0 (taking that branch out passed the 1e-15 tolerances above), and 180 and
 * 270 deg read as 0 and 90 (a quarter count taken mod 2) passed every test, whose
 * angles were 90 deg. */
static void test_quarter_turns_exact(void **state)
{
    (void)state;
    const double angles[] = {0, 90, 180, 270, -90, -180, 450, 720, -630};
    const double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
        long k = ((long)(angles[i] / 90) % 4 + 4) % 4; /* quarter turns, 0 .. 3 */
        const double c[4] = {1, 0, -1, 0}, s[4] = {0, 1, 0, -1};
        for (int axis = 0; axis < 3; axis++) {
            double r[3] = {0, 0, 0};
            r[axis] = angles[i];
            scene_transform tf = transform_make(one, r, zero);
            /* the axis after this one goes to c of itself + s of the one after it */
            int a = (axis + 1) % 3, b = (axis + 2) % 3;
            double p[3] = {0, 0, 0}, want[3] = {0, 0, 0};
            p[a] = 1.0;
            want[a] = c[k];
            want[b] = s[k];
            transform_apply_point(&tf, p, p);
            for (int j = 0; j < 3; j++)
                assert_true(p[j] == want[j]);
        }
    }
}

static void test_general_angles(void **state)
{
    (void)state;
    const double s[3] = {1.5, 0.5, 2}, r[3] = {30, -45, 100}, t[3] = {-1, 2, 0.5};
    scene_transform tf = transform_make(s, r, t);
    double p[3] = {0.3, -0.7, 1.1};
    double out[3];
    transform_apply_point(&tf, p, out);
    double x = 0.3 * 1.5, y = -0.7 * 0.5, z = 1.1 * 2;
    double a = 30 * M_PI / 180, b = -45 * M_PI / 180, c = 100 * M_PI / 180;
    double y1 = y * cos(a) - z * sin(a), z1 = y * sin(a) + z * cos(a);
    double x2 = x * cos(b) + z1 * sin(b), z2 = -x * sin(b) + z1 * cos(b);
    double x3 = x2 * cos(c) - y1 * sin(c), y3 = x2 * sin(c) + y1 * cos(c);
    assert_point(out, x3 - 1, y3 + 2, z2 + 0.5, 1e-12);
    assert_true(fabs(transform_determinant(&tf) - 1.5) < 1e-12);
}

static void test_mirror_flips_winding(void **state)
{
    (void)state;
    const double sizes[3] = {1, 2, 3};
    const double scales[][3] = {{-1, 1, 1}, {1, -2, 1}, {-1, -1, -1}, {2, -1, -1}};
    const double rot[3] = {10, 20, 30}, tr[3] = {5, -3, 1};
    for (size_t i = 0; i < 4; i++) {
        thz_mesh m = {0};
        assert_int_equal(primitive_box(&m, sizes, false, NULL), THZ_OK);
        scene_transform tf = transform_make(scales[i], rot, tr);
        bool mirror = transform_determinant(&tf) < 0;
        assert_true(mirror == (i != 3));
        transform_apply_mesh(&tf, &m);
        assert_true(mesh_finalize(&m));
        double centre[3] = {0, 0, 0};
        transform_apply_point(&tf, centre, centre);
        for (size_t t = 0; t < m.n_triangles; t++) {
            double c[3] = {0, 0, 0}, dot = 0;
            for (int v = 0; v < 3; v++)
                for (int k = 0; k < 3; k++)
                    c[k] += m.positions[3 * m.indices[3 * t + (size_t)v] + (size_t)k] / 3.0;
            for (int k = 0; k < 3; k++)
                dot += m.normals[3 * t + (size_t)k] * (c[k] - centre[k]);
            assert_true(dot > 0);
        }
        mesh_fini(&m);
    }
}

static void test_identity(void **state)
{
    (void)state;
    scene_transform tf = transform_identity();
    double p[3] = {1.25, -2.5, 3.75};
    transform_apply_point(&tf, p, p);
    assert_point(p, 1.25, -2.5, 3.75, 1e-300);
    assert_true(transform_determinant(&tf) == 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_order),          cmocka_unit_test(test_quarter_turns_exact),
        cmocka_unit_test(test_general_angles), cmocka_unit_test(test_mirror_flips_winding),
        cmocka_unit_test(test_identity),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
