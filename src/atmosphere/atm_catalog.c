/* Line catalogues and partition sums for the `lines` model (atm_catalog.h): am 14.0's
 * CSV tables and HITRAN .par files, read into the HITRAN reference state in am's units
 * (GHz, hPa, K). */
#include "atmosphere/atm_catalog.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere/atm_internal.h"
#include "core/alloc.h"
#include "core/c_locale.h"

static thz_status catalog_push(raw_catalog *cat, const raw_line *line, thz_error *err)
{
    if (cat->n == cat->cap) {
        size_t cap = cat->cap ? 2 * cat->cap : 4096;
        raw_line *l = thz_realloc_array(cat->lines, cap, sizeof *l);
        if (!l)
            return thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading a line catalogue");
        cat->lines = l;
        cat->cap = cap;
    }
    cat->lines[cat->n++] = *line;
    return THZ_OK;
}

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    if (n < m)
        return false;
    for (size_t i = 0; i < m; i++)
        if (tolower((unsigned char)s[n - m + i]) != suffix[i])
            return false;
    return true;
}

static thz_status check_line(const raw_line *l, const char *path, size_t lineno, thz_error *err)
{
    /* the first rule the line breaks, by name (the fields' names differ between .par and
     * CSV files; these are the quantities) */
    const char *broken = !(l->nu0_ghz > 0.0)         ? "frequency must be > 0"
                         : !(l->s296_cm2_ghz >= 0.0) ? "intensity must be >= 0"
                         : !(l->gamma_air >= 0.0)    ? "air-broadened width must be >= 0"
                         : !(l->gamma_self >= 0.0)   ? "self-broadened width must be >= 0"
                         : !isfinite(l->n_air)       ? "n_air must be finite"
                         : !isfinite(l->delta_air)   ? "pressure shift must be finite"
                         : !isfinite(l->elower_k)    ? "lower-state energy must be finite"
                         : l->iso < 1                ? "isotopologue must be >= 1"
                                                     : NULL;
    if (broken)
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: the line's %s", path, lineno, broken);
    return THZ_OK;
}

thz_status atm_catalog_read_csv(const char *path, bool coupled, raw_catalog *cat, thz_error *err)
{
    static const char *const base[] = {"freq_GHz",
                                       "S296_cm2_GHz",
                                       "Elower_K",
                                       "gamma_air_GHz_per_mbar",
                                       "gamma_self_GHz_per_mbar",
                                       "n_air",
                                       "delta_air_GHz_per_mbar",
                                       "hitran_iso"};
    static const char *const mix[] = {"y0_per_mbar",  "y1_per_mbar", "yx",           "g0_per_mbar2",
                                      "g1_per_mbar2", "gx",          "d0_per_mbar2", "d1_per_mbar2",
                                      "dx",           "Tref_K"};
    enum { N_BASE = 8, N_MIX = 10 };
    size_t col[N_BASE + N_MIX];
    csv_table csv;
    thz_status st = csv_read(path, NULL, &csv, err);
    if (st != THZ_OK)
        return st;
    for (size_t i = 0; st == THZ_OK && i < N_BASE; i++)
        st = csv_column_index(&csv, base[i], &col[i], err);
    for (size_t i = 0; coupled && st == THZ_OK && i < N_MIX; i++)
        st = csv_column_index(&csv, mix[i], &col[N_BASE + i], err);
    for (size_t r = 0; st == THZ_OK && r < csv.n_rows; r++) {
        raw_line l;
        memset(&l, 0, sizeof l);
        l.nu0_ghz = csv_value(&csv, r, col[0]);
        l.s296_cm2_ghz = csv_value(&csv, r, col[1]);
        l.elower_k = csv_value(&csv, r, col[2]);
        l.gamma_air = csv_value(&csv, r, col[3]);
        l.gamma_self = csv_value(&csv, r, col[4]);
        l.n_air = csv_value(&csv, r, col[5]);
        l.delta_air = csv_value(&csv, r, col[6]);
        double iso = csv_value(&csv, r, col[7]);
        l.iso = iso >= 1.0 && iso <= 99.0 ? (int)iso : 0;
        if (coupled) {
            /* each field by its own address: indexing past &l.y0 into the next members is
             * undefined behaviour, whatever the struct's layout */
            double *const m[N_MIX] = {&l.y0, &l.y1, &l.yx, &l.g0, &l.g1,
                                      &l.gx, &l.d0, &l.d1, &l.dx, &l.tref_k};
            for (size_t i = 0; i < N_MIX; i++)
                *m[i] = csv_value(&csv, r, col[N_BASE + i]);
            if (!(l.tref_k > 0.0))
                st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: Tref_K must be > 0", path,
                                   csv.row_lines[r]);
        }
        if (st == THZ_OK)
            st = check_line(&l, path, csv.row_lines[r], err);
        if (st == THZ_OK)
            st = catalog_push(cat, &l, err);
    }
    csv_fini(&csv);
    return st;
}

