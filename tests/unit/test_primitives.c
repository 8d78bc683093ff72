/* Primitives: triangle counts, areas against the exact polygon formulas (a tessellated
 * cylinder, sphere or disk has the area of its polygons, not of the smooth shape),
 * outward normals (each points away from the shape's centroid; for closed shapes the
 * area-weighted normals sum to zero), consistent winding, Embree's padding, and Ward's
 * tangent (each triangle's first edge) along one line over a whole face. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "scene/mesh_import.h"
#include "scene/primitives.h"
#include "scene/scene.h"

/* Every normal points away from `centre` (dot with the triangle centroid's offset > 0),
 * or, if `fixed` is given, equals it. */
/* The winding conflicts mesh_import_defects counts. */
static size_t winding_conflicts(const thz_mesh *m)
{
    mesh_defects d;
    assert_true(mesh_import_defects(m, &d));
    return d.winding_conflicts;
}

static void check_normals(const thz_mesh *m, const double centre[3], const double *fixed)
{
    for (size_t t = 0; t < m->n_triangles; t++) {
        const float *n = &m->normals[3 * t];
        if (fixed) {
            for (int k = 0; k < 3; k++)
                assert_true(fabs(n[k] - fixed[k]) < 1e-6);
            continue;
        }
        double c[3] = {0, 0, 0};
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                c[k] += m->positions[3 * m->indices[3 * t + (size_t)v] + (size_t)k] / 3.0;
        double dot = 0;
        for (int k = 0; k < 3; k++)
            dot += n[k] * (c[k] - centre[k]);
        assert_true(dot > 0);
    }
}

static void check_closed(const thz_mesh *m)
{
    double s[3] = {0, 0, 0};
    for (size_t t = 0; t < m->n_triangles; t++)
        for (int k = 0; k < 3; k++)
            s[k] += m->areas_m2[t] * m->normals[3 * t + (size_t)k];
    for (int k = 0; k < 3; k++)
        assert_true(fabs(s[k]) < 1e-5 * m->total_area_m2);
    assert_int_equal(winding_conflicts(m), 0);
}

/* Triangle t's first edge v0 -> v1, Ward's tangent, is parallel (either way) to `axis`
 * (a unit vector): a quad's second triangle once started on its diagonal, and half of an
 * anisotropic lobe's face was brushed across it. */
static void check_tangent(const thz_mesh *m, size_t t, const double axis[3])
{
    const float *a = &m->positions[3 * m->indices[3 * t]];
    const float *b = &m->positions[3 * m->indices[3 * t + 1]];
    double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    double dot = (e[0] * axis[0] + e[1] * axis[1] + e[2] * axis[2]) / len;
    assert_true(fabs(fabs(dot) - 1.0) < 1e-6);
}

/* A box's faces: the tangent along x, on the faces normal to x along y. */
static void check_box_tangents(const thz_mesh *m)
{
    const double x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    for (size_t t = 0; t < m->n_triangles; t++)
        check_tangent(m, t, fabs(m->normals[3 * t]) > 0.5 ? y : x);
}

/* scene-format.md: Ward's tangent runs radially on a disk and a cylinder's caps:
 * triangles t0 .. t0 + n - 1, every other one from t0 when `step` is 2, each at height
 * z, have their first edge along the line from the axis through its centroid. (A disk,
 * and caps, listed from the rim, the tangent along the circumference, passed every
 * test.) */
static void check_radial_tangents(const thz_mesh *m, size_t t0, size_t step, size_t n, double z)
{
    for (size_t i = 0; i < n; i++) {
        size_t t = t0 + step * i;
        double c[3] = {0, 0, 0};
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                c[k] += m->positions[3 * m->indices[3 * t + (size_t)v] + (size_t)k] / 3.0;
        assert_true(fabs(c[2] - z) < 1e-6);
        double len = hypot(c[0], c[1]);
        const double radial[3] = {c[0] / len, c[1] / len, 0.0};
        /* the first edge from the centre to the rim: at an angle of pi / n at most from
         * the centroid's direction, where one along the rim is at pi / 2 */
        const float *a = &m->positions[3 * m->indices[3 * t]];
        const float *b = &m->positions[3 * m->indices[3 * t + 1]];
        double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double el = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        double cosang = fabs(e[0] * radial[0] + e[1] * radial[1] + e[2] * radial[2]) / el;
        assert_true(cosang >= cos(M_PI / (double)n) - 1e-6);
    }
}

