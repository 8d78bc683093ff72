/* Complex indices (permittivity.h, material_index.h) against closed forms and
 * independent numbers: Debye limits and its value at omega tau = 1; liquid water's
 * double-Debye model (Liebe 1991 at 25 °C) against Segelstein's measured n, k; Drude
 * aluminium (Ordal 1983's fit) against Ordal 1988's measurement, its DC-conductivity
 * limit and k >> n above the collision frequency; a Lorentz line at and away from
 * resonance; the square root; the ITU-R P.2040 formula and range coverage; tables. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "physics/material_index.h"
#include "physics/permittivity.h"

#define EPS0 8.8541878128e-12

static void expect_rel(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol * fabs(want)))
        fail_msg("%s: got %.9g, want %.9g (relative tolerance %g)", what, got, want, tol);
}

static void test_debye(void **state)
{
    (void)state;
    permittivity_model m = {
        .kind = PERMITTIVITY_DEBYE, .eps_inf = 3.0, .eps_s = 70.0, .tau1_s = 8e-12};
    double re, im;
    permittivity_eval(&m, 1.0, &re, &im); /* omega tau = 5e-11 */
    expect_rel(re, 70.0, 1e-12, "eps(0)");
    assert_true(im > 0.0 && im < 1e-8);
    permittivity_eval(&m, 1e20, &re, &im);
    expect_rel(re, 3.0, 1e-12, "eps(infinity)");
    assert_true(im > 0.0 && im < 1e-6);
    /* omega tau = 1: eps = eps_inf + (eps_s - eps_inf)(1 + i)/2 */
    permittivity_eval(&m, 1.0 / (2.0 * M_PI * 8e-12), &re, &im);
    expect_rel(re, 3.0 + 33.5, 1e-12, "eps' at omega tau = 1");
    expect_rel(im, 33.5, 1e-12, "eps'' at omega tau = 1");
    /* a double Debye with eps_2 = eps_inf is the single Debye of tau1 */
    permittivity_model d = {.kind = PERMITTIVITY_DOUBLE_DEBYE,
                            .eps_inf = 3.0,
                            .eps_2 = 3.0,
                            .eps_s = 70.0,
                            .tau1_s = 8e-12,
                            .tau2_s = 0.1e-12};
    for (double f = 1e10; f < 1e13; f *= 3.7) {
        double r1, i1, r2, i2;
        permittivity_eval(&m, f, &r1, &i1);
        permittivity_eval(&d, f, &r2, &i2);
        expect_rel(r2, r1, 1e-13, "double = single Debye (re)");
        expect_rel(i2, i1, 1e-13, "double = single Debye (im)");
    }
}

/* Liebe, Hufford & Manabe 1991 at 298.15 K (the library's "water") against Segelstein
 * 1981's measured index (refractiveindex.info, H2O/nk/Segelstein.yml): n and k at 1 THz
 * within 3 % and eps'' within 1 % (measured: n +2.4 %, k -2.3 %, eps'' +0.1 %; eps' is
 * +5.6 % off), n and k at 0.1-0.5 THz within 6 % (measured: n +5.5 % at 0.3 THz). */
static void test_water(void **state)
{
    (void)state;
    permittivity_model w = {.kind = PERMITTIVITY_DOUBLE_DEBYE,
                            .eps_inf = 3.4733,
                            .eps_2 = 5.2540,
                            .eps_s = 78.301,
                            .tau1_s = 8.2448e-12,
                            .tau2_s = 0.20715e-12};
    material_index *idx = material_index_model(&w);
    const double measured[][3] = {{0.0999357e12, 3.37461, 2.07917},
                                  {0.299792e12, 2.39911, 1.04181},
                                  {0.499828e12, 2.23669, 0.761711}};
    for (size_t i = 0; i < 3; i++) {
        double n, k;
        assert_true(material_index_at(idx, measured[i][0], &n, &k));
        expect_rel(n, measured[i][1], 0.06, "water n against Segelstein");
        expect_rel(k, measured[i][2], 0.06, "water k against Segelstein");
    }
    double n1 = 2.05977, k1 = 0.550542, n, k, re, im;
    assert_true(material_index_at(idx, 0.999587e12, &n, &k));
    expect_rel(n, n1, 0.03, "water n at 1 THz against Segelstein");
    expect_rel(k, k1, 0.03, "water k at 1 THz against Segelstein");
    assert_true(material_index_permittivity(idx, 0.999587e12, &re, &im));
    expect_rel(im, 2 * n1 * k1, 0.01, "water eps'' at 1 THz against Segelstein");
    material_index_destroy(idx);
}

