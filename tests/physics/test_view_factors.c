/* View factors: a hot one-sided black plate forms the floor of a black enclosure at 0 K
 * whose five other walls are separate objects. Every photon is emitted by the plate and
 * absorbed at its first hit, so the fraction of photons landing on each wall is the
 * plate's view factor to it (Howell's catalogue: C-11 parallel, directly opposed equal
 * rectangles; C-14 perpendicular rectangles sharing an edge). Tolerance: 5 binomial
 * standard errors of the photon count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon_scenes.h"

/* C-11: directly opposed parallel rectangles a x b at distance c. */
static double vf_parallel(double a, double b, double c)
{
    double x = a / c, y = b / c;
    double x1 = sqrt(1 + x * x), y1 = sqrt(1 + y * y);
    double f = log(sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y))) + x * y1 * atan(x / y1) +
               y * x1 * atan(y / x1) - x * atan(x) - y * atan(y);
    return 2.0 / (M_PI * x * y) * f;
}

/* C-14: from a rectangle of width w to a perpendicular one of height h sharing an edge
 * of length l. */
static double vf_perpendicular(double l, double w, double h)
{
    double hh = h / l, ww = w / l;
    double h2 = hh * hh, w2 = ww * ww, s = sqrt(h2 + w2);
    double a = (1 + w2) * (1 + h2) / (1 + w2 + h2);
    double b = w2 * (1 + w2 + h2) / ((1 + w2) * (w2 + h2));
    double c = h2 * (1 + h2 + w2) / ((1 + h2) * (h2 + w2));
    double f = ww * atan(1 / ww) + hh * atan(1 / hh) - s * atan(1 / s) +
               0.25 * (log(a) + w2 * log(b) + h2 * log(c));
    return f / (M_PI * ww);
}

static void test_closed_forms(void **state)
{
    (void)state;
    /* Catalogue values: unit squares at unit distance 0.1998; perpendicular unit squares
     * 0.2000. */
    assert_float_equal(vf_parallel(1, 1, 1), 0.19982, 1e-4);
    assert_float_equal(vf_perpendicular(1, 1, 1), 0.20004, 1e-4);
    /* Reciprocity: A1 F12 = A2 F21. */
    assert_float_equal(2.0 * vf_perpendicular(1, 2, 0.5), 0.5 * vf_perpendicular(1, 0.5, 2), 1e-12);
}

static void test_enclosure(void **state)
{
    (void)state;
    const double a = 1.0, b = 2.0, c = 0.7; /* plate a (x) by b (y), enclosure height c */
    uint64_t k = ps_scaled(400000);
    thz_scene *s = ps_scene(0.35, 0.01, k, 11);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plate = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, plate, v3(a / 2, b / 2, 0), v3(a / 2, 0, 0), v3(0, b / 2, 0)); /* normal +z */
    /* Walls with inward normals: top, x = 0, x = a, y = 0, y = b. */
    size_t top = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, top, v3(a / 2, b / 2, c), v3(0, b / 2, 0), v3(a / 2, 0, 0));
    size_t x0 = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, x0, v3(0, b / 2, c / 2), v3(0, b / 2, 0), v3(0, 0, c / 2));
    size_t x1 = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, x1, v3(a, b / 2, c / 2), v3(0, 0, c / 2), v3(0, b / 2, 0));
    size_t y0 = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, y0, v3(a / 2, 0, c / 2), v3(0, 0, c / 2), v3(a / 2, 0, 0));
    size_t y1 = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, y1, v3(a / 2, b, c / 2), v3(a / 2, 0, 0), v3(0, 0, c / 2));
    ps_finalize(s);
    for (size_t i = 1; i < s->n_objects; i++) /* every wall faces the inside */
        assert_true(s->objects[i].mesh.normals[0] * (a / 2 - s->objects[i].mesh.bbox_min_m[0]) +
                        s->objects[i].mesh.normals[1] * (b / 2 - s->objects[i].mesh.bbox_min_m[1]) +
                        s->objects[i].mesh.normals[2] * (c / 2 - s->objects[i].mesh.bbox_min_m[2]) >
                    0.0);

    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    photon_map *map;
    photon_stats st;
    assert_int_equal(photon_phase_run(s, acc, 0, NULL, &map, &st, &err), THZ_OK);
    assert_int_equal(st.hits, k); /* closed and black: one hit each */
    assert_int_equal(st.escaped, 0);
    assert_int_equal(st.back_face_hits, 0);

    uint64_t counts[6] = {0};
    const photon_record *r = photon_map_records(map);
    for (size_t i = 0; i < photon_map_count(map); i++) {
        assert_true(photon_first_hit(&r[i])); /* first hits only */
        assert_int_equal(photon_side(&r[i]), 0);
        counts[photon_object(&r[i])]++;
    }
    double expect[6] = {0};
    expect[top] = vf_parallel(a, b, c);
    expect[x0] = expect[x1] = vf_perpendicular(b, a, c); /* shared edge along y, length b */
    expect[y0] = expect[y1] = vf_perpendicular(a, b, c);
    double sum = 0.0;
    for (size_t i = 1; i < 6; i++)
        sum += expect[i];
    assert_float_equal(sum, 1.0, 1e-9); /* summation rule: the closed forms agree */
    assert_int_equal(counts[plate], 0);
    for (size_t i = 1; i < 6; i++) {
        double f = (double)counts[i] / (double)k;
        double se = sqrt(expect[i] * (1 - expect[i]) / (double)k);
        printf("# wall %zu: fraction %.5f, view factor %.5f (%.1f standard errors)\n", i, f,
               expect[i], (f - expect[i]) / se);
        assert_true(fabs(f - expect[i]) < 5.0 * se);
    }
    photon_map_destroy(map);
    accel_destroy(acc);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_forms),
        cmocka_unit_test(test_enclosure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