static void check_padding(const thz_mesh *m)
{
    for (int k = 0; k < 4; k++)
        assert_true(m->positions[3 * m->n_vertices + (size_t)k] == 0.0f);
}

static void test_box(void **state)
{
    (void)state;
    thz_mesh m = {0};
    const double size[3] = {1, 1, 2};
    assert_int_equal(primitive_box(&m, size, false, NULL), THZ_OK);
    assert_true(mesh_finalize(&m));
    assert_int_equal(m.n_triangles, 12);
    assert_int_equal(m.n_vertices, 8);
    assert_true(fabs(m.total_area_m2 - 10.0) < 1e-12);
    const double centre[3] = {0, 0, 0};
    check_normals(&m, centre, NULL);
    check_closed(&m);
    check_padding(&m);
    assert_true(m.bbox_min_m[2] == -1.0 && m.bbox_max_m[2] == 1.0);
    check_box_tangents(&m);
    mesh_fini(&m);
}

static void test_box_inward(void **state)
{
    (void)state;
    thz_mesh m = {0};
    const double size[3] = {2, 3, 4};
    assert_int_equal(primitive_box(&m, size, true, NULL), THZ_OK);
    assert_true(mesh_finalize(&m));
    assert_true(fabs(m.total_area_m2 - 2 * (6 + 12 + 8)) < 1e-12);
    for (size_t t = 0; t < m.n_triangles; t++) {
        double c[3] = {0, 0, 0}, dot = 0;
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                c[k] += m.positions[3 * m.indices[3 * t + (size_t)v] + (size_t)k] / 3.0;
        for (int k = 0; k < 3; k++)
            dot += m.normals[3 * t + (size_t)k] * c[k];
        assert_true(dot < 0); /* towards the inside */
    }
    check_closed(&m);
    check_box_tangents(&m);
    mesh_fini(&m);
}

static void test_cylinder(void **state)
{
    (void)state;
    const double r = 0.1, h = 0.75;
    const unsigned segs[] = {3, 7, 64};
    for (size_t i = 0; i < 3; i++) {
        unsigned n = segs[i];
        thz_mesh m = {0};
        assert_int_equal(primitive_cylinder(&m, r, h, true, n, NULL), THZ_OK);
        assert_true(mesh_finalize(&m));
        assert_int_equal(m.n_triangles, 4 * n);
        double side = n * 2 * r * sin(M_PI / n) * h;
        double cap = n * r * r * sin(2 * M_PI / n) / 2;
        assert_true(fabs(m.total_area_m2 - (side + 2 * cap)) < 1e-6 * m.total_area_m2);
        const double centre[3] = {0, 0, h / 2};
        check_normals(&m, centre, NULL);
        check_closed(&m);
        check_padding(&m);
        assert_true(fabs(m.bbox_min_m[2]) < 1e-7 && fabs(m.bbox_max_m[2] - h) < 1e-7);
        check_radial_tangents(&m, 2 * n, 2, n, 0.0);   /* the bottom cap */
        check_radial_tangents(&m, 2 * n + 1, 2, n, h); /* the top cap */
        mesh_fini(&m);

        assert_int_equal(primitive_cylinder(&m, r, h, false, n, NULL), THZ_OK);
        assert_true(mesh_finalize(&m));
        assert_int_equal(m.n_triangles, 2 * n);
        assert_true(fabs(m.total_area_m2 - side) < 1e-6 * side);
        check_normals(&m, centre, NULL);
        assert_int_equal(winding_conflicts(&m), 0);
        for (size_t t = 0; t < m.n_triangles; t++) { /* along the circumference */
            double a = 2.0 * M_PI * ((double)(t / 2) + 0.5) / (double)n;
            const double along[3] = {-sin(a), cos(a), 0.0};
            check_tangent(&m, t, along);
        }
        mesh_fini(&m);
    }
}

