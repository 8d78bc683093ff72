/* Channels with a measured response table (scene-format.md "Channels: measured spectral
 * response") and the noise bandwidth of both kinds: B_c, B_n, FWHM and centre against
 * closed forms, the response itself, the support, band means (fixed and adaptive) and
 * exact sampling of the piecewise-linear density (chi-square with a fixed seed). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "core/rng.h"
#include "physics/channel.h"

/* Relative closeness. */
static int close_rel(double a, double b, double rel)
{
    return fabs(a - b) <= rel * fabs(b);
}

/* A table channel from points in THz. */
static thz_channel table_channel(const double *thz, const double *w, size_t n, double centre_thz)
{
    thz_channel ch = {.name = "t"};
    double f[64];
    assert_true(n <= 64);
    for (size_t i = 0; i < n; i++)
        f[i] = thz[i] * 1e12;
    thz_error err;
    assert_int_equal(channel_set_response(&ch, n, f, w, centre_thz * 1e12, &err), THZ_OK);
    return ch;
}

static double f_const(double nu, void *ctx)
{
    (void)nu;
    return *(const double *)ctx;
}

static double f_nu(double nu, void *ctx)
{
    (void)ctx;
    return nu;
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

static void test_gaussian_noise_bandwidth(void **state)
{
    (void)state;
    /* B_n = 2 sqrt(pi) sigma = 2 sqrt(pi) / (2 sqrt(2 ln 2)) FWHM = 1.5054 FWHM */
    const thz_channel chs[] = {{.name = "a", .center_hz = 0.35e12, .relative_width = 0.01},
                               {.name = "b", .center_hz = 1.2e12, .relative_width = 0.2}};
    for (size_t i = 0; i < 2; i++) {
        double fwhm = chs[i].relative_width * chs[i].center_hz;
        assert_true(close_rel(channel_noise_bandwidth_hz(&chs[i]), 1.5054 * fwhm, 1e-4));
        assert_true(close_rel(channel_noise_bandwidth_hz(&chs[i]),
                              sqrt(M_PI / (2.0 * log(2.0))) * fwhm, 1e-14));
        assert_true(
            close_rel(channel_bandwidth_hz(&chs[i]), sqrt(M_PI / (4.0 * log(2.0))) * fwhm, 1e-14));
        assert_true(channel_fwhm_hz(&chs[i]) == fwhm);
        assert_false(channel_has_response(&chs[i]));
    }
}

static void test_top_hat(void **state)
{
    (void)state;
    const double thz[] = {0.34, 0.36}, w[] = {3.0, 3.0}; /* a top-hat of height 3 */
    thz_channel ch = table_channel(thz, w, 2, 0.0);
    const double width = 0.02e12;
    assert_true(channel_has_response(&ch));
    assert_true(ch.relative_width == 0.0);
    /* B_c = int g keeps the weights' scale, B_n and the FWHM do not depend on it */
    assert_true(close_rel(channel_bandwidth_hz(&ch), 3.0 * width, 1e-12));
    assert_true(close_rel(channel_noise_bandwidth_hz(&ch), width, 1e-12));
    assert_true(close_rel(channel_fwhm_hz(&ch), width, 1e-12));
    assert_true(close_rel(ch.center_hz, 0.35e12, 1e-14)); /* the response-weighted mean */
    assert_true(close_rel(channel_sigma_hz(&ch) * sqrt(2.0 * M_PI), 3.0 * width, 1e-14));
    assert_true(channel_response(&ch, 0.345e12) == 3.0);
    assert_true(channel_response(&ch, 0.34e12) == 3.0);
    assert_true(channel_response(&ch, 0.36e12) == 3.0);
    assert_true(channel_response(&ch, 0.3399e12) == 0.0); /* 0 outside the table */
    assert_true(channel_response(&ch, 0.3601e12) == 0.0);
    double lo, hi;
    channel_support_hz(&ch, 6.0, &lo, &hi);
    assert_true(lo == 0.34e12 && hi == 0.36e12);
    channel_fini(&ch);
    assert_false(channel_has_response(&ch));
    channel_fini(NULL);
}

static void test_triangles_and_trapezoid(void **state)
{
    (void)state;
    /* An asymmetric triangle a < b < c: int g = (c - a) / 2, int g^2 = (c - a) / 3, so
     * B_n = 3 (c - a) / 4; centre (a + b + c) / 3; FWHM (c - a) / 2. Zeros around it
     * do not change anything but the table's extent. */
    const double thz[] = {0.2, 0.5, 0.58, 0.6, 0.66, 0.9}, w[] = {0, 0, 0, 1, 0, 0};
    thz_channel ch = table_channel(thz, w, 6, 0.0);
    double a = 0.58e12, b = 0.6e12, c = 0.66e12;
    assert_true(close_rel(channel_bandwidth_hz(&ch), (c - a) / 2.0, 1e-12));
    assert_true(close_rel(channel_noise_bandwidth_hz(&ch), 0.75 * (c - a), 1e-12));
    assert_true(close_rel(ch.center_hz, (a + b + c) / 3.0, 1e-12));
    assert_true(close_rel(channel_fwhm_hz(&ch), (c - a) / 2.0, 1e-12));
    assert_true(close_rel(channel_response(&ch, 0.59e12), 0.5, 1e-12));
    assert_true(close_rel(channel_response(&ch, 0.63e12), 0.5, 1e-12));
    double lo, hi;
    channel_support_hz(&ch, 6.0, &lo, &hi);
    assert_true(lo == a && hi == c);
    channel_fini(&ch);

    /* A trapezoid 0 -> h over r, h over p, h -> 0 over r (h = 5): int g = h (p + r),
     * int g^2 = h^2 (p + 2 r / 3); a given centre stays as given. */
    const double tz[] = {1.0, 1.01, 1.05, 1.06}, tw[] = {0, 5, 5, 0};
    ch = table_channel(tz, tw, 4, 1.02);
    double r = 0.01e12, p = 0.04e12;
    assert_true(close_rel(channel_bandwidth_hz(&ch), 5.0 * (p + r), 1e-12));
    assert_true(
        close_rel(channel_noise_bandwidth_hz(&ch), (p + r) * (p + r) / (p + 2.0 * r / 3.0), 1e-12));
    assert_true(ch.center_hz == 1.02e12);
    assert_true(close_rel(channel_fwhm_hz(&ch), p + r, 1e-12));
    channel_fini(&ch);

    /* Flanks that do not start from 0: g rises 0.2 -> 1 over [1.00, 1.08] THz and falls
     * 1 -> 0.4 over [1.10, 1.16]: half the peak is crossed at 1.00 + 0.08 x 0.3 / 0.8 and
     * 1.10 + 0.06 x 0.5 / 0.6 THz. */
    const double fz[] = {1.0, 1.08, 1.10, 1.16}, fw[] = {0.2, 1.0, 1.0, 0.4};
    ch = table_channel(fz, fw, 4, 0.0);
    assert_true(close_rel(channel_fwhm_hz(&ch), (1.15 - 1.03) * 1e12, 1e-12));
    channel_fini(&ch);

    /* bad tables are refused (the loader's messages are tested with the loader) */
    thz_channel bad = {.name = "bad"};
    thz_error err;
    const double f2[] = {1e12, 2e12}, zero[] = {0, 0}, neg[] = {1, -1}, down[] = {2e12, 1e12};
    assert_int_equal(channel_set_response(&bad, 2, f2, zero, 0.0, &err), THZ_ERR_INPUT);
    assert_int_equal(channel_set_response(&bad, 2, f2, neg, 0.0, &err), THZ_ERR_INPUT);
    assert_int_equal(channel_set_response(&bad, 2, down, tw, 0.0, &err), THZ_ERR_INPUT);
    const double same[] = {1e12, 1e12, 2e12}, w3[] = {1, 1, 1}; /* strictly increasing */
    assert_int_equal(channel_set_response(&bad, 3, same, w3, 0.0, &err), THZ_ERR_INPUT);
    assert_int_equal(channel_set_response(&bad, 1, f2, tw + 1, 0.0, &err), THZ_ERR_INPUT);
    assert_false(channel_has_response(&bad));
}

static void test_band_means(void **state)
{
    (void)state;
    const double thz[] = {0.30, 0.31, 0.32, 0.33, 0.34, 0.35, 0.36, 0.37},
                 w[] = {0, 1, 0.5, 0.5, 0, 0, 2, 0};
    thz_channel ch = table_channel(thz, w, 8, 0.0);
    double k = 2.5;
    assert_true(fabs(channel_band_mean(&ch, f_const, &k) - k) < 1e-15);
    /* the band mean of nu is the centre (Simpson is exact for the quadratic g nu) */
    assert_true(close_rel(channel_band_mean(&ch, f_nu, NULL), ch.center_hz, 1e-13));

    channel_quadrature q;
    thz_error err;
    assert_int_equal(channel_quadrature_init(&q, &ch, CHANNEL_QUADRATURE_NODES, &err), THZ_OK);
    assert_true(q.n >= 300 && q.n <= CHANNEL_QUADRATURE_NODES + 16);
    double sw = 0.0, snu = 0.0;
    for (size_t i = 0; i < q.n; i++) {
        assert_true(q.freq_hz[i] >= 0.30e12 && q.freq_hz[i] <= 0.37e12);
        assert_true(i == 0 || q.freq_hz[i] > q.freq_hz[i - 1]);
        assert_true(q.weight[i] >= 0.0);
        sw += q.weight[i];
        snu += q.weight[i] * q.freq_hz[i];
    }
    assert_true(fabs(sw - 1.0) < 1e-14);
    assert_true(close_rel(snu, ch.center_hz, 1e-13));
    channel_quadrature_fini(&q);
    channel_fini(&ch);

    /* A narrow line inside a top-hat: the band mean is the line's area over the width,
     * wherever the line sits, to 1e-6 (adaptive), and a line outside counts nothing. */
    const double th[] = {0.34, 0.36}, one[] = {1, 1};
    ch = table_channel(th, one, 2, 0.0);
    const double places[] = {0.3405e12, 0.3501234e12, 0.3593e12};
    for (size_t i = 0; i < 3; i++) {
        triangle t = {places[i], 0.02e9}; /* area 0.02 GHz over 20 GHz: 1e-3 */
        assert_true(close_rel(channel_band_mean(&ch, f_triangle, &t), 1e-3, 1e-6));
    }
    triangle out = {0.37e12, 0.02e9};
    assert_true(channel_band_mean(&ch, f_triangle, &out) == 0.0);
    channel_fini(&ch);
}

/* The histogram of sampled frequencies against the table's density: g is linear
 * within each 1 GHz bin (the table's points are bin edges), so the probability of a bin
 * is exactly its trapezoid over B_c. */
static void test_sampling_chi_square(void **state)
{
    (void)state;
    const double thz[] = {0.30, 0.31, 0.32, 0.33, 0.34, 0.35, 0.36, 0.37},
                 w[] = {0, 1, 0.5, 0.5, 0, 0, 2, 0};
    thz_channel ch = table_channel(thz, w, 8, 0.0);
    enum { bins = 70 }; /* 1 GHz each, 10 per piece */
    const double lo = 0.30e12, step = 1e9;
    const double scale = getenv("THZ_TEST_SCALE") ? atof(getenv("THZ_TEST_SCALE")) : 1.0;
    const size_t n = (size_t)(400000 * (scale > 0.0 && scale <= 1.0 ? scale : 1.0));
    size_t count[bins] = {0};
    rng_stream rng;
    rng_init(&rng, 7, 0, RNG_PURPOSE_TEST, 0);
    for (size_t i = 0; i < n; i++) {
        double nu = channel_sample_hz(&ch, rng_uniform(&rng), rng_uniform(&rng));
        assert_true(nu >= 0.30e12 && nu <= 0.37e12);
        size_t b = (size_t)((nu - lo) / step);
        count[b < bins ? b : bins - 1]++;
    }
    double total = channel_bandwidth_hz(&ch), chi2 = 0.0;
    size_t dof = 0;
    for (size_t b = 0; b < bins; b++) {
        double x0 = lo + step * (double)b, x1 = x0 + step;
        double p = 0.5 * step * (channel_response(&ch, x0 + 1.0) + channel_response(&ch, x1 - 1.0));
        p /= total;
        double expect = p * (double)n;
        if (expect == 0.0) {
            assert_int_equal(count[b], 0); /* never where g = 0 (0.34 to 0.35 THz) */
            continue;
        }
        chi2 += ((double)count[b] - expect) * ((double)count[b] - expect) / expect;
        dof++;
    }
    dof -= 1;
    /* chi-square with dof degrees of freedom: mean dof, sd sqrt(2 dof); 5 sd */
    print_message("chi-square %.1f for %zu degrees of freedom\n", chi2, dof);
    assert_true(chi2 < (double)dof + 5.0 * sqrt(2.0 * (double)dof));
    channel_fini(&ch);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gaussian_noise_bandwidth), cmocka_unit_test(test_top_hat),
        cmocka_unit_test(test_triangles_and_trapezoid),  cmocka_unit_test(test_band_means),
        cmocka_unit_test(test_sampling_chi_square),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
