/* ITU-R P.676-13 Annex 1: specific attenuation of oxygen and water vapour by
 * summing the individual lines of its Tables 1 and 2 (eq. 1-9), 1-1000 GHz.
 *
 * gamma = 0.1820 f (N''_ox(f) + N''_wv(f))  dB/km, f in GHz
 * N''_ox = sum_i S_i F_i + N''_D,  N''_wv = sum_i S_i F_i
 * with p the dry-air pressure and e the water-vapour pressure in hPa, theta = 300/T.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "atmosphere/atm_internal.h"
#include "core/alloc.h"
#include "core/data_dir.h"
#include "core/path.h"

enum { ITU_COEFFS = 6 };

typedef struct itu_line {
    double f0_ghz;
    double c[ITU_COEFFS]; /* a1..a6 (O2) or b1..b6 (H2O) */
} itu_line;

struct atm_itu_data {
    size_t n_o2, n_h2o;
    itu_line *o2, *h2o;
};

static thz_status read_lines(const char *dir, const char *name, const char *prefix, itu_line **out,
                             size_t *n_out, thz_error *err)
{
    char path[4096];
    csv_table csv;
    itu_line *lines = NULL;
    thz_status st = thz_path_join(path, sizeof path, dir, name, err);
    if (st != THZ_OK)
        return st;
    st = csv_read(path, NULL, &csv, err);
    if (st != THZ_OK)
        return st;
    size_t cols[ITU_COEFFS + 1];
    st = csv_column_index(&csv, "f0_GHz", &cols[0], err);
    for (int i = 0; st == THZ_OK && i < ITU_COEFFS; i++) {
        char name_i[16];
        snprintf(name_i, sizeof name_i, "%s%d", prefix, i + 1);
        st = csv_column_index(&csv, name_i, &cols[i + 1], err);
    }
    if (st != THZ_OK)
        goto cleanup;
    lines = thz_calloc(csv.n_rows, sizeof *lines);
    if (!lines) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
        goto cleanup;
    }
    for (size_t r = 0; r < csv.n_rows; r++) {
        lines[r].f0_ghz = csv_value(&csv, r, cols[0]);
        for (int i = 0; i < ITU_COEFFS; i++)
            lines[r].c[i] = csv_value(&csv, r, cols[i + 1]);
        if (!(lines[r].f0_ghz > 0.0)) {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: line frequency must be > 0 GHz", path,
                               csv.row_lines[r]);
            goto cleanup;
        }
    }
    *out = lines;
    *n_out = csv.n_rows;
    lines = NULL;
cleanup:
    free(lines);
    csv_fini(&csv);
    return st;
}

/* The tables in the data directory. */
#define ITU_O2_FILE "atmosphere/itu_r_p676_13_oxygen_lines.csv"
#define ITU_H2O_FILE "atmosphere/itu_r_p676_13_water_vapour_lines.csv"

thz_status atm_itu_create(atm_itu_data **out, const char *data_dir, thz_error *err)
{
    char dir[THZ_PATH_MAX], path[THZ_PATH_MAX];
    thz_status st = thz_data_dir_find(data_dir, dir, sizeof dir, err);
    if (st == THZ_OK)
        st = thz_data_file(data_dir, ITU_O2_FILE, path, sizeof path, err);
    if (st == THZ_OK)
        st = thz_data_file(data_dir, ITU_H2O_FILE, path, sizeof path, err);
    if (st != THZ_OK)
        return st;
    atm_itu_data *itu = thz_calloc(1, sizeof *itu);
    if (!itu)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    st = read_lines(dir, ITU_O2_FILE, "a", &itu->o2, &itu->n_o2, err);
    if (st == THZ_OK)
        st = read_lines(dir, ITU_H2O_FILE, "b", &itu->h2o, &itu->n_h2o, err);
    if (st != THZ_OK) {
        atm_itu_destroy(itu);
        return st;
    }
    *out = itu;
    return THZ_OK;
}