/* Parses columns [start, start+len) (0-based) of a .par record as a number. */
static bool par_field(const char *rec, size_t start, size_t len, double *out)
{
    char buf[32];
    memcpy(buf, rec + start, len);
    buf[len] = '\0';
    char *p = buf;
    while (*p == ' ')
        p++;
    if (!*p)
        return false;
    char *end = NULL;
    errno = 0;
    *out = thz_strtod(p, &end);
    while (*end == ' ')
        end++;
    return !*end && errno != ERANGE && isfinite(*out);
}

/* HITRAN 2004+ 160-character records: molecule I2, isotopologue I1 (0 = 10, A = 11,
 * ...), nu F12.6 cm^-1, S E10.3 cm^-1/(molecule cm^-2), A E10.3, gamma_air F5.4 and
 * gamma_self F5.3 cm^-1/atm, E'' F10.4 cm^-1, n_air F4.2, delta_air F8.6 cm^-1/atm,
 * then quantum numbers, error and reference codes, flag, g' and g'' (unused). */
static thz_status read_par_catalog(const char *path, int molecule, raw_catalog *cat, thz_error *err)
{
    thz_status st = THZ_OK;
    char *line = NULL;
    size_t cap = 0, lineno = 0, n_found = 0;
    FILE *f = fopen(path, "r");
    if (!f && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while opening it", path);
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", path, strerror(errno));
    ssize_t len;
    while ((len = getline(&line, &cap, f)) != -1) {
        lineno++;
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
            line[--len] = '\0';
        if (len == 0)
            continue;
        if (len < 67) {
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s:%zu: a HITRAN .par record has 160 characters, this line has "
                               "%zd",
                               path, lineno, len);
            goto cleanup;
        }
        double mol;
        if (!par_field(line, 0, 2, &mol)) {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu:1: expected the molecule number", path,
                               lineno);
            goto cleanup;
        }
        if ((int)mol != molecule)
            continue; /* other molecules are skipped */
        int iso;
        char c = line[2];
        if (c >= '1' && c <= '9')
            iso = c - '0';
        else if (c == '0')
            iso = 10;
        else if (c >= 'A' && c <= 'Z')
            iso = 11 + (c - 'A');
        else {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu:3: bad isotopologue code '%c'", path,
                               lineno, c);
            goto cleanup;
        }
        static const struct {
            size_t start, len;
            const char *name;
        } fields[] = {{3, 12, "nu"},         {15, 10, "S"},   {35, 5, "gamma_air"},
                      {40, 5, "gamma_self"}, {45, 10, "E''"}, {55, 4, "n_air"},
                      {59, 8, "delta_air"}};
        double v[7];
        for (size_t i = 0; i < 7; i++) {
            if (!par_field(line, fields[i].start, fields[i].len, &v[i])) {
                st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu:%zu: expected a number for %s", path,
                                   lineno, fields[i].start + 1, fields[i].name);
                goto cleanup;
            }
        }
        raw_line l;
        memset(&l, 0, sizeof l);
        l.nu0_ghz = v[0] * ATM_GHZ_PER_CM1;
        l.s296_cm2_ghz = v[1] * ATM_GHZ_PER_CM1;
        l.gamma_air = v[2] * ATM_GHZ_PER_CM1 / ATM_HPA_PER_ATM;
        l.gamma_self = v[3] * ATM_GHZ_PER_CM1 / ATM_HPA_PER_ATM;
        l.elower_k = v[4] * ATM_HC_OVER_K_CM_K;
        l.n_air = v[5];
        l.delta_air = v[6] * ATM_GHZ_PER_CM1 / ATM_HPA_PER_ATM;
        l.iso = iso;
        st = check_line(&l, path, lineno, err);
        if (st == THZ_OK)
            st = catalog_push(cat, &l, err);
        if (st != THZ_OK)
            goto cleanup;
        n_found++;
    }
    if (ferror(f))
        st = thz_error_set(err, THZ_ERR_IO, "%s: read error", path);
    else if (n_found == 0)
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: no lines of molecule %d (%s) in this file",
                           path, molecule, molecule == 1 ? "H2O" : "O2");
