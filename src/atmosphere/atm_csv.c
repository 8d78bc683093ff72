/* Reading the numeric CSV tables of data/atmosphere/ (line catalogues, partition
 * sums, continuum and ITU tables). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere/atm_internal.h"
#include "core/alloc.h"

/* Splits line in place at commas; returns the number of fields (at most max). */
static size_t split_fields(char *line, char **fields, size_t max)
{
    size_t n = 0;
    char *p = line;
    for (;;) {
        if (n < max)
            fields[n] = p;
        n++;
        char *comma = strchr(p, ',');
        if (!comma)
            break;
        *comma = '\0';
        p = comma + 1;
    }
    return n;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    return s;
}

thz_status atm_csv_read(atm_csv *csv, const char *path, thz_error *err)
{
    enum { MAX_FIELDS = 64 };
    memset(csv, 0, sizeof *csv);
    thz_status st = THZ_OK;
    char *line = NULL;
    size_t cap = 0, rows_cap = 0;
    size_t lineno = 0;
    char *fields[MAX_FIELDS];
    FILE *f = fopen(path, "r");
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", path, strerror(errno));
    csv->path = thz_strdup(path);
    if (!csv->path) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
        goto cleanup;
    }
    ssize_t len;
    while ((len = getline(&line, &cap, f)) != -1) {
        lineno++;
        char *text = trim(line);
        if (text[0] == '#' || text[0] == '\0')
            continue;
        size_t n = split_fields(text, fields, MAX_FIELDS);
        if (n > MAX_FIELDS) {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: more than %d columns", path, lineno,
                               MAX_FIELDS);
            goto cleanup;
        }
        if (!csv->names) {
            csv->n_cols = n;
            csv->names = thz_calloc(n, sizeof *csv->names);
            if (!csv->names) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
                goto cleanup;
            }
            for (size_t i = 0; i < n; i++) {
                csv->names[i] = thz_strdup(trim(fields[i]));
                if (!csv->names[i]) {
                    st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
                    goto cleanup;
                }
            }
            continue;
        }
        if (n != csv->n_cols) {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: %zu fields, the header has %zu", path,
                               lineno, n, csv->n_cols);
            goto cleanup;
        }
        if (csv->n_rows == rows_cap) {
            size_t new_cap = rows_cap ? 2 * rows_cap : 1024;
            double *v = thz_realloc_array(csv->values, new_cap * csv->n_cols, sizeof *v);
            if (!v) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
                goto cleanup;
            }
            csv->values = v;
            size_t *l = thz_realloc_array(csv->line_of, new_cap, sizeof *l);
            if (!l) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
                goto cleanup;
            }
            csv->line_of = l;
            rows_cap = new_cap;
        }
        double *row = csv->values + csv->n_rows * csv->n_cols;
        for (size_t i = 0; i < n; i++) {
            char *field = trim(fields[i]);
            if (field[0] == '\0') {
                row[i] = NAN;
                continue;
            }
            char *end = NULL;
            errno = 0;
            row[i] = strtod(field, &end);
            if (*end || errno == ERANGE || !isfinite(row[i])) {
                st = thz_error_set(err, THZ_ERR_INPUT,
                                   "%s:%zu: column %zu (%s): expected a number, got '%s'", path,
                                   lineno, i + 1, csv->names[i], field);
                goto cleanup;
            }
        }
        csv->line_of[csv->n_rows] = lineno;
        csv->n_rows++;
    }
    if (ferror(f)) {
        st = thz_error_set(err, THZ_ERR_IO, "%s: read error", path);
        goto cleanup;
    }
    if (!csv->names || csv->n_rows == 0)
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: no header line or no data rows", path);
cleanup:
    free(line);
    fclose(f);
    if (st != THZ_OK)
        atm_csv_fini(csv);
    return st;
}

thz_status atm_csv_column(const atm_csv *csv, const char *name, size_t *col, thz_error *err)
{
    for (size_t i = 0; i < csv->n_cols; i++) {
        if (strcmp(csv->names[i], name) == 0) {
            *col = i;
            return THZ_OK;
        }
    }
    return thz_error_set(err, THZ_ERR_INPUT, "%s: no column '%s' in the header", csv->path, name);
}

void atm_csv_fini(atm_csv *csv)
{
    if (csv->names)
        for (size_t i = 0; i < csv->n_cols; i++)
            free(csv->names[i]);
    free(csv->names);
    free(csv->values);
    free(csv->line_of);
    free(csv->path);
    memset(csv, 0, sizeof *csv);
}
