/* Atmospheric attenuation: the models' dispatch, their set-up, and the per-band
 * tabulation that makes line-by-line alpha cheap enough to evaluate per photon. */
#include "atmosphere/atmosphere.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere/atm_internal.h"
#include "core/alloc.h"

/* Tabulation: the grid step starts from the line widths in the band (see
 * model_first_step_hz) and is halved until the cubic interpolation agrees with
 * evaluation at the point (for `lines`, its band's: atm_lines_band.c) to TABLE_TOLERANCE
 * at every grid midpoint: relative to alpha there, or to TABLE_FLOOR times the band's
 * largest alpha where alpha is smaller. Below that floor the relative error is not worth chasing:
 * an error of 1e-5 x 1e-9 of the band's peak changes a transmittance exp(-alpha d) by 1e-14
 * alpha_peak d relative, and in near vacuum (1e-10 hPa) the Voigt wings far from a line, there
 * 1e-12 of its peak, carry the series' own rounding: a step ever smaller never met 1e-5 relative,
 * and the band was refused after minutes of halving. */
#define TABLE_TOLERANCE 1e-5
#define TABLE_FLOOR 1e-9
#define TABLE_MAX_POINTS ((size_t)4000000)
#define TABLE_MAX_REFINEMENTS 8
#define BAND_SIGMAS 6.0

void atmosphere_model_range_hz(atm_model model, double *lo_hz, double *hi_hz)
{
    switch (model) {
    case ATM_ITU_P676:
        *lo_hz = 1e9;
        *hi_hz = 1000e9;
        return;
    case ATM_LINES:
        *lo_hz = 1e9;
        *hi_hz = 15e12;
        return;
    case ATM_NONE:
    case ATM_CONSTANT:
    case ATM_TABLE:
        break;
    }
    *lo_hz = 0.0;
    *hi_hz = INFINITY;
}

thz_status atmosphere_init_itu_p676(thz_atmosphere *atm, const atm_air_state *air,
                                    const char *data_dir, thz_error *err)
{
    atm_itu_data *itu = NULL;
    thz_status st = atm_itu_create(&itu, data_dir, err);
    if (st != THZ_OK)
        return st;
    atm->model = ATM_ITU_P676;
    atm->itu = itu;
    atm->has_air = true;
    atm->air = *air;
    return THZ_OK;
}

void atmosphere_lines_options_default(atm_lines_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->continuum = true;
}

thz_status atmosphere_init_lines(thz_atmosphere *atm, const atm_air_state *air,
                                 const atm_lines_options *opt, thz_error *err)
{
    atm_lines_options defaults;
    if (!opt) {
        atmosphere_lines_options_default(&defaults);
        opt = &defaults;
    }
    atm_lines_data *lines = NULL;
    thz_status st = atm_lines_create(&lines, air, opt, err);
    if (st != THZ_OK)
        return st;
    atm->model = ATM_LINES;
    atm->lines = lines;
    atm->has_air = true;
    atm->air = *air;
    return THZ_OK;
}

thz_status atmosphere_check_range(const thz_atmosphere *atm, double lo_hz, double hi_hz,
                                  const char *what, thz_error *err)
{
    if (!isfinite(lo_hz) || !isfinite(hi_hz) || lo_hz > hi_hz)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: %.6g to %.6g THz: expected finite frequencies, the first not "
                             "above the second",
                             what, lo_hz * 1e-12, hi_hz * 1e-12);
    double lo, hi;
    atmosphere_model_range_hz(atm->model, &lo, &hi);
    if (lo_hz >= lo && hi_hz <= hi)
        return THZ_OK;
    /* itu-p676 ends at 1 THz, where a THz camera's channels go on: name the model that
     * covers them (a channel at 1.05 THz was refused with the range alone) */
    double lines_lo, lines_hi;
    atmosphere_model_range_hz(ATM_LINES, &lines_lo, &lines_hi);
    char other[96] = "";
    if (atm->model == ATM_ITU_P676 && lo_hz >= lines_lo && hi_hz <= lines_hi)
        snprintf(other, sizeof other, "; model 'lines' covers %.6g to %.6g THz", lines_lo * 1e-12,
                 lines_hi * 1e-12);
    if (lo_hz == hi_hz) /* one frequency: not "20 to 20 THz" */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: %.6g THz lies outside the range of atmosphere model '%s' "
                             "(%.6g to %.6g THz)%s",
                             what, lo_hz * 1e-12, atmosphere_model_name(atm->model), lo * 1e-12,
                             hi * 1e-12, other);
    return thz_error_set(err, THZ_ERR_INPUT,
                         "%s: %.6g to %.6g THz leaves the range of atmosphere model '%s' "
                         "(%.6g to %.6g THz)%s",
                         what, lo_hz * 1e-12, hi_hz * 1e-12, atmosphere_model_name(atm->model),
                         lo * 1e-12, hi * 1e-12, other);
}