static void test_drude(void **state)
{
    (void)state;
    const double cm = 29.9792458e9; /* Hz per cm^-1 */
    permittivity_model al = {
        .kind = PERMITTIVITY_DRUDE, .plasma_hz = 119000 * cm, .collision_hz = 660 * cm};
    material_index *idx = material_index_model(&al);
    double n, k;
    /* Ordal et al. 1988 (Appl. Opt. 27, 1203) measured Al at 1.49896 THz */
    material_index_at(idx, 1.49896e12, &n, &k);
    expect_rel(n, 436.989, 0.03, "Al n against Ordal 1988");
    expect_rel(k, 485.199, 0.03, "Al k against Ordal 1988");
    assert_true(k > n && n > 1.0);
    /* f << collision: eps'' -> sigma0 / (eps0 omega), sigma0 = eps0 (2 pi fp)^2 / (2 pi fc) */
    double f = al.collision_hz * 1e-3, re, im;
    permittivity_eval(&al, f, &re, &im);
    double sigma0 = EPS0 * 2.0 * M_PI * al.plasma_hz * al.plasma_hz / al.collision_hz;
    expect_rel(im, sigma0 / (EPS0 * 2.0 * M_PI * f), 1e-5, "Drude DC limit");
    assert_true(re < 0.0 && -re < 1e-2 * im);
    /* well above the collision frequency (below the plasma frequency): k >> n */
    material_index_at(idx, 30.0 * al.collision_hz, &n, &k);
    assert_true(k > 20.0 * n);
    material_index_destroy(idx);
}

static void test_lorentz(void **state)
{
    (void)state;
    permittivity_model m = {.kind = PERMITTIVITY_LORENTZ,
                            .eps_inf = 2.9,
                            .n_oscillators = 2,
                            .oscillators = {{0.82e12, 0.02, 0.06e12}, {1.96e12, 0.03, 0.15e12}}};
    double re, im;
    permittivity_eval(&m, 1.0, &re, &im);
    expect_rel(re, 2.9 + 0.05, 1e-12, "eps(0) = eps_inf + sum S");
    /* exactly at the first line: its term is i S f0 / g; the second adds its own value */
    permittivity_eval(&m, 0.82e12, &re, &im);
    double f = 0.82e12, f2 = 1.96e12, a = f2 * f2 - f * f, b = f * 0.15e12;
    double s2 = 0.03 * f2 * f2 / (a * a + b * b);
    expect_rel(im, 0.02 * 0.82 / 0.06 + s2 * b, 1e-12, "eps'' at resonance");
    expect_rel(re, 2.9 + s2 * a, 1e-12, "eps' at resonance");
    /* absorption everywhere; the peak of eps'' near the line; eps' falls across it */
    double lo_re, hi_re, peak = 0, peak_f = 0;
    permittivity_eval(&m, 0.6e12, &lo_re, &im);
    permittivity_eval(&m, 1.0e12, &hi_re, &im);
    assert_true(hi_re < lo_re);
    for (double g = 0.05e12; g < 1.5e12; g += 1e9) {
        permittivity_eval(&m, g, &re, &im);
        assert_true(im > 0.0);
        if (im > peak) {
            peak = im;
            peak_f = g;
        }
    }
    assert_true(fabs(peak_f - 0.82e12) < 0.01e12);
}

static void test_sqrt(void **state)
{
    (void)state;
    const double eps[][2] = {{2.25, 0.0},  {4.0, 1.0},   {-32000.0, 6.4e5},
                             {-5.0, 1e-3}, {1e-9, 1e-9}, {78.0, 2.0}};
    for (size_t i = 0; i < sizeof eps / sizeof eps[0]; i++) {
        double n, k;
        permittivity_to_index(eps[i][0], eps[i][1], &n, &k);
        assert_true(n >= 0.0 && k >= 0.0);
        double mod = hypot(eps[i][0], eps[i][1]);
        assert_true(fabs(n * n - k * k - eps[i][0]) <= 1e-12 * mod);
        assert_true(fabs(2 * n * k - eps[i][1]) <= 1e-12 * mod);
    }
    double n, k;
    permittivity_to_index(2.25, 0.0, &n, &k);
    assert_true(n == 1.5 && k == 0.0);
}

