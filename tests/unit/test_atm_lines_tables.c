/* The `lines` model's per-band tables, which a run reads alpha from between their
 * points: tabulated against the direct line sum off the grid at 1 atm, 10 hPa and near
 * vacuum, and the band evaluator the tables are filled from (near lines summed, the
 * others as Chebyshev series) against the direct sum. (The model itself:
 * test_atm_lines.c.) */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "atm_lines_helpers.h"
#include "atmosphere/atm_internal.h"
#include "atmosphere/atmosphere.h"

/* Tabulated alpha over channel bands matches direct evaluation to < 1e-4 relative
 * at frequencies off the grid (deterministic quasi-random points). */
static void test_tabulation_error(void **state)
{
    (void)state;
    atm_air_state air = reference_air(7.5);
    thz_atmosphere lbl;
    init_lines(&lbl, &air, NULL);
    thz_channel ch[] = {{.name = "a", .center_hz = 0.35e12, .relative_width = 0.05},
                        {.name = "b", .center_hz = 0.557e12, .relative_width = 0.01},
                        {.name = "c", .center_hz = 0.66e12, .relative_width = 0.1},
                        {.name = "d", .center_hz = 1.5e12, .relative_width = 0.02}};
    thz_error err = {0};
    if (atmosphere_prepare(&lbl, ch, 4, &err) != THZ_OK)
        fail_msg("%s", err.message);
    assert_int_equal(lbl.n_tables, 4);
    double worst = 0;
    for (size_t c = 0; c < 4; c++) {
        double sigma = channel_sigma_hz(&ch[c]);
        for (int i = 0; i < 2000; i++) {
            double u = fmod(0.5 + i * 0.6180339887498949, 1.0);
            double f = ch[c].center_hz + (2 * u - 1) * 6 * sigma;
            double t = atmosphere_alpha_per_m(&lbl, f), d = atmosphere_alpha_direct_per_m(&lbl, f);
            worst = fmax(worst, fabs(t / d - 1));
        }
    }
    print_message("tabulation: worst relative error %.2e\n", worst);
    assert_true(worst < 1e-4);
    atmosphere_fini(&lbl);
}

/* At 10 hPa the lines are Doppler-and-pressure (Voigt) lines of a few MHz; the
 * tabulation must still reach < 1e-4 (it needs a smooth Voigt to do so). */
static void test_tabulation_low_pressure(void **state)
{
    (void)state;
    thz_error err = {0};
    atm_air_state air;
    assert_int_equal(atm_air_state_init(&air, 230.0, 10.0, ATM_HUMIDITY_VMR, 1e-4, &err), THZ_OK);
    thz_atmosphere lbl;
    init_lines(&lbl, &air, NULL);
    thz_channel ch = {.name = "557", .center_hz = 556.936e9, .relative_width = 0.002};
    if (atmosphere_prepare(&lbl, &ch, 1, &err) != THZ_OK)
        fail_msg("%s", err.message);
    double sigma = channel_sigma_hz(&ch), worst = 0;
    for (int i = 0; i < 4000; i++) {
        double u = fmod(0.5 + i * 0.6180339887498949, 1.0);
        double f = ch.center_hz + (2 * u - 1) * 6 * sigma;
        double t = atmosphere_alpha_per_m(&lbl, f), d = atmosphere_alpha_direct_per_m(&lbl, f);
        worst = fmax(worst, fabs(t / d - 1));
    }
    print_message("tabulation at 10 hPa: %zu points, worst relative error %.2e\n", lbl.tables[0].n,
                  worst);
    assert_true(worst < 1e-4);
    atmosphere_fini(&lbl);
}

/* Near vacuum (1e-10 hPa) the lines are Doppler's Gaussians, 1e-5 of their peak a few
 * MHz from the centre; far out their Voigt wings carry the series' rounding, 1e-12 of the
 * peak, which no step interpolates to 1e-5 relative: the band was refused after minutes
 * of halving (46 s for a 1 % band at 1 THz). Below 1e-9 of the band's peak the check asks
 * for 1e-5 of that floor instead: the band tabulates, to < 1e-4 relative where alpha is
 * above the floor and to 1e-4 of the floor below it. */
static void test_tabulation_near_vacuum(void **state)
{
    (void)state;
    thz_error err = {0};
    atm_air_state air;
    assert_int_equal(atm_air_state_init(&air, 230.0, 1e-10, ATM_HUMIDITY_VMR, 1e-4, &err), THZ_OK);
    thz_atmosphere lbl;
    init_lines(&lbl, &air, NULL);
    thz_channel ch = {.name = "557", .center_hz = 556.936e9, .relative_width = 2e-4};
    if (atmosphere_prepare(&lbl, &ch, 1, &err) != THZ_OK)
        fail_msg("%s", err.message);
    const atm_band_table *t = &lbl.tables[0];
    double peak = 0.0;
    for (size_t i = 0; i < t->n; i++)
        peak = fmax(peak, t->alpha_per_m[i]);
    double sigma = channel_sigma_hz(&ch), worst = 0;
    for (int i = 0; i < 4000; i++) {
        double u = fmod(0.5 + i * 0.6180339887498949, 1.0);
        double f = ch.center_hz + (2 * u - 1) * 6 * sigma;
        double a = atmosphere_alpha_per_m(&lbl, f), d = atmosphere_alpha_direct_per_m(&lbl, f);
        worst = fmax(worst, fabs(a - d) / fmax(d, 1e-9 * peak));
    }
    print_message("tabulation at 1e-10 hPa: %zu points, peak %.3g /m, worst error %.2e\n", t->n,
                  peak, worst);
    assert_true(peak > 0.0);
    assert_true(worst < 1e-4);
    atmosphere_fini(&lbl);
}

