/* The classes' pixel statistics of band selection (analysis/bands_classes.c), by hand:
 * the pixel covariance about the class mean, the Monte Carlo variance taken out of it
 * (rows and columns scaled by sqrt(1 - mc / var), so that the diagonal is var - mc and
 * the correlations stay), the NETD^2 added to the diagonal, and the mean's Monte Carlo
 * variance. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>

#include "analysis/bands_values_internal.h"
#include "physics/planck.h"

/* One class of 4 pixels, two candidates (0.5 and 0.6 THz): Tb 299, 301, 299, 301 K
 * (mean 300, variance 4/3 K^2) with a standard error of 0.5 K each (mc = 0.25 K^2) in
 * candidate 0; 298, 302, 298, 302 K (variance 16/3) without one in candidate 1; their
 * covariance 8/3. After: var_0 = 4/3 - 1/4 = 13/12, var_1 = 16/3, cov = 8/3 x
 * sqrt(1 - 0.25 / (4/3)); NETD 0.2 and 0.1 K add 0.04 and 0.01 to the diagonal; the
 * mean's Monte Carlo variance is mc / 4. Scaling by 1 - mc / var instead of its square
 * root (a variance of (var - mc)^2 / var = 0.880) passed every test. */
static void test_pixel_covariance_by_hand(void **state)
{
    (void)state;
    enum { P = 4, N = 2 };
    const double thz[N] = {0.5, 0.6};
    float tb[N * P] = {299.0f, 301.0f, 299.0f, 301.0f, 298.0f, 302.0f, 298.0f, 302.0f};
    float se[N * P] = {0.0f};
    for (size_t p = 0; p < P; p++) /* 0.5 K through dB/dT at the pixel's Tb */
        se[p] = (float)(0.5 * planck_dbdt(thz[0] * 1e12, tb[p]));
    int32_t ids[P] = {0, 0, 0, 0}, cls[P] = {0, 0, 0, 0};
    bands_render r = {.tb = tb, .stderr_l = se, .ids = ids, .pixels = P, .has_stderr = true};
    bands_setup s = {.candidates_thz = thz, .n_candidates = N};
    uint64_t class_pixels[1] = {P};
    double mean[N] = {300.0, 300.0}, cov[N * N] = {0.0}, pixel_sd[N], mean_mc_var[N];
    double netd[N] = {0.2, 0.1}, x[N];
    bands_values v = {.n_candidates = N,
                      .n_classes = 1,
                      .class_pixels = class_pixels,
                      .mean = mean,
                      .cov = cov,
                      .pixel_sd = pixel_sd,
                      .mean_mc_var = mean_mc_var,
                      .netd_k = netd};
    bands_pixel_covariance(&r, cls, &s, &v, x);
    const double tol = 1e-6; /* the standard errors are floats */
    assert_true(fabs(cov[0] - (13.0 / 12.0 + 0.04)) < tol);
    assert_true(fabs(cov[3] - (16.0 / 3.0 + 0.01)) < tol);
    double c01 = 8.0 / 3.0 * sqrt(1.0 - 0.25 / (4.0 / 3.0));
    assert_true(fabs(cov[1] - c01) < tol && fabs(cov[2] - c01) < tol);
    assert_true(fabs(pixel_sd[0] - sqrt(13.0 / 12.0)) < tol);
    assert_true(fabs(pixel_sd[1] - sqrt(16.0 / 3.0)) < tol);
    assert_true(fabs(mean_mc_var[0] - 0.25 / 4.0) < tol);
    assert_true(mean_mc_var[1] == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pixel_covariance_by_hand),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
