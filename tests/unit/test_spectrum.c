/* Spectra: constants, tables with linear interpolation and end values, copies. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "physics/spectrum.h"

static void test_absent_and_constant(void **state)
{
    (void)state;
    thz_spectrum s = {0};
    assert_true(spectrum_eval(&s, 1e12) == 0.0);
    double lo = -1, hi = -1;
    spectrum_range(&s, &lo, &hi);
    assert_true(lo == 0.0 && hi == 0.0);
    assert_false(spectrum_table_exceeded(&s, 0.0, 1e15));
    assert_true(spectrum_set_constant(&s, 0.25));
    assert_int_equal(s.n, 1);
    assert_true(spectrum_eval(&s, 1e9) == 0.25);
    assert_true(spectrum_eval(&s, 7e12) == 0.25);
    spectrum_range(&s, &lo, &hi);
    assert_true(lo == 0.25 && hi == 0.25);
    assert_false(spectrum_table_exceeded(&s, 0.0, 1e15));
    spectrum_fini(&s);
    assert_int_equal(s.n, 0);
    assert_null(s.value);
    spectrum_fini(&s); /* twice is harmless */
}

static void test_table(void **state)
{
    (void)state;
    const double f[] = {1e12, 2e12, 4e12};
    const double v[] = {0.1, 0.5, 0.3};
    thz_spectrum s = {0};
    assert_true(spectrum_set_table(&s, 3, f, v));
    assert_int_equal(s.n, 3);
    /* beyond the ends: end values */
    assert_true(spectrum_eval(&s, 0.5e12) == 0.1);
    assert_true(spectrum_eval(&s, 9e12) == 0.3);
    /* at the nodes: exact */
    assert_true(spectrum_eval(&s, 1e12) == 0.1);
    assert_true(spectrum_eval(&s, 2e12) == 0.5);
    assert_true(spectrum_eval(&s, 4e12) == 0.3);
    /* between: linear */
    assert_true(fabs(spectrum_eval(&s, 1.5e12) - 0.3) < 1e-15);
    assert_true(fabs(spectrum_eval(&s, 1.25e12) - 0.2) < 1e-15);
    assert_true(fabs(spectrum_eval(&s, 3e12) - 0.4) < 1e-15);
    assert_true(fabs(spectrum_eval(&s, 3.5e12) - 0.35) < 1e-15);
    double lo, hi;
    spectrum_range(&s, &lo, &hi);
    assert_true(lo == 0.1 && hi == 0.5);
    assert_false(spectrum_table_exceeded(&s, 1e12, 4e12));
    assert_true(spectrum_table_exceeded(&s, 0.9e12, 3e12));
    assert_true(spectrum_table_exceeded(&s, 1.1e12, 4.1e12));

    thz_spectrum c = {0};
    assert_true(spectrum_copy(&c, &s));
    assert_true(c.value != s.value && c.freq_hz != s.freq_hz);
    spectrum_fini(&s);
    assert_true(fabs(spectrum_eval(&c, 3e12) - 0.4) < 1e-15);
    /* replacing a table by a constant frees the table */
    assert_true(spectrum_set_constant(&c, 2.0));
    assert_null(c.freq_hz);
    assert_true(spectrum_eval(&c, 3e12) == 2.0);
    spectrum_fini(&c);
}

static void test_two_point_and_copy_absent(void **state)
{
    (void)state;
    const double f[] = {1e12, 3e12};
    const double v[] = {1.0, 0.0};
    thz_spectrum s = {0}, c = {0};
    assert_true(spectrum_set_table(&s, 2, f, v));
    assert_true(fabs(spectrum_eval(&s, 2.5e12) - 0.25) < 1e-15);
    thz_spectrum absent = {0};
    assert_true(spectrum_copy(&c, &s));
    assert_true(spectrum_copy(&c, &absent));
    assert_int_equal(c.n, 0);
    assert_true(spectrum_eval(&c, 2e12) == 0.0);
    spectrum_fini(&s);
    spectrum_fini(&c);
}

/* The interpolation by the interval lookup of spectrum_interval (the reference). */
static double reference_eval(const double *f, const double *v, size_t n, double x)
{
    if (!(x > f[0]))
        return v[0];
    if (!(x < f[n - 1]))
        return v[n - 1];
    size_t lo = spectrum_interval(f, n, x);
    return v[lo] + (x - f[lo]) / (f[lo + 1] - f[lo]) * (v[lo + 1] - v[lo]);
}

/* An even grid (the guessed interval) and an uneven one (bisection) give bit for bit
 * what the bisection gives, at the nodes, next to them and between them. */
static void test_even_grid_lookup(void **state)
{
    (void)state;
    enum { N = 55 };
    double f[N], g[N], v[N];
    for (size_t i = 0; i < N; i++) {
        f[i] = 0.1e12 + (double)i * 0.025e12; /* as a CSV in THz, every 25 GHz */
        g[i] = 0.1e12 + (double)(i * i) * 1e9;
        v[i] = sin((double)i);
    }
    thz_spectrum even = {0}, uneven = {0};
    assert_true(spectrum_set_table(&even, N, f, v));
    assert_true(spectrum_set_table(&uneven, N, g, v));
    assert_true(even.inv_step_per_hz > 0.0);
    assert_true(uneven.inv_step_per_hz == 0.0);
    for (size_t i = 0; i < N; i++)
        for (int d = -3; d <= 3; d++) {
            double x = f[i] + (double)d * (d % 2 ? 1.0 : 1e6);
            assert_true(spectrum_eval(&even, x) == reference_eval(f, v, N, x));
            double y = g[i] + (double)d * (d % 2 ? 1.0 : 1e6);
            assert_true(spectrum_eval(&uneven, y) == reference_eval(g, v, N, y));
        }
    for (int k = 0; k < 100000; k++) {
        double x = 0.09e12 + k * 1.41421e7;
        assert_true(spectrum_eval(&even, x) == reference_eval(f, v, N, x));
    }
    thz_spectrum copy = {0};
    assert_true(spectrum_copy(&copy, &even));
    assert_true(copy.inv_step_per_hz == even.inv_step_per_hz);
    spectrum_fini(&even);
    assert_true(even.inv_step_per_hz == 0.0);
    spectrum_fini(&uneven);
    spectrum_fini(&copy);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_absent_and_constant),
        cmocka_unit_test(test_table),
        cmocka_unit_test(test_two_point_and_copy_absent),
        cmocka_unit_test(test_even_grid_lookup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