static void test_sphere(void **state)
{
    (void)state;
    const double r = 2.0;
    const double centre[3] = {0, 0, 0};
    thz_mesh m = {0};
    /* the icosahedron: 20 equilateral triangles of edge a = 4r / sqrt(10 + 2 sqrt 5) */
    assert_int_equal(primitive_sphere(&m, r, 0, NULL), THZ_OK);
    assert_true(mesh_finalize(&m));
    assert_int_equal(m.n_triangles, 20);
    assert_int_equal(m.n_vertices, 12);
    double a = 4 * r / sqrt(10 + 2 * sqrt(5));
    assert_true(fabs(m.total_area_m2 - 5 * sqrt(3) * a * a) < 1e-6 * m.total_area_m2);
    check_normals(&m, centre, NULL);
    check_closed(&m);
    mesh_fini(&m);

    double last = 0;
    for (unsigned s = 1; s <= 4; s++) {
        assert_int_equal(primitive_sphere(&m, r, s, NULL), THZ_OK);
        assert_true(mesh_finalize(&m));
        assert_int_equal(m.n_triangles, 20u << (2 * s));
        assert_int_equal(m.n_vertices, 10u * (1u << (2 * s)) + 2);
        /* inscribed polyhedra grow towards the sphere's area */
        assert_true(m.total_area_m2 > last && m.total_area_m2 < 4 * M_PI * r * r);
        last = m.total_area_m2;
        for (size_t v = 0; v < m.n_vertices; v++) {
            const float *p = &m.positions[3 * v];
            assert_true(fabs(sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - r) < 1e-5);
        }
        check_normals(&m, centre, NULL);
        check_closed(&m);
        check_padding(&m);
        mesh_fini(&m);
    }
    assert_true(last > 0.99 * 4 * M_PI * r * r);
    assert_int_not_equal(primitive_sphere(&m, r, PRIMITIVE_MAX_SUBDIVISIONS + 1, NULL), THZ_OK);
}

static void test_rectangle(void **state)
{
    (void)state;
    thz_mesh m = {0};
    const double size[2] = {0.5, 3};
    const double up[3] = {0, 0, 1};
    assert_int_equal(primitive_rectangle(&m, size, NULL), THZ_OK);
    assert_true(mesh_finalize(&m));
    assert_int_equal(m.n_triangles, 2);
    assert_true(fabs(m.total_area_m2 - 1.5) < 1e-12);
    check_normals(&m, NULL, up);
    assert_true(m.bbox_min_m[0] == -0.25 && m.bbox_max_m[1] == 1.5);
    assert_int_equal(winding_conflicts(&m), 0);
    const double x[3] = {1, 0, 0};
    check_tangent(&m, 0, x);
    check_tangent(&m, 1, x);
    mesh_fini(&m);
}

static void test_disk(void **state)
{
    (void)state;
    const double up[3] = {0, 0, 1};
    const unsigned segs[] = {3, 5, 64, 1000};
    for (size_t i = 0; i < 4; i++) {
        unsigned n = segs[i];
        thz_mesh m = {0};
        double r = 0.3;
        assert_int_equal(primitive_disk(&m, r, n, NULL), THZ_OK);
        assert_true(mesh_finalize(&m));
        assert_int_equal(m.n_triangles, n);
        double exact = n * r * r * sin(2 * M_PI / n) / 2;
        assert_true(fabs(m.total_area_m2 - exact) < 1e-6 * exact);
        check_normals(&m, NULL, up);
        assert_int_equal(winding_conflicts(&m), 0);
        check_padding(&m);
        check_radial_tangents(&m, 0, 1, n, 0.0);
        mesh_fini(&m);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box),       cmocka_unit_test(test_box_inward),
        cmocka_unit_test(test_cylinder),  cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_rectangle), cmocka_unit_test(test_disk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
