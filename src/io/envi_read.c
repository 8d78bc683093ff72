/* ENVI reader: the header's keys that locate and describe the values, then the raw
 * data (io/envi.h). Inputs are checked before they are opened (core/file.h) and the
 * data's size must match the header exactly, so a damaged or foreign file ends in an
 * error naming it instead of a wrong picture. A cube of the caller's values
 * (envi_cube_init) is made here too, so that one file fills an envi_cube.
 */
#include "io/envi.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/c_locale.h"
#include "core/file.h"
#include "core/path.h"

void envi_cube_fini(envi_cube *c)
{
    free(c->data);
    free(c->wavelength);
    free(c->wavelength_units);
    for (size_t i = 0; i < c->n_object_names; i++)
        free(c->object_names[i]);
    free(c->object_names);
    memset(c, 0, sizeof *c);
}

thz_status envi_cube_init(envi_cube *out, const char *name, uint32_t samples, uint32_t lines,
                          size_t bands, const float *data, thz_error *err)
{
    memset(out, 0, sizeof *out);
    if (!data)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: no values (data is NULL)", name);
    if (!samples || !lines || !bands)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: %u columns, %u rows, %zu bands: expected at least 1 of each",
                             name, samples, lines, bands);
    if (bands > ENVI_MAX_DIM)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: %zu bands: expected at most %u", name, bands,
                             ENVI_MAX_DIM);
    size_t pixels = (size_t)samples * lines; /* < 2^64: no overflow */
    if (pixels > SIZE_MAX / sizeof(float) / bands)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: %u x %u pixels of %zu bands: more values than memory holds", name,
                             samples, lines, bands);
    out->data = thz_malloc_array(pixels * bands, sizeof *out->data);
    if (!out->data)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    memcpy(out->data, data, pixels * bands * sizeof *out->data);
    out->samples = samples;
    out->lines = lines;
    out->bands = bands;
    return THZ_OK;
}

thz_status envi_cube_set_object_names(envi_cube *cube, const char *name, const char *const *names,
                                      size_t n, thz_error *err)
{
    if (n && !names)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: no object names (names is NULL)", name);
    for (size_t i = 0; i < n; i++)
        if (!names[i] || !names[i][0])
            return thz_error_set(err, THZ_ERR_INPUT, "%s: object name %zu is %s", name, i,
                                 names[i] ? "empty" : "NULL");
    char **copy = n ? thz_calloc(n, sizeof *copy) : NULL;
    if (n && !copy)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; i++)
        if (!(copy[i] = thz_strdup(names[i]))) {
            for (size_t j = 0; j < i; j++)
                free(copy[j]);
            free(copy);
            return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        }
    for (size_t i = 0; i < cube->n_object_names; i++)
        free(cube->object_names[i]);
    free(cube->object_names);
    cube->object_names = copy;
    cube->n_object_names = n;
    return THZ_OK;
}

/* The whole file into a NUL-terminated buffer (at most max bytes). */
static thz_status read_text(const char *path, uint64_t max, char **out, thz_error *err)
{
    uint64_t size = 0;
    thz_status st = file_check_regular(path, NULL, max, &size, err);
    if (st != THZ_OK)
        return st;
    FILE *f = fopen(path, "rb");
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", path, strerror(errno));
    char *buf = thz_malloc_array((size_t)size + 1, 1);
    if (!buf) {
        fclose(f);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    size_t n = fread(buf, 1, (size_t)size, f);
    fclose(f);
    buf[n] = '\0';
    if (strlen(buf) != n) {
        free(buf);
        return thz_error_set(err, THZ_ERR_INPUT, "%s: holds a NUL byte: not an ENVI header", path);
    }
    *out = buf;
    return THZ_OK;
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

/* A whole number value of key at line `line`. */
static thz_status parse_count(const char *path, size_t line, const char *key, const char *v,
                              uint64_t max, uint64_t *out, thz_error *err)
{
    char *end = NULL;
    errno = 0;
    unsigned long long x = strtoull(v, &end, 10);
    if (!v[0] || *end || errno || v[0] == '-' || x > max)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s:%zu: %s: expected a whole number up to %llu, got '%s'", path, line,
                             key, (unsigned long long)max, v);
    *out = x;
    return THZ_OK;
}

/* Splits the braced list v ("{a, b}") into its trimmed items (written into v). */
static thz_status split_list(const char *path, size_t line, const char *key, char *v, char ***items,
                             size_t *n, thz_error *err)
{
    size_t len = strlen(v);
    if (len < 2 || v[0] != '{' || v[len - 1] != '}')
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: %s: expected a list in braces", path,
                             line, key);
    v[len - 1] = '\0';
    v++;
    size_t count = 1;
    for (const char *p = v; *p; p++)
        count += *p == ',';
    char **list = thz_calloc(count, sizeof *list);
    if (!list)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    size_t i = 0;
    for (char *tok = v;; i++) {
        char *comma = strchr(tok, ',');
        if (comma)
            *comma = '\0';
        list[i] = trim(tok);
        if (!comma)
            break;
        tok = comma + 1;
    }
    *items = list;
    *n = i + 1;
    return THZ_OK;
}

