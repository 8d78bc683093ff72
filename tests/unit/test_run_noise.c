/* The noise figures (run_noise.c): the median and the nearest-rank 95th percentile of the
 * per-pixel standard error of Tb, per object and over all pixels, against a sort of the
 * same values done here: random values with many ties, all equal, one and two pixels,
 * pixels of no object and of object ids out of range, and a pixel whose Tb is not
 * counted. The figures come from a selection (linear time), which must give a sort's
 * values exactly. A pixel whose standard error is unknown (NaN: photon-map samples short
 * of photons) is counted and ranks above every known one: a figure that falls on one is
 * infinite (summary.json's null), never 0 K (10 photons a channel gave every figure 0 K). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "run/run_noise.h"
#include "sensor/render.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The figures of n values by sorting them. */
static run_noise by_sort(double *x, size_t n)
{
    run_noise r = {.pixels = n};
    if (n == 0)
        return r;
    qsort(x, n, sizeof *x, cmp_double);
    r.median_k = n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
    r.p95_k = x[(size_t)ceil(0.95 * (double)n - 1e-9) - 1];
    return r;
}

/* 64 random bits from the project's own streams */
static uint64_t next(void)
{
    static rng_stream rng;
    static bool started;
    if (!started) {
        rng_init(&rng, 2, 0, RNG_PURPOSE_TEST, 0);
        started = true;
    }
    return rng_next_u64(&rng);
}

/* The unknown values (infinite) among n. */
static size_t count_unknown(const double *x, size_t n)
{
    size_t u = 0;
    for (size_t k = 0; k < n; k++)
        u += isinf(x[k]) != 0;
    return u;
}

/* One image of `px` pixels in one channel: object ids in -1 .. n_objects + 1 (the last two
 * out of range), Tb 0 (not counted) now and then, radiance standard errors from `levels`
 * distinct values (ties) or all the same, one in `unknown_every` NaN (0: none); checks
 * run_noise_channel against by_sort of the values with NaN taken as +infinity. */
static void check_unknown(size_t px, size_t n_objects, unsigned levels, int all_same,
                          unsigned unknown_every)
{
    const double freq_hz = 0.5e12;
    float tb[4096], se[4096];
    int32_t ids[4096];
    assert_true(px <= 4096);
    sensor_images img = {.columns = (uint32_t)px, .rows = 1, .n_channels = 1};
    img.brightness_temperature = tb;
    img.radiance_stderr = se;
    img.object_id = ids;
    double *want_all = calloc(px + 1, sizeof *want_all);
    double *want_obj = calloc(px + 1, sizeof *want_obj);
    size_t n_all = 0;
    for (size_t p = 0; p < px; p++) {
        ids[p] = (int32_t)(next() % (n_objects + 3)) - 1;
        tb[p] = next() % 17 == 0 ? 0.0f : (float)(250.0 + (double)(next() % 100));
        se[p] = all_same ? 2e-18f : (float)(1e-18 * (double)(1 + next() % levels));
        if (unknown_every && next() % unknown_every == 0)
            se[p] = NAN;
        if (tb[p] > 0.0f)
            want_all[n_all++] = isnan(se[p]) ? INFINITY : render_stderr_k(freq_hz, tb[p], se[p]);
    }
    run_noise all, objects[8];
    assert_true(n_objects <= 8);
    thz_error err = {0};
    assert_int_equal(run_noise_channel(&img, 1, 0, freq_hz, n_objects, &all, objects, &err),
                     THZ_OK);
    assert_int_equal(all.unknown, count_unknown(want_all, n_all));
    run_noise ref = by_sort(want_all, n_all);
    assert_int_equal(all.pixels, ref.pixels);
    assert_true(all.median_k == ref.median_k);
    assert_true(all.p95_k == ref.p95_k);
    for (size_t o = 0; o < n_objects; o++) {
        size_t n = 0;
        for (size_t p = 0; p < px; p++)
            if (ids[p] == (int32_t)o && tb[p] > 0.0f)
                want_obj[n++] = isnan(se[p]) ? INFINITY : render_stderr_k(freq_hz, tb[p], se[p]);
        assert_int_equal(objects[o].unknown, count_unknown(want_obj, n));
        ref = by_sort(want_obj, n);
        assert_int_equal(objects[o].pixels, ref.pixels);
        assert_true(objects[o].median_k == ref.median_k);
        assert_true(objects[o].p95_k == ref.p95_k);
    }
    free(want_all);
    free(want_obj);
}

static void check(size_t px, size_t n_objects, unsigned levels, int all_same)
{
    check_unknown(px, n_objects, levels, all_same, 0);
}

static void test_against_a_sort(void **state)
{
    (void)state;
    for (int round = 0; round < 200; round++) {
        size_t px = 1 + next() % 4096;
        check(px, 1 + next() % 8, 1 + (unsigned)(next() % 50), 0);
    }
    for (size_t px = 1; px <= 40; px++) { /* small counts: one and two pixels, odd and even */
        check(px, 3, 3, 0);
        check(px, 2, 1, 1);
    }
    check(4096, 5, 1, 1);        /* every value the same */
    check(4096, 1, 1u << 30, 0); /* nearly all distinct */
}

/* Unknown standard errors: at random among known ones, and at the edges of the ranks. */
static void test_unknown(void **state)
{
    (void)state;
    for (int round = 0; round < 100; round++)
        check_unknown(1 + next() % 4096, 1 + next() % 8, 1 + (unsigned)(next() % 50), 0,
                      2 + (unsigned)(next() % 40));
    check_unknown(300, 2, 5, 0, 1); /* every one unknown */
    /* 100 pixels, Tb 300 K, standard errors 1..100 x 1e-19 in pixel order: the 95th
     * percentile is the 95th, known with the 5 largest unknown and unknown with 6; the
     * median unknown once 50 are */
    const double freq_hz = 0.5e12;
    float tb[100], se[100];
    int32_t ids[100];
    sensor_images img = {.columns = 100, .rows = 1, .n_channels = 1};
    img.brightness_temperature = tb;
    img.radiance_stderr = se;
    img.object_id = ids;
    for (size_t u = 0; u <= 50; u++) {
        for (size_t p = 0; p < 100; p++) {
            tb[p] = 300.0f;
            ids[p] = 0;
            se[p] = p >= 100 - u ? NAN : (float)(1e-19 * (double)(p + 1));
        }
        run_noise all;
        thz_error err = {0};
        assert_int_equal(run_noise_channel(&img, 1, 0, freq_hz, 0, &all, NULL, &err), THZ_OK);
        assert_int_equal(all.pixels, 100);
        assert_int_equal(all.unknown, u);
        assert_true(u <= 5 ? all.p95_k == render_stderr_k(freq_hz, 300.0, se[94])
                           : isinf(all.p95_k));
        assert_true(u < 50 ? isfinite(all.median_k) && all.median_k > 0.0 : isinf(all.median_k));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_against_a_sort),
                                       cmocka_unit_test(test_unknown)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
