/* Planck's law and its inverse against closed forms, limits and independently
 * computed values. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "physics/planck.h"

/* The same closed form evaluated in long double. */
static long double planck_ld(long double nu, long double t)
{
    const long double h = 6.62607015e-34L, k = 1.380649e-23L, c = 299792458.0L;
    return 2.0L * h * nu * nu * nu / (c * c) / expm1l(h * nu / (k * t));
}

static void test_matches_long_double(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i <= 60; i++) {
        double nu = 0.05e12 * pow(100.0, i / 60.0); /* 0.05 .. 5 THz */
        for (int j = 0; j <= 60; j++) {
            double t = pow(5000.0, j / 60.0); /* 1 .. 5000 K */
            long double ref = planck_ld(nu, t);
            double b = planck_radiance(nu, t);
            double rel = (double)fabsl(((long double)b - ref) / ref);
            if (rel > worst)
                worst = rel;
        }
    }
    assert_true(worst < 1e-12);
}

/* Values computed independently with Python's decimal module at 40 digits. */
static void test_exact_values(void **state)
{
    (void)state;
    static const struct {
        double nu, t, b;
    } v[] = {
        {1e12, 300.0, 8.499473904489865987e-14},
        {0.1e12, 4.0, 6.357002117770046765e-18},
        {3e12, 1000.0, 2.570840084729333581e-12},
        {0.5e12, 77.0, 5.040516216104664656e-15},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        double b = planck_radiance(v[i].nu, v[i].t);
        assert_true(fabs(b - v[i].b) <= 1e-13 * v[i].b);
    }
}

static void test_rayleigh_jeans_limit(void **state)
{
    (void)state;
    const double h = THZ_PLANCK_H, k = THZ_BOLTZMANN_K, c = THZ_SPEED_OF_LIGHT;
    static const double nus[] = {0.05e12, 0.1e12, 0.3e12};
    static const double ts[] = {300.0, 1000.0, 5000.0};
    for (size_t i = 0; i < 3; i++) {
        for (size_t j = 0; j < 3; j++) {
            double nu = nus[i], t = ts[j];
            double x = h * nu / (k * t);
            double rj = 2.0 * nu * nu * k * t / (c * c);
            double rel = (rj - planck_radiance(nu, t)) / rj;
            assert_true(rel > 0.0);
            assert_true(rel <= 0.5 * x * 1.01);
            /* and the leading term really is x/2 (not x or x/4) */
            assert_true(rel >= 0.5 * x * 0.9);
        }
    }
}

static void test_wien_limit(void **state)
{
    (void)state;
    const double h = THZ_PLANCK_H, k = THZ_BOLTZMANN_K, c = THZ_SPEED_OF_LIGHT;
    static const double cases[][2] = {{5e12, 16.0}, {3e12, 12.0}, {1e12, 4.5}, {2e12, 7.0}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double nu = cases[i][0], t = cases[i][1];
        double x = h * nu / (k * t);
        assert_true(x > 10.0 && x < 16.0);
        double wien = 2.0 * h * nu * nu * nu / (c * c) * exp(-x);
        double rel = (planck_radiance(nu, t) - wien) / wien;
        /* B / B_Wien - 1 = 1/(1 - e^-x) - 1 ~ e^-x */
        assert_true(rel > 0.0);
        assert_true(rel <= exp(-x) * 1.01);
    }
}

static void test_zero_and_negative(void **state)
{
    (void)state;
    assert_true(planck_radiance(1e12, 0.0) == 0.0);
    assert_true(planck_radiance(1e12, -5.0) == 0.0);
    assert_true(planck_brightness_temperature(1e12, 0.0) == 0.0);
    assert_true(planck_brightness_temperature(1e12, -1e-15) == 0.0);
    /* Tiny T: the radiance underflows to 0 rather than producing NaN. */
    double b = planck_radiance(5e12, 0.01);
    assert_true(b == 0.0 || (b > 0.0 && isfinite(b)));
}

/* Frequencies so low that h nu / k T underflows (a channel may be anywhere above 0 THz):
 * the Rayleigh-Jeans limit, which underflows to 0 too, not 0/0 = NaN (a NaN there made
 * the band mean's adaptive quadrature split every panel 40 levels deep: a scene with a
 * channel at 1e-301 THz hung in validate). Likewise dB/dT, and dB/dT beyond the Wien
 * tail's overflow (x > 709.8), where it was 0 * inf. */
static void test_extreme_arguments(void **state)
{
    (void)state;
    static const double nus[] = {1e-290, 1e-300, 5e-324};
    static const double ts[] = {1e-3, 300.0, 1e6};
    for (size_t i = 0; i < 3; i++)
        for (size_t j = 0; j < 3; j++) {
            double b = planck_radiance(nus[i], ts[j]), d = planck_dbdt(nus[i], ts[j]);
            assert_true(isfinite(b) && b >= 0.0);
            assert_true(isfinite(d) && d >= 0.0);
        }
    /* 10 THz at 0.65 K: x = 738, e^x overflows */
    double d = planck_dbdt(10e12, 0.65);
    assert_true(isfinite(d) && d >= 0.0);
    /* and where nothing underflows, dB/dT is still the closed form's */
    double t = 300.0, nu = 1e12, dt = 1e-3;
    double fd = (planck_radiance(nu, t + dt) - planck_radiance(nu, t - dt)) / (2.0 * dt);
    assert_true(fabs(planck_dbdt(nu, t) - fd) <= 1e-6 * fd);
}

static void test_round_trip(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i <= 40; i++) {
        double nu = 0.05e12 * pow(100.0, i / 40.0);
        for (int j = 0; j <= 40; j++) {
            double t = pow(5000.0, j / 40.0);
            double tb = planck_brightness_temperature(nu, planck_radiance(nu, t));
            double d = fabs(tb - t);
            if (d > worst)
                worst = d;
        }
    }
    assert_true(worst < 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_long_double),  cmocka_unit_test(test_exact_values),
        cmocka_unit_test(test_rayleigh_jeans_limit), cmocka_unit_test(test_wien_limit),
        cmocka_unit_test(test_zero_and_negative),    cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_extreme_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
