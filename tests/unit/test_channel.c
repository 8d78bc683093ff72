/* Channels: widths, response, band-mean quadrature and frequency sampling. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/rng.h"
#include "physics/channel.h"

static const thz_channel ch_default = {.name = "c1", .center_hz = 1.0e12, .relative_width = 0.1};

static double f_const(double nu, void *ctx)
{
    (void)nu;
    return *(const double *)ctx;
}

static double f_linear(double nu, void *ctx)
{
    (void)ctx;
    return 3.0 + 2.0e-12 * nu;
}

static double f_response(double nu, void *ctx)
{
    return channel_response((const thz_channel *)ctx, nu);
}

/* A triangular line of peak 1 and half-width half_width_hz at centre_hz. */
typedef struct triangle {
    double centre_hz, half_width_hz;
} triangle;

static double f_triangle(double nu, void *ctx)
{
    const triangle *t = ctx;
    double d = fabs(nu - t->centre_hz) / t->half_width_hz;
    return d < 1.0 ? 1.0 - d : 0.0;
}

static void test_widths(void **state)
{
    (void)state;
    /* FWHM = w nu_c: the response is 1/2 at nu_c +- FWHM/2 */
    double fwhm = ch_default.relative_width * ch_default.center_hz;
    assert_true(fabs(channel_response(&ch_default, ch_default.center_hz + 0.5 * fwhm) - 0.5) <
                1e-14);
    assert_true(fabs(channel_response(&ch_default, ch_default.center_hz - 0.5 * fwhm) - 0.5) <
                1e-14);
    assert_true(channel_response(&ch_default, ch_default.center_hz) == 1.0);
    double sigma = fwhm / (2.0 * sqrt(2.0 * log(2.0)));
    assert_true(fabs(channel_sigma_hz(&ch_default) - sigma) < 1e-14 * sigma);
    assert_true(fabs(channel_bandwidth_hz(&ch_default) - sigma * sqrt(2.0 * M_PI)) < 1e-14 * sigma);
}

static void test_band_mean_constant_and_linear(void **state)
{
    (void)state;
    double k = 0.123456789;
    assert_true(fabs(channel_band_mean(&ch_default, f_const, &k) - k) < 1e-16);
    double centre = 3.0 + 2.0e-12 * ch_default.center_hz;
    assert_true(fabs(channel_band_mean(&ch_default, f_linear, NULL) - centre) < 1e-10 * centre);
}

static void test_band_mean_of_response(void **state)
{
    (void)state;
    /* int g^2 / int g = 1/sqrt(2). The quadrature spans +-6 sigma, which drops
     * P(|z| > 6) = 1.97e-9 of int g: allowance 2.5e-9. */
    const thz_channel chs[] = {{.name = "a", .center_hz = 1e12, .relative_width = 0.1},
                               {.name = "b", .center_hz = 0.3e12, .relative_width = 0.02},
                               {.name = "c", .center_hz = 2.5e12, .relative_width = 0.3}};
    for (size_t i = 0; i < 3; i++) {
        double m = channel_band_mean(&chs[i], f_response, (void *)&chs[i]);
        assert_true(fabs(m - M_SQRT1_2) < 2.5e-9);
    }
}

/* int over [z1, z2] of (p + q z) exp(-z^2/2) dz */
static double gauss_linear_integral(double p, double q, double z1, double z2)
{
    return p * sqrt(M_PI / 2.0) * (erf(z2 / M_SQRT2) - erf(z1 / M_SQRT2)) +
           q * (exp(-0.5 * z1 * z1) - exp(-0.5 * z2 * z2));
}

static void test_narrow_line(void **state)
{
    (void)state;
    const thz_channel *ch = &ch_default;
    double sigma = channel_sigma_hz(ch);
    static const double offsets[] = {1.3, -0.77, 0.0, 2.1};
    for (size_t i = 0; i < 4; i++) {
        /* a line of full width sigma/10 (half-width sigma/20) */
        triangle t = {ch->center_hz + offsets[i] * sigma, sigma / 20.0};
        double z0 = offsets[i], a = 1.0 / 20.0; /* in units of sigma */
        /* rising edge: 1 + (z - z0)/a ; falling edge: 1 - (z - z0)/a */
        double num = gauss_linear_integral(1.0 - z0 / a, 1.0 / a, z0 - a, z0) +
                     gauss_linear_integral(1.0 + z0 / a, -1.0 / a, z0, z0 + a);
        double exact = num / sqrt(2.0 * M_PI);
        double m = channel_band_mean(ch, f_triangle, &t);
        assert_true(fabs(m - exact) < 1e-6 * exact);
    }
}