void atmosphere_alpha_parts(const thz_atmosphere *atm, double freq_hz, atm_alpha_parts *parts)
{
    memset(parts, 0, sizeof *parts);
    switch (atm->model) {
    case ATM_NONE:
        return;
    case ATM_CONSTANT:
    case ATM_TABLE:
        parts->other_per_m = spectrum_eval(&atm->attenuation_per_m, freq_hz);
        return;
    case ATM_ITU_P676:
        atm_itu_parts(atm->itu, &atm->air, freq_hz, parts);
        return;
    case ATM_LINES:
        atm_lines_parts(atm->lines, freq_hz, parts);
        return;
    }
}

double atmosphere_alpha_parts_sum(const atm_alpha_parts *p)
{
    return p->h2o_lines_per_m + p->h2o_continuum_per_m + p->o2_per_m + p->dry_continuum_per_m +
           p->other_per_m;
}

double atmosphere_alpha_direct_per_m(const thz_atmosphere *atm, double freq_hz)
{
    atm_alpha_parts p;
    atmosphere_alpha_parts(atm, freq_hz, &p);
    return atmosphere_alpha_parts_sum(&p);
}

/* 4-point Lagrange interpolation on the uniform grid; valid for
 * lo + step <= freq <= lo + (n - 2) step. */
static double table_eval(const atm_band_table *t, double freq_hz)
{
    double x = (freq_hz - t->lo_hz) / t->step_hz;
    size_t i = (size_t)x;
    if (i < 1)
        i = 1;
    if (i > t->n - 3)
        i = t->n - 3;
    double u = x - (double)i;
    const double *a = t->alpha_per_m + i - 1;
    double wm = -u * (u - 1.0) * (u - 2.0) / 6.0;
    double w0 = (u + 1.0) * (u - 1.0) * (u - 2.0) / 2.0;
    double w1 = -(u + 1.0) * u * (u - 2.0) / 2.0;
    double w2 = (u + 1.0) * u * (u - 1.0) / 6.0;
    return wm * a[0] + w0 * a[1] + w1 * a[2] + w2 * a[3];
}

static bool table_covers(const atm_band_table *t, double freq_hz)
{
    return freq_hz >= t->lo_hz + t->step_hz &&
           freq_hz <= t->lo_hz + (double)(t->n - 2) * t->step_hz;
}

double atmosphere_alpha_per_m(const thz_atmosphere *atm, double freq_hz)
{
    switch (atm->model) {
    case ATM_NONE:
        return 0.0;
    case ATM_CONSTANT:
    case ATM_TABLE:
        return spectrum_eval(&atm->attenuation_per_m, freq_hz);
    case ATM_ITU_P676:
    case ATM_LINES:
        for (size_t i = 0; i < atm->n_tables; i++)
            if (table_covers(&atm->tables[i], freq_hz))
                return table_eval(&atm->tables[i], freq_hz);
        return atmosphere_alpha_direct_per_m(atm, freq_hz);
    }
    return 0.0;
}

double atmosphere_transmittance(const thz_atmosphere *atm, double freq_hz, double distance_m)
{
    if (atm->model == ATM_NONE)
        return 1.0;
    double alpha = atmosphere_alpha_per_m(atm, freq_hz);
    if (alpha == 0.0)
        return 1.0; /* also for an infinite distance, where alpha d would be 0 * inf = NaN */
    return exp(-alpha * distance_m);
}

