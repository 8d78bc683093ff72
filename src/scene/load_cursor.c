/* The JSON cursor of the loader: typed access to members with the document path in
 * every message, the unknown-key check, and spectral properties from JSON or CSV. */
#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/c_locale.h"
#include "scene/load.h"

load_cursor load_root(json_t *value)
{
    load_cursor c = {.value = value};
    c.path[0] = '\0';
    return c;
}

/* Appends text to the path, cutting it at LOAD_PATH_MAX (paths only serve messages). */
static void load_path_append(char *path, const char *text)
{
    size_t used = strlen(path), n = strlen(text);
    if (n > LOAD_PATH_MAX - 1 - used)
        n = LOAD_PATH_MAX - 1 - used;
    memcpy(path + used, text, n);
    path[used + n] = '\0';
}

load_cursor load_key(const load_cursor *c, const char *key)
{
    load_cursor k = {.value = json_is_object(c->value) ? json_object_get(c->value, key) : NULL};
    memcpy(k.path, c->path, sizeof k.path);
    if (k.path[0])
        load_path_append(k.path, ".");
    load_path_append(k.path, key);
    return k;
}

load_cursor load_index(const load_cursor *c, size_t i)
{
    load_cursor k = {.value = json_is_array(c->value) ? json_array_get(c->value, i) : NULL};
    char index[32];
    snprintf(index, sizeof index, "[%zu]", i);
    memcpy(k.path, c->path, sizeof k.path);
    load_path_append(k.path, index);
    return k;
}

thz_status load_fail(load_ctx *ctx, const load_cursor *c, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (c && c->path[0])
        return thz_error_set(ctx->err, THZ_ERR_INPUT, "%s: %s: %s", ctx->label, c->path, msg);
    return thz_error_set(ctx->err, THZ_ERR_INPUT, "%s: %s", ctx->label, msg);
}

const char *load_type_name(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT:
        return "an object";
    case JSON_ARRAY:
        return "a list";
    case JSON_STRING:
        return "a string";
    case JSON_INTEGER:
    case JSON_REAL:
        return "a number";
    case JSON_TRUE:
    case JSON_FALSE:
        return "a boolean";
    case JSON_NULL:
        return "null";
    }
    return "an unknown value";
}

thz_status load_expect_object(load_ctx *ctx, const load_cursor *c, const char *const *allowed)
{
    if (!json_is_object(c->value))
        return load_fail(ctx, c, "expected an object {...}, got %s", load_type_name(c->value));
    const char *key;
    json_t *value;
    json_object_foreach(c->value, key, value)
    {
        bool known = false;
        for (const char *const *a = allowed; *a && !known; a++)
            known = strcmp(*a, key) == 0;
        if (known)
            continue;
        char list[512] = "";
        size_t used = 0;
        for (const char *const *a = allowed; *a; a++) {
            int n = snprintf(list + used, sizeof list - used, "%s%s", a == allowed ? "" : ", ", *a);
            if (n < 0 || (size_t)n >= sizeof list - used)
                break;
            used += (size_t)n;
        }
        load_cursor k = load_key(c, key);
        return load_fail(ctx, &k, "unknown key (expected one of: %s)", list);
    }
    return THZ_OK;
}

thz_status load_require(load_ctx *ctx, const load_cursor *c, const char *key, const char *what)
{
    if (json_object_get(c->value, key))
        return THZ_OK;
    load_cursor k = load_key(c, key);
    return load_fail(ctx, &k, "missing key (expected %s)", what);
}

const char *load_number_text(double v, char *out)
{
    for (int digits = 6; digits <= 17; digits++) {
        snprintf(out, LOAD_NUMBER_CHARS, "%.*g", digits, v);
        if (!isfinite(v) || thz_strtod(out, NULL) == v)
            break;
    }
    return out;
}

