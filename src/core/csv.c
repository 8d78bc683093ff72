/* The numeric CSV reader. */
#include "core/csv.h"
#include "core/file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/c_locale.h"

/* Files larger than this are not tables a scene needs; refusing them early keeps a
 * mistaken path (a binary, a device) from being read whole. */
#define CSV_MAX_BYTES ((size_t)256 << 20)

static char *csv_trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

/* A field trimmed, and without the double quotes around it that spreadsheets write
 * ("frequency_thz"; a quote inside a field is not supported: fields hold names and
 * numbers). */
static char *csv_field(char *s)
{
    s = csv_trim(s);
    size_t n = strlen(s);
    if (n >= 2 && s[0] == '"' && s[n - 1] == '"' && !memchr(s + 1, '"', n - 2)) {
        s[n - 1] = '\0';
        s = csv_trim(s + 1);
    }
    return s;
}

/* Number of comma-separated fields in line. */
static size_t csv_count_fields(const char *line)
{
    size_t n = 1;
    for (const char *p = line; *p; p++)
        n += *p == ',';
    return n;
}

void csv_fini(csv_table *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n_columns && t->names; i++)
        free(t->names[i]);
    free(t->names);
    free(t->values);
    free(t->row_lines);
    free(t->label);
    memset(t, 0, sizeof *t);
}

static thz_status csv_parse_header(csv_table *t, char *line, size_t line_no, thz_error *err)
{
    t->n_columns = csv_count_fields(line);
    t->names = thz_calloc(t->n_columns, sizeof *t->names);
    if (!t->names)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", t->label);
    char *field = line;
    for (size_t c = 0; c < t->n_columns; c++) {
        char *comma = strchr(field, ',');
        if (comma)
            *comma = '\0';
        char *name = csv_field(field);
        if (!name[0])
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "%s:%zu: header column %zu has no name (expected a header line "
                                 "of column names such as 'frequency_thz,reflectivity')",
                                 t->label, line_no, c + 1);
        for (size_t k = 0; k < c; k++)
            if (strcmp(t->names[k], name) == 0)
                return thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: header names column '%s' twice",
                                     t->label, line_no, name);
        char *end = NULL;
        thz_strtod(name, &end);
        if (*end == '\0')
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "%s:%zu: the first line that is not a comment must be a header "
                                 "of column names, got the number '%s'",
                                 t->label, line_no, name);
        t->names[c] = thz_strdup(name);
        if (!t->names[c])
            return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", t->label);
        field = comma ? comma + 1 : field + strlen(field);
    }
    return THZ_OK;
}

static thz_status csv_parse_row(csv_table *t, char *line, size_t line_no, double *row,
                                thz_error *err)
{
    size_t n = csv_count_fields(line);
    size_t row_no = t->n_rows + 1;
    if (n != t->n_columns)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s:%zu: row %zu has %zu fields, expected %zu (one per header column)",
                             t->label, line_no, row_no, n, t->n_columns);
    char *field = line;
    for (size_t c = 0; c < n; c++) {
        char *comma = strchr(field, ',');
        if (comma)
            *comma = '\0';
        char *text = csv_field(field);
        char *end = NULL;
        errno = 0;
        double v = thz_strtod(text, &end);
        if (!text[0] || *end || (errno == ERANGE && fabs(v) == HUGE_VAL) || !isfinite(v))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "%s:%zu: row %zu, column '%s': expected a finite number, got '%s'",
                                 t->label, line_no, row_no, t->names[c], text);
        row[c] = v;
        field = comma ? comma + 1 : field + strlen(field);
    }
    return THZ_OK;
}