cleanup:
    free(line);
    fclose(f);
    return st;
}

bool atm_catalog_is_par(const char *path)
{
    return has_suffix(path, ".par");
}

thz_status atm_catalog_read(const char *path, int molecule, raw_catalog *cat, thz_error *err)
{
    if (atm_catalog_is_par(path))
        return read_par_catalog(path, molecule, cat, err);
    return atm_catalog_read_csv(path, false, cat, err);
}

thz_status atm_partition_sums_read(const char *path, partition_sums *q, thz_error *err)
{
    csv_table csv;
    memset(q, 0, sizeof *q);
    thz_status st = csv_read(path, NULL, &csv, err);
    if (st != THZ_OK)
        return st;
    size_t col_t;
    st = csv_column_index(&csv, "T_K", &col_t, err);
    size_t cols[32];
    size_t n_iso = 0;
    while (st == THZ_OK && n_iso < 32) {
        char name[16];
        snprintf(name, sizeof name, "Q_iso%zu", n_iso + 1);
        if (csv_column_index(&csv, name, &cols[n_iso], NULL) != THZ_OK)
            break;
        n_iso++;
    }
    if (st == THZ_OK && (n_iso == 0 || csv.n_rows < 2))
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: needs columns T_K, Q_iso1, ... and >= 2 rows",
                           path);
    if (st != THZ_OK)
        goto cleanup;
    q->t0_k = csv_value(&csv, 0, col_t);
    q->dt_k = csv_value(&csv, 1, col_t) - q->t0_k;
    for (size_t r = 0; r < csv.n_rows; r++) {
        double t = csv_value(&csv, r, col_t);
        if (!(q->dt_k > 0.0) || fabs(t - (q->t0_k + (double)r * q->dt_k)) > 1e-6 * q->dt_k) {
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s:%zu: temperatures must be evenly spaced and increasing", path,
                               csv.row_lines[r]);
            goto cleanup;
        }
    }
    q->n_t = csv.n_rows;
    q->n_iso = n_iso;
    q->q = thz_malloc_array(q->n_t * n_iso, sizeof *q->q);
    if (!q->q) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
        goto cleanup;
    }
    for (size_t r = 0; r < csv.n_rows; r++) {
        for (size_t i = 0; i < n_iso; i++) {
            double v = csv_value(&csv, r, cols[i]);
            if (!(v > 0.0)) {
                st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: partition sums must be > 0", path,
                                   csv.row_lines[r]);
                goto cleanup;
            }
            q->q[r * n_iso + i] = v;
        }
    }
cleanup:
    if (st != THZ_OK) {
        free(q->q);
        q->q = NULL;
    }
    csv_fini(&csv);
    return st;
}

double atm_partition_sum(const partition_sums *q, int iso, double t_k)
{
    if (iso < 1 || (size_t)iso > q->n_iso)
        return NAN;
    double x = (t_k - q->t0_k) / q->dt_k;
    if (x < 0.0 || x > (double)(q->n_t - 1))
        return NAN;
    size_t i = (size_t)x;
    if (i >= q->n_t - 1)
        i = q->n_t - 2;
    double u = x - (double)i;
    const double *col = q->q + (size_t)(iso - 1);
    return (1.0 - u) * col[i * q->n_iso] + u * col[(i + 1) * q->n_iso];
}