static void test_quadrature_struct(void **state)
{
    (void)state;
    channel_quadrature q;
    thz_error err;
    assert_int_equal(channel_quadrature_init(&q, &ch_default, CHANNEL_QUADRATURE_NODES, &err),
                     THZ_OK);
    assert_int_equal(q.n, CHANNEL_QUADRATURE_NODES);
    double sum = 0.0, num = 0.0;
    for (size_t i = 0; i < q.n; i++) {
        sum += q.weight[i];
        num += q.weight[i] * channel_response(&ch_default, q.freq_hz[i]);
        /* symmetric about the centre */
        double mirror = 2.0 * ch_default.center_hz - q.freq_hz[q.n - 1 - i];
        assert_true(fabs(q.freq_hz[i] - mirror) < 1e-3);
        assert_true(q.weight[i] == q.weight[q.n - 1 - i]);
    }
    assert_true(fabs(sum - 1.0) < 1e-14);
    double sigma = channel_sigma_hz(&ch_default);
    assert_true(fabs(q.freq_hz[0] - (ch_default.center_hz - 6.0 * sigma)) < 1e-3);
    double m = channel_band_mean(&ch_default, f_response, (void *)&ch_default);
    assert_true(fabs(num - m) < 1e-9); /* fixed rule vs adaptive refinement */
    channel_quadrature_fini(&q);
    assert_null(q.weight);

    /* Even n is rounded up to odd; a wide channel keeps only positive nodes. */
    thz_channel wide = {.name = "w", .center_hz = 1e12, .relative_width = 0.5};
    assert_int_equal(channel_quadrature_init(&q, &wide, 100, &err), THZ_OK);
    assert_true(q.n <= 101);
    for (size_t i = 0; i < q.n; i++)
        assert_true(q.freq_hz[i] > 0.0);
    channel_quadrature_fini(&q);
}

static void test_sampling(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "s", .center_hz = 0.8e12, .relative_width = 0.2};
    const double sigma = channel_sigma_hz(&ch);
    const double scale = getenv("THZ_TEST_SCALE") ? atof(getenv("THZ_TEST_SCALE")) : 1.0;
    const size_t n = (size_t)(1e6 * (scale > 0.0 && scale <= 1.0 ? scale : 1.0));
    rng_stream rng;
    rng_init(&rng, 42, 0, RNG_PURPOSE_TEST, 0);
    double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
    size_t within_1sigma = 0;
    for (size_t i = 0; i < n; i++) {
        double u1 = rng_uniform(&rng), u2 = rng_uniform(&rng);
        double nu = channel_sample_hz(&ch, u1, u2);
        assert_true(nu > 0.0);
        double z = (nu - ch.center_hz) / sigma;
        sum += z;
        sum2 += z * z;
        sum4 += z * z * z * z;
        within_1sigma += fabs(z) < 1.0;
    }
    double dn = (double)n;
    double mean = sum / dn, var = sum2 / dn - mean * mean;
    /* standard errors: mean 1/sqrt(n); variance sqrt(2/n); fraction sqrt(p(1-p)/n) */
    assert_true(fabs(mean) < 5.0 / sqrt(dn));
    assert_true(fabs(var - 1.0) < 5.0 * sqrt(2.0 / dn));
    assert_true(fabs(sum4 / dn - 3.0) < 5.0 * sqrt(96.0 / dn));
    double p = erf(M_SQRT1_2);
    assert_true(fabs((double)within_1sigma / dn - p) < 5.0 * sqrt(p * (1.0 - p) / dn));

    /* u1 = 0 must not produce an infinity; results stay positive for a wide channel */
    const thz_channel wide = {.name = "w", .center_hz = 1e12, .relative_width = 0.5};
    for (int i = 0; i < 64; i++) {
        double nu = channel_sample_hz(&wide, i / 64.0, (i * 37 % 64) / 64.0);
        assert_true(isfinite(nu) && nu > 0.0);
    }
    assert_true(isfinite(channel_sample_hz(&ch, 0.0, 0.0)));
    assert_true(channel_sample_hz(&wide, 1.0 - 1e-16, 0.5) > 0.0);
}

