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
#include "sensor/images.h"
#include "sensor/measure.h"
#include "sensor/noise.h"

#include "../physics/identity.h"

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

/* Band mean of dB_nu/dT at temp_k over ch by a central difference of the independent
 * trapezoid band mean (identity.h), W m^-2 sr^-1 Hz^-1 K^-1. */
static double band_dbdt(const thz_channel *ch, double temp_k)
{
    const double h = 0.01;
    return (ident_band_planck(ch, temp_k + h) - ident_band_planck(ch, temp_k - h)) / (2.0 * h);
}

/* The noise is NETD in K turned into radiance by the band mean of dB/dT at each pixel's
 * own Tb: at 1 THz, a plane at 30 K (h nu / k T = 1.6) takes 0.81 x the dB/dT of one at
 * 300 K. Each pixel draws on its own stream, so its noise in the 30 K plane over that in
 * the 300 K plane is that ratio exactly; and the 300 K plane's noise over NETD dB/dT is a
 * unit normal: spread 1 within 3 / sqrt(2 (N - 1)), mean 0 within 3 / sqrt(N). sigma_L
 * taken at a fixed 300 K (its noise in K then wrong where Tb is far from it) passed every
 * test: at 0.35 THz, where test_sensor.sh's hot ball is, dB/dT is flat in T. */
static void test_sigma_follows_tb(void **state)
{
    (void)state;
    thz_scene *s = load("{\"netd_k\": 0.5}");
    const thz_sensor *sn = &s->sensors[0];
    const thz_channel *ch = &s->channels[0];
    static float cold[PIXELS], warm[PIXELS], l_cold[PIXELS], l_warm[PIXELS];
    for (size_t p = 0; p < PIXELS; p++) {
        cold[p] = 30.0f;
        warm[p] = 300.0f;
    }
    memset(l_cold, 0, sizeof l_cold);
    memset(l_warm, 0, sizeof l_warm);
    thz_error err;
    assert_int_equal(noise_apply(sn, 0, ch, 0, 5, cold, l_cold, 1, &err), THZ_OK);
    assert_int_equal(noise_apply(sn, 0, ch, 0, 5, warm, l_warm, 1, &err), THZ_OK);
    double d_cold = band_dbdt(ch, 30.0), d_warm = band_dbdt(ch, 300.0);
    assert_true(d_cold / d_warm < 0.85); /* the case tells the two apart */
    double sum = 0.0, sum2 = 0.0;
    for (size_t p = 0; p < PIXELS; p++) {
        double ratio = (double)l_cold[p] / (double)l_warm[p];
        if (!(fabs(ratio / (d_cold / d_warm) - 1.0) < 1e-5))
            fail_msg("pixel %zu: noise at 30 K over that at 300 K %.6f, dB/dT ratio %.6f", p, ratio,
                     d_cold / d_warm);
        double z = (double)l_warm[p] / (0.5 * d_warm);
        sum += z;
        sum2 += z * z;
    }
    double n = PIXELS, mean = sum / n, sd = sqrt((sum2 - n * mean * mean) / (n - 1.0));
    if (!(fabs(sd - 1.0) < 3.0 / sqrt(2.0 * (n - 1.0)) && fabs(mean) < 3.0 / sqrt(n)))
        fail_msg("noise over NETD dB/dT: spread %.4f, mean %+.4f over %zu pixels", sd, mean,
                 (size_t)PIXELS);
    thz_scene_destroy(s);
}

/* The radiometer sees the image through its PSF: its NETD (T_rec + Tb) follows the Tb
 * after the PSF, not the sharp scene's (measure.h). Columns alternating 1000 K and 100 K
 * under a Gaussian PSF of 4.8 pixels' FWHM are a uniform ~550 K after it, away from the
 * mirrored left and right edges, so there the noise (measured less the PSF alone) has the
 * same spread on the hot columns as on the cold: a ratio 1 within 3 x its precision,
 * sqrt(2 / (N - 1)) with N = 88 each. Taken at the sharp Tb it was (1000 + 500) /
 * (100 + 500) x their dB/dT ratio = 2.5 x, and passed every test (the PSF test has no
 * noise, the noise tests had no PSF). */
static void test_noise_after_the_psf(void **state)
{
    (void)state;
    thz_scene *s = load("{\"receiver_temperature_k\": 500, \"integration_time_s\": 0.01, "
                        "\"radiometer\": \"total-power\"}, \"psf\": \"gaussian\", "
                        "\"psf_fwhm_deg\": 3");
    thz_sensor *sn = &s->sensors[0];
    sensor_images img;
    thz_error err;
    assert_int_equal(sensor_images_init(&img, COLUMNS, ROWS, 1, 0, &err), THZ_OK);
    double hot = ident_band_planck(&s->channels[0], 1000.0);
    double cold = ident_band_planck(&s->channels[0], 100.0);
    for (size_t p = 0; p < PIXELS; p++)
        img.radiance[p] = (float)(p % 2 ? hot : cold);
    static float blurred[PIXELS];
    thz_sensor_noise noise = sn->noise;
    sn->noise.kind = NOISE_NONE;
    assert_int_equal(sensor_measure(s, 0, 9, &img, 1, &err), THZ_OK);
    memcpy(blurred, img.measured_radiance, sizeof blurred);
    sn->noise = noise;
    assert_int_equal(sensor_measure(s, 0, 9, &img, 1, &err), THZ_OK);
    double sum[2] = {0.0, 0.0}, sum2[2] = {0.0, 0.0}, n = 0.0;
    for (size_t p = 0; p < PIXELS; p++) {
        size_t col = p % COLUMNS;
        if (col < 10 || col >= COLUMNS - 10)
            continue;
        /* the PSF evened the image out */
        assert_true(fabs(blurred[p] / (0.5 * (hot + cold)) - 1.0) < 0.01);
        double d = (double)img.measured_radiance[p] - (double)blurred[p];
        sum[col % 2] += d;
        sum2[col % 2] += d * d;
        n += 0.5;
    }
    assert_true(n == 88.0);
    double sd[2];
    for (int h = 0; h < 2; h++)
        sd[h] = sqrt((sum2[h] - sum[h] * sum[h] / n) / (n - 1.0));
    if (!(fabs(sd[1] / sd[0] - 1.0) < 3.0 * sqrt(2.0 / (n - 1.0))))
        fail_msg("noise on the hot columns over that on the cold: %.4f, expected 1", sd[1] / sd[0]);
    sensor_images_fini(&img);
    thz_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_table_against_its_nodes),
                                       cmocka_unit_test(test_sigma_follows_tb),
                                       cmocka_unit_test(test_noise_after_the_psf)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