/* The band evaluator the tables are filled from (atm_lines_band.c: the lines near a piece
 * of the band summed, the others as Chebyshev series) against the direct sum over every
 * line, at 1 atm humid, 10 hPa, 1e-3 hPa and 1e-10 hPa, for bands of 0.02 % to 50 % from
 * 60 GHz to 3 THz, in one piece and in as many as 20,000 points give: within 1e-10
 * of alpha (or of 1e-9 of the band's peak where alpha is smaller), over the band and the
 * eighth of its width beyond each end that the tables reach; and in pieces, a band of 1 %
 * sums few lines at a frequency (else the split would gain nothing). */
static void test_band_split(void **state)
{
    (void)state;
    const struct {
        double p_hpa, vmr;
    } airs[] = {{1013.25, 1e-2}, {10.0, 1e-4}, {1e-3, 1e-4}, {1e-10, 1e-4}};
    const thz_channel chs[] = {{.name = "a", .center_hz = 0.2e12, .relative_width = 0.01},
                               {.name = "b", .center_hz = 0.556936e12, .relative_width = 2e-4},
                               {.name = "c", .center_hz = 1.0e12, .relative_width = 0.01},
                               {.name = "d", .center_hz = 1.2e12, .relative_width = 0.1},
                               {.name = "e", .center_hz = 3.0e12, .relative_width = 0.5},
                               {.name = "f", .center_hz = 0.06e12, .relative_width = 0.05}};
    const size_t points[] = {100, 20000};
    double worst = 0.0, most_near = 0.0;
    for (size_t a = 0; a < sizeof airs / sizeof airs[0]; a++) {
        thz_error err = {0};
        atm_air_state air;
        assert_int_equal(
            atm_air_state_init(&air, 260.0, airs[a].p_hpa, ATM_HUMIDITY_VMR, airs[a].vmr, &err),
            THZ_OK);
        thz_atmosphere lbl;
        init_lines(&lbl, &air, NULL);
        for (size_t c = 0; c < sizeof chs / sizeof chs[0]; c++) {
            double lo, hi;
            channel_support_hz(&chs[c], 6.0, &lo, &hi);
            enum { N = 500 };
            double f[N], direct[N], peak = 0.0;
            for (int i = 0; i < N; i++) {
                double u = fmod(0.5 + i * 0.6180339887498949, 1.0);
                f[i] = lo - (hi - lo) / 8.0 + u * (hi - lo) * 1.25;
                direct[i] = atmosphere_alpha_direct_per_m(&lbl, f[i]);
                peak = fmax(peak, fabs(direct[i]));
            }
            for (size_t p = 0; p < sizeof points / sizeof points[0]; p++) {
                atm_lines_band *band = NULL;
                if (atm_lines_band_create(lbl.lines, lo, hi, points[p], &band, &err) != THZ_OK)
                    fail_msg("%s", err.message);
                double band_worst = 0.0;
                for (int i = 0; i < N; i++) {
                    double b = atm_lines_band_alpha_per_m(band, f[i]);
                    band_worst =
                        fmax(band_worst, fabs(b - direct[i]) / fmax(fabs(direct[i]), 1e-9 * peak));
                }
                size_t pieces, near, all;
                atm_lines_band_counts(band, &pieces, &near, &all);
                if (p > 0 && chs[c].relative_width <= 0.01)
                    most_near = fmax(most_near, (double)near / (double)pieces);
                if (band_worst > 1e-10)
                    print_message("%g hPa, channel %s, %zu pieces: error %.2e (%zu of %zu lines "
                                  "near)\n",
                                  airs[a].p_hpa, chs[c].name, pieces, band_worst, near, all);
                worst = fmax(worst, band_worst);
                atm_lines_band_destroy(band);
            }
        }
        atmosphere_fini(&lbl);
    }
    print_message("band split: worst relative error %.2e; at most %.1f of ~15,000 lines summed "
                  "at a frequency of a band of <= 1 %%\n",
                  worst, most_near);
    assert_true(worst <= 1e-10);
    assert_true(most_near <= 50.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tabulation_error),
        cmocka_unit_test(test_tabulation_low_pressure),
        cmocka_unit_test(test_tabulation_near_vacuum),
        cmocka_unit_test(test_band_split),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
