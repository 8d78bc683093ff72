/* Counter-based RNG: Philox4x32-10 known answers, stream keying, uniform ranges and
 * distribution. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include <Random123/philox.h>

#include "core/rng.h"

static double test_scale(void)
{
    const char *s = getenv("THZ_TEST_SCALE");
    double v = s ? atof(s) : 1.0;
    return (v > 0.0 && v <= 1.0) ? v : 1.0;
}

/* Random123's published known-answer vectors for philox4x32_10 (kat_vectors). */
static void test_known_answers(void **state)
{
    (void)state;
    philox4x32_ctr_t c = {{0, 0, 0, 0}};
    philox4x32_key_t k = {{0, 0}};
    philox4x32_ctr_t r = philox4x32(c, k);
    assert_int_equal(r.v[0], 0x6627e8d5u);
    assert_int_equal(r.v[1], 0xe169c58du);
    assert_int_equal(r.v[2], 0xbc57ac4cu);
    assert_int_equal(r.v[3], 0x9b00dbd8u);
    philox4x32_ctr_t c2 = {{0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u}};
    philox4x32_key_t k2 = {{0xa4093822u, 0x299f31d0u}};
    r = philox4x32(c2, k2);
    assert_int_equal(r.v[0], 0xd16cfe09u);
    assert_int_equal(r.v[1], 0x94fdccebu);
    assert_int_equal(r.v[2], 0x5001e420u);
    assert_int_equal(r.v[3], 0x24126ea1u);

    /* seed 0, channel 0, purpose 0, index 0 is counter 0 under key 0 */
    rng_stream s;
    rng_init(&s, 0, 0, 0, 0);
    assert_int_equal(rng_next_u32(&s), 0x6627e8d5u);
    assert_int_equal(rng_next_u32(&s), 0xe169c58du);
    assert_int_equal(rng_next_u32(&s), 0xbc57ac4cu);
    assert_int_equal(rng_next_u32(&s), 0x9b00dbd8u);
}

/* The stream's words are Philox blocks at successive low counters. */
static void test_stream_layout(void **state)
{
    (void)state;
    const uint64_t seed = 0x0123456789abcdefull, index = 0xfedcba9876543210ull;
    rng_stream s;
    rng_init(&s, seed, 5, RNG_PURPOSE_RENDER, index);
    for (uint32_t block = 0; block < 5; block++) {
        philox4x32_ctr_t c = {
            {block, (5u << 4) | RNG_PURPOSE_RENDER, (uint32_t)index, (uint32_t)(index >> 32)}};
        philox4x32_key_t k = {{(uint32_t)seed, (uint32_t)(seed >> 32)}};
        philox4x32_ctr_t r = philox4x32(c, k);
        for (int w = 0; w < 4; w++)
            assert_int_equal(rng_next_u32(&s), r.v[w]);
    }
}

/* rng_init_many's streams are rng_init's, word for word, past the blocks it computed
 * ahead and across a carry into the index's high word; at most RNG_MANY streams. */
static void test_init_many(void **state)
{
    (void)state;
    const uint64_t seed = 0x0123456789abcdefull, first = 0xfffffffaull; /* carries at +6 */
    for (unsigned blocks = 0; blocks <= RNG_BUFFER_BLOCKS + 1; blocks++) {
        for (size_t n = 1; n <= RNG_MANY; n += 5) {
            rng_stream many[RNG_MANY];
            rng_init_many(many, n, seed, 3, RNG_PURPOSE_PHOTON, first, blocks);
            for (size_t j = 0; j < n; j++) {
                rng_stream one;
                rng_init(&one, seed, 3, RNG_PURPOSE_PHOTON, first + j);
                for (int w = 0; w < 4 * (int)RNG_BUFFER_BLOCKS + 9; w++)
                    assert_int_equal(rng_next_u32(&many[j]), rng_next_u32(&one));
            }
        }
    }
    rng_stream many[RNG_MANY + 1];
    many[RNG_MANY].used = 12345u; /* beyond RNG_MANY: untouched */
    rng_init_many(many, RNG_MANY + 1, seed, 0, RNG_PURPOSE_PHOTON, 0, 2);
    assert_int_equal(many[RNG_MANY].used, 12345u);
}