/* channel_sample_many_hz gives channel_sample_hz's frequencies bit for bit: every
 * quadrant of the cosine (u2 at and beside the quarter turns), u1 at both ends of the
 * 32-bit grid, and the reflected tail of a channel wider than its centre; batches of every
 * size up to 16. (A measured response's table is sampled one at a time by both.) */
static void test_sampling_many(void **state)
{
    (void)state;
    const thz_channel gauss = {.name = "s", .center_hz = 0.8e12, .relative_width = 0.2};
    const thz_channel wide = {.name = "w", .center_hz = 1e12, .relative_width = 3.0};
    const thz_channel *chans[2] = {&gauss, &wide};
    const double edges[] = {0.0,         0x1p-32,     0.125,          0.25 - 0x1p-32, 0.25,
                            0.25 + 1e-9, 0.5,         0.75 - 0x1p-32, 0.75,           0.875,
                            0.999,       1 - 0x1p-31, 1 - 0x1p-32};
    const size_t ne = sizeof edges / sizeof edges[0];
    for (int c = 0; c < 2; c++) {
        double u1[256], u2[256], many[256];
        size_t m = 0;
        for (size_t a = 0; a < ne; a++)
            for (size_t b = 0; b < ne; b++, m++) {
                u1[m] = edges[a];
                u2[m] = edges[b];
            }
        /* every pair, in batches of 1, 2, ..., 16, 1, ... */
        for (size_t off = 0, k = 0; off < m; off += 1 + k % 16, k++) {
            size_t n = 1 + k % 16 < m - off ? 1 + k % 16 : m - off;
            channel_sample_many_hz(chans[c], u1 + off, u2 + off, n, many);
            for (size_t j = 0; j < n; j++) {
                double one = channel_sample_hz(chans[c], u1[off + j], u2[off + j]);
                if (memcmp(&one, &many[j], sizeof one) != 0)
                    fail_msg("channel %d, u1 = %.17g, u2 = %.17g: %.17g, one at a time %.17g", c,
                             u1[off + j], u2[off + j], many[j], one);
            }
        }
    }
}

/* Box-Muller's libm-free log and cos against libm's: the same frequencies to 1e-14 of
 * sigma, over every 32-bit u1 near 0 and 1 (the log's extremes) and a grid of both. */
static void test_sampling_against_libm(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "s", .center_hz = 0.8e12, .relative_width = 0.2};
    const double sigma = channel_sigma_hz(&ch);
    for (uint64_t i = 0; i < 3000000; i++) {
        uint64_t k1 = i < 1000 ? i : i < 2000 ? 0xffffffffull - (i - 1000) : i * 1431655;
        double u1 = (double)(k1 & 0xffffffffull) * 0x1p-32;
        double u2 = (double)((i * 2654435761ull) & 0xffffffffull) * 0x1p-32;
        double z = sqrt(-2.0 * log(1.0 - u1)) * cos(2.0 * M_PI * u2);
        double got = (channel_sample_hz(&ch, u1, u2) - ch.center_hz) / sigma;
        if (!(fabs(got - z) <= 1e-14 * (1.0 + fabs(z))))
            fail_msg("u1 = %.17g, u2 = %.17g: z = %.17g, libm %.17g", u1, u2, got, z);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_widths),
        cmocka_unit_test(test_band_mean_constant_and_linear),
        cmocka_unit_test(test_band_mean_of_response),
        cmocka_unit_test(test_narrow_line),
        cmocka_unit_test(test_quadrature_struct),
        cmocka_unit_test(test_sampling),
        cmocka_unit_test(test_sampling_against_libm),
        cmocka_unit_test(test_sampling_many),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