typedef struct header {
    uint64_t samples, lines, bands, offset, data_type, byte_order;
    int have[4]; /* samples, lines, bands, data type */
    size_t n_wavelength, wavelength_line;
    char interleave[16];
} header;

/* One "key = value" entry (value with its braces joined over lines). */
static thz_status header_entry(const char *path, size_t line, char *key, char *value, header *h,
                               envi_cube *c, thz_error *err)
{
    key = trim(key);
    value = trim(value);
    for (char *p = key; *p; p++)
        *p = (char)tolower((unsigned char)*p);
    thz_status st = THZ_OK;
    const uint64_t max_dim = ENVI_MAX_DIM;
    if (strcmp(key, "samples") == 0) {
        st = parse_count(path, line, key, value, max_dim, &h->samples, err);
        h->have[0] = 1;
    } else if (strcmp(key, "lines") == 0) {
        st = parse_count(path, line, key, value, max_dim, &h->lines, err);
        h->have[1] = 1;
    } else if (strcmp(key, "bands") == 0) {
        st = parse_count(path, line, key, value, max_dim, &h->bands, err);
        h->have[2] = 1;
    } else if (strcmp(key, "header offset") == 0) {
        st = parse_count(path, line, key, value, ENVI_MAX_DATA_BYTES, &h->offset, err);
    } else if (strcmp(key, "data type") == 0) {
        st = parse_count(path, line, key, value, 100, &h->data_type, err);
        h->have[3] = 1;
    } else if (strcmp(key, "byte order") == 0) {
        st = parse_count(path, line, key, value, 1, &h->byte_order, err);
    } else if (strcmp(key, "interleave") == 0) {
        snprintf(h->interleave, sizeof h->interleave, "%s", value);
        for (char *p = h->interleave; *p; p++)
            *p = (char)tolower((unsigned char)*p);
    } else if (strcmp(key, "wavelength units") == 0) {
        free(c->wavelength_units);
        c->wavelength_units = thz_strdup(value);
        if (!c->wavelength_units)
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    } else if (strcmp(key, "wavelength") == 0 || strcmp(key, "object names") == 0) {
        char **items = NULL;
        size_t n = 0;
        st = split_list(path, line, key, value, &items, &n, err);
        if (st != THZ_OK)
            return st;
        if (key[0] == 'w') {
            free(c->wavelength);
            c->wavelength = thz_calloc(n, sizeof *c->wavelength);
            if (!c->wavelength)
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            for (size_t i = 0; i < n && st == THZ_OK; i++) {
                char *end = NULL;
                c->wavelength[i] = thz_strtod(items[i], &end);
                if (!items[i][0] || *end)
                    st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: wavelength %zu: not a number",
                                       path, line, i + 1);
            }
            h->n_wavelength = n;
            h->wavelength_line = line;
        } else { /* a second list replaces the first (it leaked) */
            for (size_t i = 0; i < c->n_object_names; i++)
                free(c->object_names[i]);
            free(c->object_names);
            c->n_object_names = 0;
            c->object_names = thz_calloc(n, sizeof *c->object_names);
            if (!c->object_names)
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            for (size_t i = 0; i < n && st == THZ_OK; i++) {
                c->object_names[i] = thz_strdup(items[i]);
                c->n_object_names = i + 1;
                if (!c->object_names[i])
                    st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            }
        }
        free(items);
    }
    return st;
}