static void test_keying(void **state)
{
    (void)state;
    /* the same key and index give the same numbers; changing any one part changes
     * them */
    rng_stream a, b;
    rng_init(&a, 9, 1, RNG_PURPOSE_PHOTON, 77);
    rng_init(&b, 9, 1, RNG_PURPOSE_PHOTON, 77);
    for (int i = 0; i < 100; i++)
        assert_true(rng_uniform(&a) == rng_uniform(&b));
    static const uint64_t variants[][4] = {
        {10, 1, RNG_PURPOSE_PHOTON, 77},
        {9, 2, RNG_PURPOSE_PHOTON, 77},
        {9, 1, RNG_PURPOSE_RENDER, 77},
        {9, 1, RNG_PURPOSE_PHOTON, 78},
        {9ull | 1ull << 40, 1, RNG_PURPOSE_PHOTON, 77},
        {9, 1, RNG_PURPOSE_PHOTON, 77ull | 1ull << 40},
    };
    for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
        rng_init(&a, 9, 1, RNG_PURPOSE_PHOTON, 77);
        rng_init(&b, variants[v][0], (uint32_t)variants[v][1], (uint32_t)variants[v][2],
                 variants[v][3]);
        int same = 0;
        for (int i = 0; i < 16; i++)
            same += rng_next_u32(&a) == rng_next_u32(&b);
        assert_true(same <= 1);
    }
}

static void test_uniform_distribution(void **state)
{
    (void)state;
    enum { bins = 64 };
    const size_t n = (size_t)(1000000 * test_scale());
    size_t count[bins] = {0};
    double sum = 0.0, sum2 = 0.0, lag = 0.0, prev = 0.5;
    rng_stream s;
    for (size_t i = 0; i < n; i++) {
        if (i % 1000 == 0) /* many short streams, as photons use them */
            rng_init(&s, 2024, 0, RNG_PURPOSE_TEST, i / 1000);
        double u = rng_uniform(&s);
        assert_true(u >= 0.0 && u < 1.0);
        assert_true(u * 9007199254740992.0 == floor(u * 9007199254740992.0)); /* 53 bits */
        count[(size_t)(u * bins)]++;
        sum += u;
        sum2 += u * u;
        lag += (u - 0.5) * (prev - 0.5);
        prev = u;
    }
    double dn = (double)n;
    double mean = sum / dn, var = sum2 / dn - mean * mean;
    /* standard errors: mean sqrt(1/12n), variance sqrt(1/180n), lag-1 covariance 1/(12 sqrt n) */
    assert_true(fabs(mean - 0.5) < 5.0 * sqrt(1.0 / (12.0 * dn)));
    assert_true(fabs(var - 1.0 / 12.0) < 5.0 * sqrt(1.0 / (180.0 * dn)));
    assert_true(fabs(lag / dn) < 5.0 / (12.0 * sqrt(dn)));
    double chi2 = 0.0, expect = dn / bins;
    for (int b = 0; b < bins; b++)
        chi2 += ((double)count[b] - expect) * ((double)count[b] - expect) / expect;
    /* 63 degrees of freedom: P(chi2 > 120) < 1e-5 */
    assert_true(chi2 < 120.0);
}

/* The photon phase's 32-bit uniform (docs/physics.md "Random streams"): one word each,
 * word / 2^32, so a stream of them is the stream of words, in [0, 1). */
static void test_uniform32(void **state)
{
    (void)state;
    rng_stream a, b;
    rng_init(&a, 11, 3, RNG_PURPOSE_PHOTON, 123456789);
    rng_init(&b, 11, 3, RNG_PURPOSE_PHOTON, 123456789);
    for (int i = 0; i < 4099; i++) {
        double u = rng_uniform32(&a);
        uint32_t w = rng_next_u32(&b);
        assert_true(u >= 0.0 && u < 1.0);
        assert_true(u * 4294967296.0 == (double)w);
    }
}

static void test_open0(void **state)
{
    (void)state;
    rng_stream s;
    rng_init(&s, 5, 0, RNG_PURPOSE_TEST, 1);
    for (int i = 0; i < 100000; i++) {
        double u = rng_uniform_open0(&s);
        assert_true(u > 0.0 && u <= 1.0);
        assert_true(isfinite(log(u)));
    }
    /* its ends, from words set by hand (2^-53 apart from rng_uniform's, too rare to meet by
     * drawing): two zero words give 1, not 0 and a log of -inf (the radiometer noise's
     * Box-Muller); two all-ones words give 2^-53, not 1 - 2^-53 */
    static const uint32_t ends[2] = {0u, UINT32_MAX};
    static const double want[2] = {1.0, 0x1p-53};
    for (int e = 0; e < 2; e++) {
        s.buf[0] = s.buf[1] = ends[e];
        s.used = 0;
        s.avail = 2;
        assert_true(rng_uniform_open0(&s) == want[e]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_answers),
        cmocka_unit_test(test_stream_layout),
        cmocka_unit_test(test_init_many),
        cmocka_unit_test(test_keying),
        cmocka_unit_test(test_uniform_distribution),
        cmocka_unit_test(test_uniform32),
        cmocka_unit_test(test_open0),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