static void load_format_range(char *out, size_t n, load_range r)
{
    if (isinf(r.lo) && isinf(r.hi))
        snprintf(out, n, "a number");
    else if (isinf(r.hi))
        snprintf(out, n, "a number %s %g", r.lo_open ? ">" : ">=", r.lo);
    else if (isinf(r.lo))
        snprintf(out, n, "a number %s %g", r.hi_open ? "<" : "<=", r.hi);
    else
        snprintf(out, n, "a number in %s%g, %g%s", r.lo_open ? "(" : "[", r.lo, r.hi,
                 r.hi_open ? ")" : "]");
}

static bool load_in_range(double v, load_range r)
{
    if (!isfinite(v))
        return false;
    if (r.lo_open ? !(v > r.lo) : !(v >= r.lo))
        return false;
    if (r.hi_open ? !(v < r.hi) : !(v <= r.hi))
        return false;
    return true;
}

thz_status load_number_value(load_ctx *ctx, const load_cursor *c, load_range r, double *out)
{
    char expected[128];
    load_format_range(expected, sizeof expected, r);
    if (!json_is_number(c->value))
        return load_fail(ctx, c, "expected %s, got %s", expected, load_type_name(c->value));
    double v = json_number_value(c->value);
    if (!load_in_range(v, r))
        return load_fail(ctx, c, "expected %s, got %s", expected, LOAD_G(v));
    *out = v;
    return THZ_OK;
}

thz_status load_number(load_ctx *ctx, const load_cursor *c, const char *key, load_range r,
                       bool required, double dflt, double *out)
{
    load_cursor k = load_key(c, key);
    if (!k.value) {
        if (!required) {
            *out = dflt;
            return THZ_OK;
        }
        char expected[128];
        load_format_range(expected, sizeof expected, r);
        return load_fail(ctx, &k, "missing key (expected %s)", expected);
    }
    return load_number_value(ctx, &k, r, out);
}

thz_status load_integer(load_ctx *ctx, const load_cursor *c, const char *key, uint64_t min,
                        uint64_t max, bool required, uint64_t dflt, uint64_t *out)
{
    load_cursor k = load_key(c, key);
    if (!k.value && !required) {
        *out = dflt;
        return THZ_OK;
    }
    const char *what = k.value ? load_type_name(k.value) : NULL;
    if (!k.value)
        return load_fail(ctx, &k, "missing key (expected a whole number from %llu to %llu)",
                         (unsigned long long)min, (unsigned long long)max);
    if (json_is_integer(k.value)) {
        json_int_t v = json_integer_value(k.value);
        if (v >= 0 && (uint64_t)v >= min && (uint64_t)v <= max) {
            *out = (uint64_t)v;
            return THZ_OK;
        }
        return load_fail(ctx, &k, "expected a whole number from %llu to %llu, got %lld",
                         (unsigned long long)min, (unsigned long long)max, (long long)v);
    }
    if (json_is_real(k.value)) {
        double v = json_real_value(k.value);
        if (v == floor(v) && v >= (double)min && v <= (double)max && v < 18446744073709551616.0) {
            *out = (uint64_t)v;
            return THZ_OK;
        }
        return load_fail(ctx, &k, "expected a whole number from %llu to %llu, got %s",
                         (unsigned long long)min, (unsigned long long)max, LOAD_G(v));
    }
    return load_fail(ctx, &k, "expected a whole number from %llu to %llu, got %s",
                     (unsigned long long)min, (unsigned long long)max, what);
}

thz_status load_string(load_ctx *ctx, const load_cursor *c, const char *key, bool required,
                       const char *dflt, const char **out)
{
    load_cursor k = load_key(c, key);
    if (!k.value) {
        if (required)
            return load_fail(ctx, &k, "missing key (expected a string)");
        *out = dflt;
        return THZ_OK;
    }
    if (!json_is_string(k.value))
        return load_fail(ctx, &k, "expected a string, got %s", load_type_name(k.value));
    *out = json_string_value(k.value);
    return THZ_OK;
}

thz_status load_bool(load_ctx *ctx, const load_cursor *c, const char *key, bool dflt, bool *out)
{
    load_cursor k = load_key(c, key);
    if (!k.value) {
        *out = dflt;
        return THZ_OK;
    }
    if (!json_is_boolean(k.value))
        return load_fail(ctx, &k, "expected true or false, got %s", load_type_name(k.value));
    *out = json_is_true(k.value);
    return THZ_OK;
}