thz_status csv_parse(const char *text, const char *label, csv_table *t, thz_error *err)
{
    thz_status st = THZ_OK;
    memset(t, 0, sizeof *t);
    char *copy = thz_strdup(text);
    double *row = NULL;
    size_t cap = 0;
    t->label = thz_strdup(label ? label : "<csv>");
    if (!copy || !t->label) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", label ? label : "CSV");
        goto cleanup;
    }
    size_t line_no = 0;
    char *line = copy;
    if (strncmp(line, "\xef\xbb\xbf", 3) == 0) /* UTF-8's byte-order mark (spreadsheets) */
        line += 3;
    while (line) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        line_no++;
        char *s = csv_trim(line);
        line = nl ? nl + 1 : NULL;
        if (!s[0] || s[0] == '#')
            continue;
        if (!t->names) {
            st = csv_parse_header(t, s, line_no, err);
            if (st != THZ_OK)
                goto cleanup;
            row = thz_malloc_array(t->n_columns, sizeof *row);
            if (!row) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", t->label);
                goto cleanup;
            }
            continue;
        }
        st = csv_parse_row(t, s, line_no, row, err);
        if (st != THZ_OK)
            goto cleanup;
        if (t->n_rows == cap) {
            size_t ncap = cap ? 2 * cap : 16;
            double *v = thz_realloc_array(t->values, ncap, t->n_columns * sizeof *v);
            if (!v) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", t->label);
                goto cleanup;
            }
            t->values = v;
            size_t *l = thz_realloc_array(t->row_lines, ncap, sizeof *l);
            if (!l) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", t->label);
                goto cleanup;
            }
            t->row_lines = l;
            cap = ncap;
        }
        memcpy(&t->values[t->n_rows * t->n_columns], row, t->n_columns * sizeof *row);
        t->row_lines[t->n_rows] = line_no;
        t->n_rows++;
    }
    if (!t->names)
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: no header line (the file is empty or all comments)", t->label);
    else if (t->n_rows == 0)
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: no data rows after the header", t->label);
cleanup:
    free(copy);
    free(row);
    if (st != THZ_OK)
        csv_fini(t);
    return st;
}

thz_status csv_read(const char *path, const char *label, csv_table *t, thz_error *err)
{
    memset(t, 0, sizeof *t);
    const char *name = label ? label : path;
    thz_status st = THZ_OK;
    char *text = NULL;
    /* A directory, FIFO or device is refused before it is opened (a FIFO would block). */
    st = file_check_regular(path, name, CSV_MAX_BYTES, NULL, err);
    if (st != THZ_OK)
        return st;
    FILE *f = fopen(path, "rb");
    if (!f && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while opening it", name);
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", name, strerror(errno));
    size_t cap = 4096, len = 0;
    text = malloc(cap);
    if (!text) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", name);
        goto cleanup;
    }
    for (;;) {
        if (len + 1 == cap) {
            if (cap >= CSV_MAX_BYTES) {
                st = thz_error_set(err, THZ_ERR_INPUT, "%s: larger than %zu MiB, not a table", name,
                                   CSV_MAX_BYTES >> 20);
                goto cleanup;
            }
            char *bigger = realloc(text, 2 * cap);
            if (!bigger) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", name);
                goto cleanup;
            }
            text = bigger;
            cap *= 2;
        }
        size_t got = fread(text + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: cannot read: %s", name, strerror(errno));
        goto cleanup;
    }
    text[len] = '\0';
    if (memchr(text, '\0', len)) {
        st = thz_error_set(err, THZ_ERR_INPUT, "%s: binary data, expected a CSV text table", name);
        goto cleanup;
    }
    st = csv_parse(text, name, t, err);
cleanup:
    free(text);
    fclose(f);
    return st;
}

long csv_column(const csv_table *t, const char *name)
{
    for (size_t c = 0; c < t->n_columns; c++)
        if (strcmp(t->names[c], name) == 0)
            return (long)c;
    return -1;
}

thz_status csv_column_index(const csv_table *t, const char *name, size_t *column, thz_error *err)
{
    long c = csv_column(t, name);
    if (c < 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: no column '%s' in the header", t->label,
                             name);
    *column = (size_t)c;
    return THZ_OK;
}

double csv_value(const csv_table *t, size_t row, size_t column)
{
    return t->values[row * t->n_columns + column];
}