/* First grid step (Hz) over [lo, hi]. lines: from the line widths and strengths.
 * itu-p676: a quarter of a lower bound on the line widths, 6.0e-4 GHz/hPa * P *
 * theta^0.8 (P the total pressure, theta = 300/T), floored at the O2 Zeeman width
 * 1.5 MHz (ITU-R P.676-13 Annex 1 eq. 6b). P.676-13 eq. 6a gives O2 widths
 * a3 * 1e-4 * (p theta^(0.8 - a4) + 1.1 e theta) GHz; the smallest a3 of Table 1 is
 * 6.69 (with a4 = 0), so 6.0 leaves about 10 % margin; the H2O widths of Table 2
 * (b3 >= 15.55) are wider. The midpoint check refines either. */
static double model_first_step_hz(const thz_atmosphere *atm, double lo_hz, double hi_hz)
{
    if (atm->model == ATM_LINES)
        return atm_lines_grid_step_hz(atm->lines, lo_hz, hi_hz);
    double w_ghz = 6.0e-4 * atm->air.pressure_hpa * pow(300.0 / atm->air.temperature_k, 0.8);
    return fmax(w_ghz, 1.5e-3) * 1e9 / 4.0;
}

/* Frequency at grid index x of t; x = i + 0.5 is the midpoint after point i. Every
 * grid and midpoint frequency comes from this one expression, so that a value is
 * reused (fill_table) only at a bit-identical frequency. */
static double table_freq_hz(const atm_band_table *t, double x)
{
    return t->lo_hz + x * t->step_hz;
}

/* alpha at freq_hz for a band's table: through the lines model's band (near lines summed,
 * far ones fitted) where there is one, else directly. */
static double band_alpha_per_m(const thz_atmosphere *atm, const atm_lines_band *band,
                               double freq_hz)
{
    return band ? atm_lines_band_alpha_per_m(band, freq_hz)
                : atmosphere_alpha_direct_per_m(atm, freq_hz);
}

/* Fills t->alpha_per_m. After a halving (prev: the previous table, prev_mid: the
 * evaluated alpha at its midpoints, or NULL on the first pass) the grid starts half a step
 * lower, lo - h/2 = (lo - h) + h/2, so the previous grid point i is the new point
 * 2i - 1 (odd) and the previous midpoint i + 1/2 the new point 2i (even): those are
 * copied where the frequency is the same to the bit, the rest (the ends, and any
 * point where rounding moved the frequency) evaluated (band_alpha_per_m). */
static void fill_table(const thz_atmosphere *atm, const atm_lines_band *band, atm_band_table *t,
                       const atm_band_table *prev, const double *prev_mid)
{
    long n = (long)t->n;
#pragma omp parallel for schedule(dynamic, 64) num_threads(atm_table_threads(t->n))
    for (long j = 0; j < n; j++) {
        double f = table_freq_hz(t, (double)j);
        size_t i = (size_t)(j + 1) / 2;
        if (prev_mid && j % 2 == 1 && i < prev->n && table_freq_hz(prev, (double)i) == f)
            t->alpha_per_m[j] = prev->alpha_per_m[i];
        else if (prev_mid && j % 2 == 0 && i >= 1 && i + 2 < prev->n &&
                 table_freq_hz(prev, (double)i + 0.5) == f)
            t->alpha_per_m[j] = prev_mid[i];
        else
            t->alpha_per_m[j] = band_alpha_per_m(atm, band, f);
    }
}

/* Largest difference between interpolation and evaluation at the midpoints
 * i + 1/2, 1 <= i < n - 2, of the grid, relative to the larger of alpha there and
 * TABLE_FLOOR times the grid's largest |alpha|; the evaluated values go to mid[i]. */
static double table_midpoint_error(const thz_atmosphere *atm, const atm_lines_band *band,
                                   const atm_band_table *t, double *mid)
{
    long n = (long)t->n;
    double peak = 0.0;
    for (long i = 0; i < n; i++)
        peak = fmax(peak, fabs(t->alpha_per_m[i]));
    const double floor_per_m = fmax(TABLE_FLOOR * peak, 1e-300);
    double worst = 0.0;
    int threads = atm_table_threads(t->n);
#pragma omp parallel for schedule(dynamic, 64) reduction(max : worst) num_threads(threads)
    for (long i = 1; i < n - 2; i++) {
        double f = table_freq_hz(t, (double)i + 0.5);
        double direct = band_alpha_per_m(atm, band, f);
        mid[i] = direct;
        double rel = fabs(table_eval(t, f) - direct) / fmax(fabs(direct), floor_per_m);
        if (rel > worst)
            worst = rel;
    }
    return worst;
}

