/* The radiometer noise's sigma_L(Tb) (sensor/noise.c): tabulated per channel over the
 * plane's range of Tb and interpolated per pixel, it must agree with its value computed
 * at that Tb alone (noise.h: relative error below 1e-12 over 250..320 K). A plane with
 * one Tb has its table's first node there, where the cubic is exact; each pixel's noise
 * draws on its own stream, so a pixel's noise in a plane of many Tb over its noise in a
 * plane of its Tb alone is sigma_L's interpolated value over its exact one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene.h"
#include "sensor/noise.h"

enum { COLUMNS = 64, ROWS = 4, PIXELS = COLUMNS * ROWS };

static thz_scene *load(const char *noise)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\","
             " \"channels\": [{\"frequency_thz\": 1.0, \"relative_width\": 0.1}],"
             " \"materials\": {\"wall\": {\"reflectivity\": 0.3}},"
             " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
             "   \"temperature_k\": 300,"
             "   \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, 0, 0],"
             "   \"look_at_m\": [0, 1, 0], \"fov_deg\": 40, \"resolution\": [%d, %d],"
             "   \"noise\": %s}]}",
             COLUMNS, ROWS, noise);
    thz_scene *s = NULL;
    thz_error err;
    if (scene_load_string(json, ".", "noise-unit", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    return s;
}

static void check_table(const char *noise)
{
    thz_scene *s = load(noise);
    const thz_sensor *sn = &s->sensors[0];
    static float tb[PIXELS], one_tb[PIXELS], l[PIXELS], l_one[PIXELS];
    for (size_t p = 0; p < PIXELS; p++) /* 250 .. 320 K, uneven in ln Tb */
        tb[p] = (float)(250.0 + 70.0 * pow((double)p / (PIXELS - 1), 1.7));
    memset(l, 0, sizeof l);
    thz_error err;
    assert_int_equal(noise_apply(sn, 0, &s->channels[0], 0, 3, tb, l, 1, &err), THZ_OK);
    for (size_t q = 0; q < PIXELS; q += 5) {
        for (size_t p = 0; p < PIXELS; p++)
            one_tb[p] = tb[q];
        memset(l_one, 0, sizeof l_one);
        assert_int_equal(noise_apply(sn, 0, &s->channels[0], 0, 3, one_tb, l_one, 1, &err), THZ_OK);
        assert_true(l_one[q] != 0.0f);
        /* the radiances are floats: 1e-6 */
        if (!(fabs((double)l[q] / (double)l_one[q] - 1.0) < 1e-6))
            fail_msg("%s: pixel %zu (Tb %.3f K): noise %g in the plane, %g at its Tb alone", noise,
                     q, (double)tb[q], (double)l[q], (double)l_one[q]);
    }
    thz_scene_destroy(s);
}

static void test_table_against_its_nodes(void **state)
{
    (void)state;
    check_table("{\"netd_k\": 0.5}");
    check_table("{\"receiver_temperature_k\": 400, \"integration_time_s\": 0.01, "
                "\"radiometer\": \"total-power\"}");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_table_against_its_nodes)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