static void test_p2040(void **state)
{
    (void)state;
    /* P.2040 Table 3 concrete rows (1-100 GHz and 110-330 GHz) */
    permittivity_model m = {
        .kind = PERMITTIVITY_P2040,
        .n_rows = 2,
        .rows = {{1e9, 100e9, 5.24, 0, 0.0462, 0.7822}, {110e9, 330e9, 5.17, 0, 0.0145, 1.09}}};
    double re, im;
    permittivity_eval(&m, 50e9, &re, &im);
    expect_rel(re, 5.24, 1e-15, "eps' = a f^b");
    double sigma = 0.0462 * pow(50.0, 0.7822);
    expect_rel(im, sigma / (2 * M_PI * 50e9 * EPS0), 1e-12, "eps'' = sigma/(omega eps0)");
    expect_rel(im, 17.98 * sigma / 50.0, 1e-3, "the Recommendation's 17.98 sigma / f_GHz");
    permittivity_eval(&m, 200e9, &re, &im);
    expect_rel(re, 5.17, 1e-15, "second row");
    /* outside every row, the row with the nearest end (permittivity.h): a Gaussian
     * band's quadrature reaches 6 sigma, beyond the +-2 FWHM the scene's check covers */
    permittivity_eval(&m, 400e9, &re, &im);
    expect_rel(re, 5.17, 1e-15, "above the rows: the nearest, 110-330 GHz");
    permittivity_eval(&m, 0.5e9, &re, &im);
    expect_rel(re, 5.24, 1e-15, "below the rows: the nearest, 1-100 GHz");
    permittivity_eval(&m, 104e9, &re, &im);
    expect_rel(re, 5.24, 1e-15, "in the gap, nearer 100 GHz");
    permittivity_eval(&m, 107e9, &re, &im);
    expect_rel(re, 5.17, 1e-15, "in the gap, nearer 110 GHz");
    assert_true(permittivity_covers(&m, 2e9, 99e9));
    assert_true(permittivity_covers(&m, 120e9, 330e9));
    assert_false(permittivity_covers(&m, 95e9, 105e9)); /* the gap */
    assert_false(permittivity_covers(&m, 300e9, 340e9));
    assert_false(permittivity_covers(&m, 0.5e9, 2e9));
    /* overlapping rows chain into one range (wood: 0.001-100, 110-330, 100-400 GHz) */
    permittivity_model w = {.kind = PERMITTIVITY_P2040,
                            .n_rows = 3,
                            .rows = {{1e6, 100e9, 1.99, 0, 0.0047, 1.0718},
                                     {110e9, 330e9, 1.82, 0, 0.004, 1.0761},
                                     {100e9, 400e9, 2.1183, 0, 0.0055, 1.1113}}};
    assert_true(permittivity_covers(&w, 50e9, 390e9));
    assert_false(permittivity_covers(&w, 50e9, 410e9));
    double lo, hi;
    assert_true(permittivity_validity(&w, &lo, &hi));
    assert_true(lo == 1e6 && hi == 400e9);
    /* first row holding f wins where rows overlap: 105 GHz is the 100-400 row's */
    permittivity_eval(&w, 105e9, &re, &im);
    expect_rel(re, 2.1183, 1e-15, "overlap: first matching row");
    permittivity_eval(&w, 200e9, &re, &im);
    expect_rel(re, 1.82, 1e-15, "overlap: first matching row in file order");
    /* a row holds its ends (scene-format.md: the first row that holds the frequency):
     * 100 GHz is the 0.001-100 GHz row's, not the 100-400 GHz one's */
    permittivity_eval(&w, 100e9, &re, &im);
    expect_rel(re, 1.99, 1e-15, "a row's upper end is inside it");
}

static void test_table_and_copy(void **state)
{
    (void)state;
    const double f[] = {0.2e12, 1.0e12, 2.0e12}, n[] = {1.5, 1.6, 2.0}, k[] = {0.01, 0.03, 0.05};
    material_index *t = material_index_table(3, f, n, k);
    material_index *c = material_index_copy(t);
    material_index_destroy(t);
    double nn, kk;
    material_index_at(c, 0.1e12, &nn, &kk);
    assert_true(nn == 1.5 && kk == 0.01); /* end value held below */
    material_index_at(c, 3e12, &nn, &kk);
    assert_true(nn == 2.0 && kk == 0.05);
    material_index_at(c, 0.6e12, &nn, &kk);
    assert_true(fabs(nn - 1.55) < 1e-14 && fabs(kk - 0.02) < 1e-14);
    double re, im;
    material_index_permittivity(c, 1e12, &re, &im);
    assert_true(fabs(re - (1.6 * 1.6 - 0.03 * 0.03)) < 1e-14 && fabs(im - 2 * 1.6 * 0.03) < 1e-14);
    assert_string_equal(material_index_form(c), "table");
    double lo, hi;
    assert_true(material_index_range(c, &lo, &hi) && lo == 0.2e12 && hi == 2.0e12);
    material_index_destroy(c);
    assert_false(material_index_at(NULL, 1e12, &nn, &kk));
    material_index *k0 = material_index_constant(1.45, 0.0007);
    assert_string_equal(material_index_form(k0), "constant");
    assert_false(material_index_range(k0, &lo, &hi));
    material_index_destroy(k0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_debye),          cmocka_unit_test(test_water),
        cmocka_unit_test(test_drude),          cmocka_unit_test(test_lorentz),
        cmocka_unit_test(test_sqrt),           cmocka_unit_test(test_p2040),
        cmocka_unit_test(test_table_and_copy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