/* The first table point whose attenuation is not finite, or t->n. */
static size_t table_first_nonfinite(const atm_band_table *t)
{
    for (size_t i = 0; i < t->n; i++)
        if (!isfinite(t->alpha_per_m[i]))
            return i;
    return t->n;
}

/* On failure t may hold the last grid tried; the caller frees t->alpha_per_m. */

static thz_status build_table(const thz_atmosphere *atm, const thz_channel *ch, double lo_hz,
                              double hi_hz, atm_band_table *t, thz_error *err)
{
    double step = fmin(model_first_step_hz(atm, lo_hz, hi_hz), (hi_hz - lo_hz) / 32.0);
    atm_band_table prev = {0};
    double *prev_mid = NULL, *mid = NULL;
    memset(t, 0, sizeof *t);
    /* the lines' band, its pieces set by the first grid's points (model_first_step_hz
     * is INFINITY where no line shapes the band; the step above is finite) */
    atm_lines_band *band = NULL;
    size_t points = (size_t)fmin(ceil((hi_hz - lo_hz) / step) + 3.0, (double)TABLE_MAX_POINTS);
    thz_status st = atm->model == ATM_LINES
                        ? atm_lines_band_create(atm->lines, lo_hz, hi_hz, points, &band, err)
                        : THZ_OK;
    if (st != THZ_OK)
        return st;
    for (int refine = 0;; refine++) {
        double n_real = ceil((hi_hz - lo_hz) / step) + 3.0;
        if (n_real > (double)TABLE_MAX_POINTS) {
            st = thz_error_set(err, THZ_ERR_LIMIT,
                               "channel '%s': tabulating the atmosphere over its band needs "
                               "more than %zu points (step %.3g MHz); narrow the channel's "
                               "band or raise the pressure",
                               ch->name, TABLE_MAX_POINTS, step * 1e-6);
            break;
        }
        t->n = (size_t)n_real;
        t->step_hz = step;
        t->lo_hz = lo_hz - step;
        t->alpha_per_m = thz_malloc_array(t->n, sizeof *t->alpha_per_m);
        mid = thz_malloc_array(t->n, sizeof *mid);
        if (!t->alpha_per_m || !mid) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
            break;
        }
        fill_table(atm, band, t, &prev, prev_mid);
        size_t bad = table_first_nonfinite(t);
        if (bad < t->n) {
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "channel '%s': the atmosphere's attenuation at %.6g THz is not a "
                               "finite number (%g /m); a line catalogue or table with values "
                               "beyond the physical range?",
                               ch->name, (t->lo_hz + (double)bad * t->step_hz) * 1e-12,
                               t->alpha_per_m[bad]);
            break;
        }
        free(prev.alpha_per_m);
        free(prev_mid);
        prev.alpha_per_m = NULL;
        prev_mid = NULL;
        double e = table_midpoint_error(atm, band, t, mid);
        if (e <= TABLE_TOLERANCE)
            break;
        if (refine == TABLE_MAX_REFINEMENTS) {
            st = thz_error_set(err, THZ_ERR_INTERNAL,
                               "channel '%s': atmosphere tabulation did not reach %g relative "
                               "error (%.3g at step %.3g MHz)",
                               ch->name, TABLE_TOLERANCE, e, step * 1e-6);
            break;
        }
        prev = *t;
        prev_mid = mid;
        mid = NULL;
        t->alpha_per_m = NULL;
        step *= 0.5;
    }
    free(mid);
    free(prev_mid);
    free(prev.alpha_per_m);
    atm_lines_band_destroy(band);
    return st;
}

/* Appends to key what every table of atm is computed from but the band: the model, its data
 * and its air (build_table's constants are the same in the whole process). */
static void table_key_model(const thz_atmosphere *atm, atm_table_key *key)
{
    int model = (int)atm->model;
    atm_table_key_add(key, &model, sizeof model);
    atm_table_key_add(key, &atm->air.temperature_k, sizeof(double));
    atm_table_key_add(key, &atm->air.pressure_hpa, sizeof(double));
    atm_table_key_add(key, &atm->air.h2o_pressure_hpa, sizeof(double));
    if (atm->model == ATM_LINES)
        atm_lines_table_key(atm->lines, key);
    else
        atm_itu_table_key(atm->itu, key);
}