static thz_status parse_header(const char *path, char *text, header *h, envi_cube *c,
                               thz_error *err)
{
    memset(h, 0, sizeof *h);
    snprintf(h->interleave, sizeof h->interleave, "bsq");
    if (strncmp(text, "ENVI", 4) != 0 || (text[4] != '\n' && text[4] != '\r'))
        return thz_error_set(err, THZ_ERR_INPUT, "%s:1: not an ENVI header (no 'ENVI' line)", path);
    size_t line = 1;
    char *p = strchr(text, '\n'); /* p: the start of the next line, or NULL at the end */
    if (p)
        p++;
    while (p && *p) {
        line++;
        char *eol = strchr(p, '\n');
        char *eq = strchr(p, '=');
        if (!eq || (eol && eq > eol)) { /* a line without '=': blank or a comment */
            p = eol ? eol + 1 : NULL;
            continue;
        }
        *eq = '\0';
        char *value = eq + 1;
        size_t start_line = line;
        char *end = eol;
        char *brace = strchr(value, '{');
        if (brace && (!eol || brace < eol)) { /* a list may span lines up to its '}' */
            char *close = strchr(brace, '}');
            if (!close)
                return thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: unclosed '{'", path, line);
            for (char *q = value; q < close; q++)
                if (*q == '\n') {
                    *q = ' ';
                    line++;
                }
            end = strchr(close, '\n');
        }
        if (end)
            *end = '\0';
        thz_status st = header_entry(path, start_line, p, value, h, c, err);
        if (st != THZ_OK)
            return st;
        p = end ? end + 1 : NULL;
    }
    static const char *const required[] = {"samples", "lines", "bands", "data type"};
    for (int i = 0; i < 4; i++)
        if (!h->have[i])
            return thz_error_set(err, THZ_ERR_INPUT, "%s: no '%s' key", path, required[i]);
    if (h->data_type != 4)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: data type %llu; only 4 (float32) is read",
                             path, (unsigned long long)h->data_type);
    if (strcmp(h->interleave, "bsq") != 0 && h->bands > 1)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: interleave %s; only bsq is read", path,
                             h->interleave);
    if (c->wavelength && h->n_wavelength != h->bands)
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: %zu wavelengths for %llu bands", path,
                             h->wavelength_line, h->n_wavelength, (unsigned long long)h->bands);
    if (!h->samples || !h->lines || !h->bands)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: an image of no pixels", path);
    return THZ_OK;
}

static thz_status read_data(const char *path, const header *h, envi_cube *c, thz_error *err)
{
    uint64_t n = h->samples * h->lines * h->bands; /* each <= 2^20: no overflow of 2^60 */
    if (n > ENVI_MAX_DATA_BYTES / 4)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: more than %llu values", path,
                             (unsigned long long)(ENVI_MAX_DATA_BYTES / 4));
    uint64_t size = 0;
    thz_status st = file_check_regular(path, NULL, ENVI_MAX_DATA_BYTES + h->offset, &size, err);
    if (st != THZ_OK)
        return st;
    if (size != h->offset + 4 * n)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: %llu bytes, but its header says %llu x %llu x %llu float32 "
                             "values after %llu bytes (%llu bytes)",
                             path, (unsigned long long)size, (unsigned long long)h->samples,
                             (unsigned long long)h->lines, (unsigned long long)h->bands,
                             (unsigned long long)h->offset,
                             (unsigned long long)(h->offset + 4 * n));
    c->data = thz_malloc_array((size_t)n, sizeof *c->data);
    if (!c->data)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    FILE *f = fopen(path, "rb");
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", path, strerror(errno));
    int failed = fseek(f, (long)h->offset, SEEK_SET) != 0;
    unsigned char *bytes = (unsigned char *)c->data;
    failed = failed || fread(bytes, 4, (size_t)n, f) != (size_t)n;
    fclose(f);
    if (failed)
        return thz_error_set(err, THZ_ERR_IO, "%s: read failed", path);
    for (size_t i = 0; i < (size_t)n; i++) { /* to host order */
        unsigned char *b = bytes + 4 * i;
        uint32_t w = h->byte_order == 0 ? (uint32_t)b[0] | (uint32_t)b[1] << 8 |
                                              (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
                                        : (uint32_t)b[3] | (uint32_t)b[2] << 8 |
                                              (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
        memcpy(b, &w, 4);
    }
    return THZ_OK;
}

thz_status envi_read_float32(const char *dir, const char *stem, envi_cube *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    char name[THZ_PATH_MAX], hdr_path[THZ_PATH_MAX], img_path[THZ_PATH_MAX];
    snprintf(name, sizeof name, "%s.hdr", stem);
    thz_status st = thz_path_join(hdr_path, sizeof hdr_path, dir, name, err);
    snprintf(name, sizeof name, "%s.img", stem);
    if (st == THZ_OK)
        st = thz_path_join(img_path, sizeof img_path, dir, name, err);
    if (st != THZ_OK)
        return st;
    char *text = NULL;
    st = read_text(hdr_path, ENVI_MAX_HEADER_BYTES, &text, err);
    header h;
    if (st == THZ_OK)
        st = parse_header(hdr_path, text, &h, out, err);
    free(text);
    if (st == THZ_OK)
        st = read_data(img_path, &h, out, err);
    if (st != THZ_OK) {
        envi_cube_fini(out);
        return st;
    }
    out->samples = (uint32_t)h.samples;
    out->lines = (uint32_t)h.lines;
    out->bands = (size_t)h.bands;
    return THZ_OK;
}
