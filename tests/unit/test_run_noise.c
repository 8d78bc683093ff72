/* The noise figures (run_noise.c): the median and the nearest-rank 95th percentile of the
 * per-pixel standard error of Tb, per object and over all pixels, against a sort of the
 * same values done here: random values with many ties, all equal, one and two pixels,
 * pixels of no object and of object ids out of range, and a pixel whose Tb is not
 * counted. The figures come from a selection (linear time), which must give a sort's
 * values exactly. */
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

/* One image of `px` pixels in one channel: object ids in -1 .. n_objects + 1 (the last two
 * out of range), Tb 0 (not counted) now and then, radiance standard errors from `levels`
 * distinct values (ties) or all the same; checks run_noise_channel against by_sort. */
static void check(size_t px, size_t n_objects, unsigned levels, int all_same)
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
        if (tb[p] > 0.0f)
            want_all[n_all++] = render_stderr_k(freq_hz, tb[p], se[p]);
    }
    run_noise all, objects[8];
    assert_true(n_objects <= 8);
    thz_error err = {0};
    assert_int_equal(run_noise_channel(&img, 1, 0, freq_hz, n_objects, &all, objects, &err),
                     THZ_OK);
    run_noise ref = by_sort(want_all, n_all);
    assert_int_equal(all.pixels, ref.pixels);
    assert_true(all.median_k == ref.median_k);
    assert_true(all.p95_k == ref.p95_k);
    for (size_t o = 0; o < n_objects; o++) {
        size_t n = 0;
        for (size_t p = 0; p < px; p++)
            if (ids[p] == (int32_t)o && tb[p] > 0.0f)
                want_obj[n++] = render_stderr_k(freq_hz, tb[p], se[p]);
        ref = by_sort(want_obj, n);
        assert_int_equal(objects[o].pixels, ref.pixels);
        assert_true(objects[o].median_k == ref.median_k);
        assert_true(objects[o].p95_k == ref.p95_k);
    }
    free(want_all);
    free(want_obj);
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

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_against_a_sort)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