void atm_itu_destroy(atm_itu_data *itu)
{
    if (!itu)
        return;
    free(itu->o2);
    free(itu->h2o);
    free(itu);
}

void atm_itu_table_key(const atm_itu_data *itu, atm_table_key *key)
{
    atm_table_key_add(key, &itu->n_o2, sizeof itu->n_o2);
    atm_table_key_add(key, &itu->n_h2o, sizeof itu->n_h2o);
    atm_table_key_add(key, itu->o2, itu->n_o2 * sizeof *itu->o2); /* doubles: no padding */
    atm_table_key_add(key, itu->h2o, itu->n_h2o * sizeof *itu->h2o);
}

/* Line shape factor F_i (eq. 5) with width df and interference correction delta. */
static double shape(double f, double fi, double df, double delta)
{
    double d1 = fi - f, d2 = fi + f;
    return f / fi *
           ((df - delta * d1) / (d1 * d1 + df * df) + (df - delta * d2) / (d2 * d2 + df * df));
}

void atm_itu_parts(const atm_itu_data *itu, const atm_air_state *air, double freq_hz,
                   atm_alpha_parts *parts)
{
    double f = freq_hz * 1e-9;
    double e = air->h2o_pressure_hpa;
    double p = air->pressure_hpa - e; /* P.676 takes the dry-air pressure */
    double theta = 300.0 / air->temperature_k;

    double n_ox = 0.0;
    for (size_t i = 0; i < itu->n_o2; i++) {
        const itu_line *l = &itu->o2[i];
        const double *a = l->c;
        double s = a[0] * 1e-7 * p * theta * theta * theta * exp(a[1] * (1.0 - theta));
        double df = a[2] * 1e-4 * (p * pow(theta, 0.8 - a[3]) + 1.1 * e * theta);
        df = sqrt(df * df + 2.25e-6); /* eq. 6b: Zeeman splitting */
        double delta = (a[4] + a[5] * theta) * 1e-4 * (p + e) * pow(theta, 0.8);
        n_ox += s * shape(f, l->f0_ghz, df, delta);
    }
    /* eq. 8: dry-air continuum, the Debye spectrum of O2 below 10 GHz plus the
     * pressure-induced N2 absorption above 100 GHz. */
    double d = 5.6e-4 * (p + e) * pow(theta, 0.8);
    double debye = f * p * theta * theta * 6.14e-5 / (d * (1.0 + (f / d) * (f / d)));
    double n2 =
        f * p * theta * theta * 1.4e-12 * p * pow(theta, 1.5) / (1.0 + 1.9e-5 * pow(f, 1.5));

    double n_wv = 0.0;
    for (size_t i = 0; i < itu->n_h2o; i++) {
        const itu_line *l = &itu->h2o[i];
        const double *b = l->c;
        double s = b[0] * 1e-1 * e * pow(theta, 3.5) * exp(b[1] * (1.0 - theta));
        double df = b[2] * 1e-4 * (p * pow(theta, b[3]) + b[4] * e * pow(theta, b[5]));
        /* eq. 6b: Doppler broadening of the water-vapour lines */
        df = 0.535 * df + sqrt(0.217 * df * df + 2.1316e-12 * l->f0_ghz * l->f0_ghz / theta);
        n_wv += s * shape(f, l->f0_ghz, df, 0.0);
    }
    /* gamma [dB/km] = 0.1820 f N''; alpha [1/m] = gamma / (10/ln 10) / 1000 */
    double to_per_m = 0.1820 * f / ATM_NEPER_TO_DB * 1e-3;
    parts->o2_per_m = (n_ox + debye) * to_per_m;
    parts->dry_continuum_per_m = n2 * to_per_m;
    parts->h2o_lines_per_m = n_wv * to_per_m;
    parts->h2o_continuum_per_m = 0.0;
    parts->other_per_m = 0.0;
}
