/* Keyframe interpolation of batch sequences (src/batch/batch_interp.c) against hand
 * values: linear between keyframes, exact at them, held beyond the ends; rotations by
 * slerp, checked through the scene's own transform (scene/transform.c), so that the
 * angles' convention (about x, then y, then z) is the scene's. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "scene/transform.h"
#include "thzmap/batch.h"

static void test_linear(void **state)
{
    (void)state;
    const double t[3] = {0.0, 1.0, 3.0};
    const double v[6] = {0.0, 300.0, 10.0, 308.0, 30.0, 300.0}; /* two values per keyframe */
    double out[2];
    thz_interp_linear(t, v, 3, 2, 0.5, out);
    assert_true(out[0] == 5.0 && out[1] == 304.0);
    thz_interp_linear(t, v, 3, 2, 2.0, out); /* second segment, half way */
    assert_true(out[0] == 20.0 && out[1] == 304.0);
    thz_interp_linear(t, v, 3, 2, 0.25, out);
    assert_true(out[0] == 2.5 && out[1] == 302.0);
    thz_interp_linear(t, v, 3, 2, 1.0, out); /* at a keyframe: its value, bit for bit */
    assert_true(out[0] == 10.0 && out[1] == 308.0);
    thz_interp_linear(t, v, 3, 2, -2.0, out); /* held before the first */
    assert_true(out[0] == 0.0 && out[1] == 300.0);
    thz_interp_linear(t, v, 3, 2, 7.0, out); /* and after the last */
    assert_true(out[0] == 30.0 && out[1] == 300.0);
    const double one_t[1] = {2.0}, one_v[1] = {0.1};
    thz_interp_linear(one_t, one_v, 1, 1, 0.0, out); /* one keyframe: held everywhere */
    assert_true(out[0] == 0.1);
    thz_interp_linear(one_t, one_v, 1, 1, 9.0, out);
    assert_true(out[0] == 0.1);
    /* a keyframe's value that is not exact in binary comes back unchanged at its time */
    const double t2[2] = {0.0, 0.3}, v2[2] = {0.1, 0.7};
    thz_interp_linear(t2, v2, 2, 1, 0.3, out);
    assert_true(out[0] == 0.7);
}

/* The rotation matrix of rotate_deg, through the scene's transform. */
static void rotation_of(const double deg[3], double r[3][3])
{
    const double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    scene_transform tf = transform_make(one, deg, zero);
    for (int j = 0; j < 3; j++) {
        double e[3] = {j == 0, j == 1, j == 2};
        transform_apply_point(&tf, e, e);
        for (int i = 0; i < 3; i++)
            r[i][j] = e[i];
    }
}

/* The angle in degrees of the rotation taking a to b. */
static double angle_between(const double a[3], const double b[3])
{
    double ra[3][3], rb[3][3], trace = 0.0;
    rotation_of(a, ra);
    rotation_of(b, rb);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            trace += ra[k][i] * rb[k][i]; /* trace(Ra^T Rb) */
    return acos(fmax(-1.0, fmin(1.0, 0.5 * (trace - 1.0)))) * 180.0 / M_PI;
}

static void test_slerp(void **state)
{
    (void)state;
    const double t[2] = {0.0, 1.0};
    double out[3];
    /* about one axis: the angle interpolates linearly */
    const double z[6] = {0, 0, 0, 0, 0, 90};
    thz_interp_rotation(t, z, 2, 0.5, out);
    assert_true(fabs(out[0]) < 1e-12 && fabs(out[1]) < 1e-12 && fabs(out[2] - 45.0) < 1e-12);
    const double x[6] = {0, 0, 0, 90, 0, 0};
    thz_interp_rotation(t, x, 2, 0.25, out);
    assert_true(fabs(out[0] - 22.5) < 1e-12 && fabs(out[1]) < 1e-12 && fabs(out[2]) < 1e-12);
    /* the shorter arc: 170 deg to -170 deg about z passes 180, not 0 */
    const double wrap[6] = {0, 0, 170, 0, 0, -170};
    thz_interp_rotation(t, wrap, 2, 0.5, out);
    assert_true(fabs(fabs(out[2]) - 180.0) < 1e-9);
    /* 90 about x to 90 about y: 120 deg apart (quaternion dot 1/2); half way is 60 deg
     * from each end, where linear angles (45, 45, 0) would be 62.8 deg from both */
    const double xy[6] = {90, 0, 0, 0, 90, 0};
    thz_interp_rotation(t, xy, 2, 0.5, out);
    assert_true(fabs(angle_between(&xy[0], &xy[3]) - 120.0) < 1e-9);
    assert_true(fabs(angle_between(&xy[0], out) - 60.0) < 1e-9);
    assert_true(fabs(angle_between(out, &xy[3]) - 60.0) < 1e-9);
    const double lin[3] = {45, 45, 0};
    assert_true(fabs(angle_between(&xy[0], lin) - 60.0) > 1.0);
    /* a quarter of the way: 30 deg from the start, 90 from the end */
    thz_interp_rotation(t, xy, 2, 0.25, out);
    assert_true(fabs(angle_between(&xy[0], out) - 30.0) < 1e-9);
    assert_true(fabs(angle_between(out, &xy[3]) - 90.0) < 1e-9);
    /* held beyond the ends, the keyframes' own angles */
    thz_interp_rotation(t, xy, 2, -1.0, out);
    assert_true(out[0] == 90.0 && out[1] == 0.0 && out[2] == 0.0);
    thz_interp_rotation(t, xy, 2, 4.0, out);
    assert_true(out[0] == 0.0 && out[1] == 90.0 && out[2] == 0.0);
    /* through the gimbal lock (ry = 90): same rotation whatever the split of rx, rz */
    const double g[6] = {0, 90, 0, 0, 90, 40};
    thz_interp_rotation(t, g, 2, 0.5, out);
    const double g_mid[3] = {0, 90, 20};
    assert_true(angle_between(out, g_mid) < 1e-6);
}

/* A value two keyframes give alike stays that value bit for bit between them: (1 - u) a
 * + u a is not always a (0.06 at u = 1/8 gives 0.060000000000000005), and a still
 * object's position moving in its last bit made the frames differ in more than their
 * sensors, so a camera moving past it fired every frame's photons anew. */
static void test_equal_keyframes_stay_exact(void **state)
{
    (void)state;
    const double t[2] = {0.0, 3.0};
    const double v[6] = {0.0, 0.06, 0.001, 0.0, 0.06, 0.001};
    for (int i = 0; i <= 24; i++) {
        double out[3];
        thz_interp_linear(t, v, 2, 3, i / 8.0, out);
        assert_true(out[0] == 0.0 && out[1] == 0.06 && out[2] == 0.001);
    }
    const double r[6] = {10.0, 20.0, 37.5, 10.0, 20.0, 37.5};
    for (int i = 0; i <= 24; i++) {
        double out[3];
        thz_interp_rotation(t, r, 2, i / 8.0, out);
        assert_true(out[0] == 10.0 && out[1] == 20.0 && out[2] == 37.5);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linear),
        cmocka_unit_test(test_slerp),
        cmocka_unit_test(test_equal_keyframes_stay_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