thz_status load_vector(load_ctx *ctx, const load_cursor *c, const char *key, size_t n, load_range r,
                       bool required, double *out)
{
    load_cursor k = load_key(c, key);
    if (!k.value) {
        if (required)
            return load_fail(ctx, &k, "missing key (expected a list of %zu numbers)", n);
        return THZ_OK;
    }
    if (!json_is_array(k.value) || json_array_size(k.value) != n)
        return load_fail(ctx, &k, "expected a list of %zu numbers, got %s%s", n,
                         load_type_name(k.value),
                         json_is_array(k.value) ? " of another length" : "");
    for (size_t i = 0; i < n; i++) {
        load_cursor e = load_index(&k, i);
        thz_status st = load_number_value(ctx, &e, r, &out[i]);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}

thz_status load_choice(load_ctx *ctx, const load_cursor *c, const char *key,
                       const char *const *choices, bool required, size_t dflt, size_t *out)
{
    const char *s = NULL;
    thz_status st = load_string(ctx, c, key, required, NULL, &s);
    if (st != THZ_OK)
        return st;
    if (!s) {
        *out = dflt;
        return THZ_OK;
    }
    char list[256] = "";
    size_t used = 0;
    for (size_t i = 0; choices[i]; i++) {
        if (strcmp(choices[i], s) == 0) {
            *out = i;
            return THZ_OK;
        }
        int n = snprintf(list + used, sizeof list - used, "%s\"%s\"", i ? ", " : "", choices[i]);
        if (n > 0 && (size_t)n < sizeof list - used)
            used += (size_t)n;
    }
    load_cursor k = load_key(c, key);
    return load_fail(ctx, &k, "expected one of %s, got \"%s\"", list, s);
}

thz_status load_csv(load_ctx *ctx, const load_cursor *c, const char *key, csv_table *table)
{
    const char *file = NULL;
    thz_status st = load_string(ctx, c, key, true, NULL, &file);
    if (st != THZ_OK)
        return st;
    load_cursor k = load_key(c, key);
    if (!file[0])
        return load_fail(ctx, &k, "expected a file name, got an empty string");
    char *path = NULL, *label = NULL;
    st = load_file_path(ctx, &k, file, &path, &label);
    if (st != THZ_OK)
        return st;
    thz_error inner = {0};
    st = csv_read(path, label, table, &inner);
    free(path);
    free(label);
    if (st == THZ_ERR_INPUT)
        return load_fail(ctx, &k, "%s", inner.message);
    if (st != THZ_OK)
        return thz_error_set(ctx->err, st, "%s", inner.message);
    return THZ_OK;
}

thz_status load_csv_columns(load_ctx *ctx, const load_cursor *c, const csv_table *t,
                            const char *const *known, const char *required)
{
    const char *needed[] = {"frequency_thz", required};
    for (size_t i = 0; i < 2; i++)
        if (needed[i] && csv_column(t, needed[i]) < 0)
            return load_fail(ctx, c, "%s: the header names no column '%s'", t->label, needed[i]);
    for (size_t i = 0; i < t->n_columns; i++) {
        bool ok = strcmp(t->names[i], "frequency_thz") == 0;
        for (size_t k = 0; known[k] && !ok; k++)
            ok = strcmp(t->names[i], known[k]) == 0;
        if (ok)
            continue;
        char list[256] = "";
        size_t used = 0;
        for (size_t k = 0; known[k]; k++) {
            int n = snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", known[k]);
            if (n > 0 && (size_t)n < sizeof list - used)
                used += (size_t)n;
        }
        return load_fail(ctx, c, "%s: unknown column '%s' (expected frequency_thz and %s%s)",
                         t->label, t->names[i], known[0] && known[1] ? "any of " : "", list);
    }
    return THZ_OK;
}

thz_status load_csv_spectrum(load_ctx *ctx, const load_cursor *c, const csv_table *t,
                             const char *column, load_range r, thz_spectrum *out)
{
    long fc = csv_column(t, "frequency_thz");
    long vc = csv_column(t, column);
    assert(fc >= 0 && vc >= 0); /* load_csv_columns has checked the header */
    char expected[128];
    load_format_range(expected, sizeof expected, r);
    double *f = thz_malloc_array(t->n_rows, sizeof *f);
    double *v = thz_malloc_array(t->n_rows, sizeof *v);
    thz_status st = THZ_OK;
    if (!f || !v) {
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t i = 0; i < t->n_rows; i++) {
        double thz = csv_value(t, i, (size_t)fc);
        if (!(thz > 0.0)) {
            st = load_fail(ctx, c,
                           "%s:%zu: row %zu, column 'frequency_thz': expected a number > 0, got %s",
                           t->label, t->row_lines[i], i + 1, LOAD_G(thz));
            goto cleanup;
        }
        if (i > 0 && !(thz * 1e12 > f[i - 1])) {
            st = load_fail(
                ctx, c,
                "%s:%zu: row %zu: frequencies must increase strictly, got %g THz after %g THz",
                t->label, t->row_lines[i], i + 1, thz, f[i - 1] * 1e-12);
            goto cleanup;
        }
        f[i] = thz * 1e12;
        v[i] = csv_value(t, i, (size_t)vc);
        if (!load_in_range(v[i], r)) {
            st = load_fail(ctx, c, "%s:%zu: row %zu, column '%s': expected %s, got %s", t->label,
                           t->row_lines[i], i + 1, column, expected, LOAD_G(v[i]));
            goto cleanup;
        }
    }
    if (!spectrum_set_table(out, t->n_rows, f, v))
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
cleanup:
    free(f);
    free(v);
    return st;
}

thz_status load_spectrum(load_ctx *ctx, const load_cursor *c, const char *key, load_range r,
                         thz_spectrum *out, bool *present)
{
    load_cursor k = load_key(c, key);
    *present = k.value != NULL;
    if (!k.value)
        return THZ_OK;
    char expected[128];
    load_format_range(expected, sizeof expected, r);
    if (json_is_number(k.value)) {
        double v;
        thz_status st = load_number_value(ctx, &k, r, &v);
        if (st != THZ_OK)
            return st;
        if (!spectrum_set_constant(out, v))
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        return THZ_OK;
    }
    size_t n = json_array_size(k.value);
    if (!json_is_array(k.value) || n == 0)
        return load_fail(
            ctx, &k, "expected %s or a non-empty table [[frequency_thz, value], ...], got %s",
            expected, json_is_array(k.value) ? "an empty list" : load_type_name(k.value));
    double *f = thz_malloc_array(n, sizeof *f);
    double *v = thz_malloc_array(n, sizeof *v);
    thz_status st = THZ_OK;
    if (!f || !v) {
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t i = 0; i < n; i++) {
        load_cursor row = load_index(&k, i);
        if (!json_is_array(row.value) || json_array_size(row.value) != 2) {
            st = load_fail(ctx, &row, "expected a pair [frequency_thz, value], got %s",
                           load_type_name(row.value));
            goto cleanup;
        }
        load_cursor fc = load_index(&row, 0), vc = load_index(&row, 1);
        double thz;
        st = load_number_value(ctx, &fc, LOAD_POSITIVE, &thz);
        if (st != THZ_OK)
            goto cleanup;
        if (i > 0 && !(thz * 1e12 > f[i - 1])) {
            st = load_fail(ctx, &fc, "frequencies must increase strictly, got %g THz after %g THz",
                           thz, f[i - 1] * 1e-12);
            goto cleanup;
        }
        f[i] = thz * 1e12;
        st = load_number_value(ctx, &vc, r, &v[i]);
        if (st != THZ_OK)
            goto cleanup;
    }
    if (!spectrum_set_table(out, n, f, v))
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
cleanup:
    free(f);
    free(v);
    return st;
}