/* The table over [lo_hz, hi_hz]: a copy of the one an atmosphere with the same key had
 * (key: table_key_model's, to which the band is appended), else tabulated and kept. */
static thz_status band_table(const thz_atmosphere *atm, const thz_channel *ch, double lo_hz,
                             double hi_hz, atm_table_key *key, atm_band_table *t, thz_error *err)
{
    atm_table_key_add(key, &lo_hz, sizeof lo_hz);
    atm_table_key_add(key, &hi_hz, sizeof hi_hz);
    if (atm_table_cache_get(key, t))
        return THZ_OK;
    thz_status st = build_table(atm, ch, lo_hz, hi_hz, t, err);
    if (st == THZ_OK)
        atm_table_cache_put(key, t);
    return st;
}

static void free_tables(thz_atmosphere *atm)
{
    for (size_t i = 0; i < atm->n_tables; i++)
        free(atm->tables[i].alpha_per_m);
    free(atm->tables);
    atm->tables = NULL;
    atm->n_tables = 0;
}

thz_status atmosphere_prepare(thz_atmosphere *atm, const thz_channel *channels, size_t n_channels,
                              thz_error *err)
{
    if (atm->model != ATM_ITU_P676 && atm->model != ATM_LINES)
        return THZ_OK;
    free_tables(atm);
    thz_status st = THZ_OK;
    atm_band_table *tables = thz_calloc(n_channels, sizeof *tables);
    if (!tables)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
    size_t done = 0;
    atm_table_key key = {0};
    table_key_model(atm, &key);
    const size_t model_key_n = key.n;
    for (size_t c = 0; c < n_channels; c++) {
        const thz_channel *ch = &channels[c];
        double lo, hi;
        channel_support_hz(ch, BAND_SIGMAS, &lo, &hi);
        /* A wide band's low tail may reach below the model's range (even below 0):
         * it is tabulated from the range's start and evaluated directly below it
         * (alpha -> 0 there); the centre and the upper edge must be in range. */
        double model_lo, model_hi;
        atmosphere_model_range_hz(atm->model, &model_lo, &model_hi);
        if (lo < model_lo && ch->center_hz >= model_lo)
            lo = model_lo;
        char what[128];
        snprintf(what, sizeof what, "channel '%s' band (%s)", ch->name,
                 channel_has_response(ch) ? "where its response is > 0" : "centre +- 6 sigma");
        st = atmosphere_check_range(atm, lo, hi, what, err);
        if (st != THZ_OK)
            goto cleanup;
        key.n = model_key_n;
        st = band_table(atm, ch, lo, hi, &key, &tables[c], err);
        done = c + 1;
        if (st != THZ_OK)
            goto cleanup;
    }
    atm_table_key_fini(&key);
    atm->tables = tables;
    atm->n_tables = n_channels;
    return THZ_OK;
cleanup:
    atm_table_key_fini(&key);
    for (size_t i = 0; i < done; i++)
        free(tables[i].alpha_per_m);
    free(tables);
    return st;
}

const char *atmosphere_model_name(atm_model model)
{
    switch (model) {
    case ATM_NONE:
        return "none";
    case ATM_CONSTANT:
        return "constant";
    case ATM_TABLE:
        return "table";
    case ATM_ITU_P676:
        return "itu-p676";
    case ATM_LINES:
        return "lines";
    }
    return "unknown";
}

bool atmosphere_model_from_name(const char *name, atm_model *model)
{
    static const atm_model all[] = {ATM_NONE, ATM_CONSTANT, ATM_TABLE, ATM_ITU_P676, ATM_LINES};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        if (strcmp(name, atmosphere_model_name(all[i])) == 0) {
            *model = all[i];
            return true;
        }
    }
    return false;
}

void atmosphere_fini(thz_atmosphere *atm)
{
    spectrum_fini(&atm->attenuation_per_m);
    atm_itu_destroy(atm->itu);
    atm_lines_destroy(atm->lines);
    free_tables(atm);
    memset(atm, 0, sizeof *atm);
    atm->model = ATM_NONE;
}
