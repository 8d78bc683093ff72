/* Mesh file checks: the shared helpers, the format dispatch, OBJ and STL (PLY is in
 * mesh_check_ply.c). See mesh_check.h for what is checked and why. */
#include "scene/mesh_check.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "scene/mesh_check_internal.h"
#include "core/c_locale.h"

const char *const mesh_supported_formats = "Wavefront OBJ (.obj), PLY (.ply) or STL (.stl)";

/* ---- shared helpers ---------------------------------------------------------- */

thz_status mc_fail(mc_ctx *c, mc_where w, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (w.binary)
        return thz_error_set(c->err, THZ_ERR_INPUT, "%s: byte %llu: %s", c->label,
                             (unsigned long long)w.at, what);
    return thz_error_set(c->err, THZ_ERR_INPUT, "%s:%llu: %s", c->label, (unsigned long long)w.at,
                         what);
}

thz_status mc_polygon(mc_ctx *c, uint64_t n, mc_where w)
{
    if (n > MESH_MAX_POLYGON_VERTICES)
        return mc_fail(c, w,
                       "a polygon of %llu vertices, more than the limit of %u (triangulation "
                       "time grows with the square of the count); split it into smaller ones",
                       (unsigned long long)n, MESH_MAX_POLYGON_VERTICES);
    c->triangles += n - 2;
    c->work += n * n;
    if (c->triangles > MESH_MAX_TRIANGLES)
        return mc_fail(c, w, "more than the limit of %u triangles (after triangulation)",
                       MESH_MAX_TRIANGLES);
    if (c->work > MESH_MAX_POLYGON_WORK)
        return mc_fail(c, w,
                       "the polygons up to here have %llu vertex pairs (the sum of their vertex "
                       "counts squared), more than the limit of %llu that bounds the "
                       "triangulation time; split the large polygons",
                       (unsigned long long)c->work, (unsigned long long)MESH_MAX_POLYGON_WORK);
    return THZ_OK;
}

bool mc_line(const char **pos, const char *end, mc_span *line)
{
    if (*pos >= end)
        return false;
    const char *nl = memchr(*pos, '\n', (size_t)(end - *pos));
    line->p = *pos;
    line->end = nl ? nl : end;
    *pos = nl ? nl + 1 : end;
    return true;
}

static bool mc_space(char ch, char extra)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\v' || ch == '\f' ||
           (extra && ch == extra);
}

bool mc_token(mc_span *s, mc_span *tok, char extra_space)
{
    const char *p = s->p;
    while (p < s->end && mc_space(*p, extra_space))
        p++;
    if (p == s->end) {
        s->p = p;
        return false;
    }
    tok->p = p;
    while (p < s->end && !mc_space(*p, extra_space))
        p++;
    tok->end = p;
    s->p = p;
    return true;
}

bool mc_is(mc_span tok, const char *word)
{
    size_t n = strlen(word);
    return (size_t)(tok.end - tok.p) == n && memcmp(tok.p, word, n) == 0;
}

bool mc_is_ci(mc_span tok, const char *word)
{
    size_t n = strlen(word);
    return (size_t)(tok.end - tok.p) == n && strncasecmp(tok.p, word, n) == 0;
}

/* tok as a NUL-terminated string in buf (64 bytes); false when it is longer. */
static bool mc_copy(mc_span tok, char *buf)
{
    size_t n = (size_t)(tok.end - tok.p);
    if (n == 0 || n > 63)
        return false;
    memcpy(buf, tok.p, n);
    buf[n] = '\0';
    return true;
}

bool mc_number(mc_span tok, double *value)
{
    char buf[64], *end;
    if (!mc_copy(tok, buf))
        return false;
    errno = 0;
    *value = thz_strtod(buf, &end);
    return *end == '\0' && isfinite(*value);
}

bool mc_integer(mc_span tok, long long *value)
{
    char buf[64], *end;
    if (!mc_copy(tok, buf))
        return false;
    errno = 0;
    *value = strtoll(buf, &end, 10);
    return *end == '\0' && errno == 0;
}

thz_status mc_check_text(mc_ctx *c, const char *data, size_t size, const char *what)
{
    const char *nul = memchr(data, '\0', size);
    if (!nul)
        return THZ_OK;
    return mc_fail(c, (mc_where){true, (uint64_t)(nul - data)},
                   "a NUL byte: binary data where %s is text", what);
}

/* ---- Wavefront OBJ ------------------------------------------------------------- */

/* v, vt, vn: counts so far, and the largest positive index used (checked at the end,
 * since a positive index may name an element defined later). */
typedef struct obj_counts {
    uint64_t defined[3];
    uint64_t max_used[3];
    uint64_t max_line[3];
} obj_counts;

static const char *const obj_kind[3] = {"v", "vt", "vn"};

/* One vertex reference "v", "v/vt", "v//vn" or "v/vt/vn". */
static thz_status obj_reference(mc_ctx *c, obj_counts *k, mc_span tok, uint64_t line)
{
    mc_where w = {false, line};
    const char *p = tok.p;
    bool more = true;
    for (int kind = 0; kind < 3 && more; kind++) {
        const char *slash = memchr(p, '/', (size_t)(tok.end - p));
        mc_span part = {p, slash ? slash : tok.end};
        more = slash != NULL;
        p = slash ? slash + 1 : tok.end;
        if (part.p == part.end && kind > 0)
            continue; /* "v//vn" */
        long long i;
        if (!mc_integer(part, &i) || i == 0)
            return mc_fail(c, w,
                           "expected a vertex reference (v, v/vt, v//vn or v/vt/vn with non-zero "
                           "integer indices), found '%.*s'",
                           MC_SHOW(tok));
        if (i > 0 && (uint64_t)i > k->max_used[kind]) {
            k->max_used[kind] = (uint64_t)i;
            k->max_line[kind] = line;
        } else if (i < 0 && (uint64_t)(-(i + 1)) + 1 > k->defined[kind]) {
            return mc_fail(c, w,
                           "relative index %lld in '%.*s', but only %llu '%s' lines precede it", i,
                           MC_SHOW(tok), (unsigned long long)k->defined[kind], obj_kind[kind]);
        }
    }
    if (more)
        return mc_fail(c, w, "expected at most three indices in '%.*s'", MC_SHOW(tok));
    return THZ_OK;
}

/* Whether assimp counts tok among a line's numbers: it starts with a digit or a sign
 * (".5" is not counted; "#" and words are not). */
static bool obj_numeric_looking(mc_span tok)
{
    char ch = tok.p[0];
    return (ch >= '0' && ch <= '9') || ch == '-' || ch == '+';
}

/* A 'v' line as the importer reads it: it counts the tokens that look like numbers on
 * the line, comments and words included, takes 3 (x y z), 4 (x y z w, divided by w) or 6
 * (x y z r g b), and then reads that many tokens from the start, each a number. Anything
 * else it refused with no line ("vertex index out of range", "Division by zero",
 * "Cannot parse string"), or it silently took fewer. */
static thz_status obj_vertex(mc_ctx *c, mc_where w, mc_span rest)
{
    mc_span all = rest, tok;
    int counted = 0;
    while (mc_token(&all, &tok, '\\'))
        counted += obj_numeric_looking(tok);
    if (counted != 3 && counted != 4 && counted != 6)
        return mc_fail(c, w,
                       "expected 'v x y z', 'v x y z w' or 'v x y z r g b' (numbers that start "
                       "with a digit or a sign, 0.5 not .5; a comment on its own line), found "
                       "%d such numbers",
                       counted);
    double value = 0.0;
    for (int k = 0; k < counted; k++) {
        mc_token(&rest, &tok, '\\');
        if (!obj_numeric_looking(tok) || !mc_number(tok, &value))
            return mc_fail(c, w,
                           "expected %d finite numbers after 'v' (0.5 not .5; a comment on its "
                           "own line)",
                           counted);
    }
    if (counted == 4 && (float)value == 0.0f)
        return mc_fail(c, w, "a homogeneous w of 0 puts the vertex at infinity (expected w not 0)");
    return THZ_OK;
}

static thz_status obj_check(mc_ctx *c, const char *data, size_t size)
{
    thz_status st = mc_check_text(c, data, size, "a Wavefront OBJ file");
    if (st != THZ_OK)
        return st;
    obj_counts k;
    memset(&k, 0, sizeof k);
    const char *pos = data, *end = data + size;
    uint64_t line_no = 0;
    mc_span line;
    while (st == THZ_OK && mc_line(&pos, end, &line)) {
        uint64_t first = ++line_no;
        /* A '\' at the end of a line continues it on the next one. */
        for (;;) {
            const char *e = line.end;
            while (e > line.p && mc_space(e[-1], 0))
                e--;
            if (e == line.p || e[-1] != '\\' || pos >= end)
                break;
            mc_span more;
            mc_line(&pos, end, &more);
            line.end = more.end;
            line_no++;
        }
        mc_span tok, rest = line;
        if (!mc_token(&rest, &tok, '\\') || tok.p[0] == '#')
            continue;
        mc_where w = {false, first};
        if (mc_is(tok, "v") || mc_is(tok, "vt") || mc_is(tok, "vn")) {
            int kind = mc_is(tok, "v") ? 0 : mc_is(tok, "vt") ? 1 : 2;
            int need = kind == 1 ? 1 : 3;
            if (kind == 0)
                st = obj_vertex(c, w, rest);
            for (int i = 0; i < need && st == THZ_OK && kind != 0; i++) {
                mc_span num;
                double v;
                if (!mc_token(&rest, &num, '\\') || !mc_number(num, &v))
                    st = mc_fail(c, w, "expected %d finite numbers after '%s'", need,
                                 obj_kind[kind]);
            }
            k.defined[kind]++;
        } else if (mc_is(tok, "f") || mc_is(tok, "l") || mc_is(tok, "p")) {
            bool face = mc_is(tok, "f");
            uint64_t n = 0;
            /* past the limit only counted, for the message (mc_polygon refuses it) */
            while (st == THZ_OK && mc_token(&rest, &tok, '\\'))
                if (++n <= MESH_MAX_POLYGON_VERTICES || !face)
                    st = obj_reference(c, &k, tok, first);
            if (st == THZ_OK && n == 0)
                st = mc_fail(c, w, "expected vertex references after '%s'", face ? "f" : "l/p");
            if (st == THZ_OK && face && n >= 3)
                st = mc_polygon(c, n, w);
        }
        /* other statements (o, g, s, usemtl, mtllib, free-form geometry, ...) add no
         * geometry that is imported: the importer skips them */
    }
    for (int kind = 0; kind < 3 && st == THZ_OK; kind++)
        if (k.max_used[kind] > k.defined[kind])
            st = mc_fail(c, (mc_where){false, k.max_line[kind]},
                         "index %llu, but the file has only %llu '%s' lines",
                         (unsigned long long)k.max_used[kind], (unsigned long long)k.defined[kind],
                         obj_kind[kind]);
    return st;
}

/* ---- STL ------------------------------------------------------------------------ */

/* ASCII STL tokens with their line numbers. */
typedef struct stl_text {
    mc_span rest;     /* what is left of the file */
    uint64_t line;    /* of the last token read */
    const char *seen; /* the file's text up to here is counted in `line` */
} stl_text;

static bool stl_next(stl_text *t, mc_span *tok)
{
    if (!mc_token(&t->rest, tok, 0))
        return false;
    for (const char *p = t->seen; p < tok->p; p++)
        t->line += *p == '\n';
    t->seen = tok->p;
    return true;
}

/* The next token must be `word`. */
static thz_status stl_expect(mc_ctx *c, stl_text *t, const char *word, const char *context)
{
    mc_span tok;
    if (!stl_next(t, &tok))
        return mc_fail(c, (mc_where){false, t->line}, "the file ends %s: expected '%s'", context,
                       word);
    if (!mc_is_ci(tok, word))
        return mc_fail(c, (mc_where){false, t->line}, "expected '%s' %s, found '%.*s'", word,
                       context, MC_SHOW(tok));
    return THZ_OK;
}

static thz_status stl_numbers(mc_ctx *c, stl_text *t, const char *what)
{
    for (int i = 0; i < 3; i++) {
        mc_span tok;
        double v;
        if (!stl_next(t, &tok) || !mc_number(tok, &v))
            return mc_fail(c, (mc_where){false, t->line},
                           "expected three finite numbers after '%s'", what);
    }
    return THZ_OK;
}

/* Skips the rest of the current line (a solid's name). */
static void stl_skip_line(stl_text *t)
{
    const char *nl = memchr(t->rest.p, '\n', (size_t)(t->rest.end - t->rest.p));
    t->rest.p = nl ? nl : t->rest.end;
}

static thz_status stl_check_ascii(mc_ctx *c, const char *data, size_t size)
{
    thz_status st = mc_check_text(c, data, size, "an ASCII STL file");
    stl_text t = {{data, data + size}, 1, data};
    mc_span tok;
    bool in_solid = false;
    while (st == THZ_OK && stl_next(&t, &tok)) {
        mc_where w = {false, t.line};
        if (!in_solid) {
            if (!mc_is_ci(tok, "solid"))
                return mc_fail(c, w, "expected 'solid', found '%.*s'", MC_SHOW(tok));
            stl_skip_line(&t);
            in_solid = true;
        } else if (mc_is_ci(tok, "endsolid")) {
            stl_skip_line(&t);
            in_solid = false;
        } else if (mc_is_ci(tok, "facet")) {
            st = stl_expect(c, &t, "normal", "after 'facet'");
            if (st == THZ_OK)
                st = stl_numbers(c, &t, "facet normal");
            if (st == THZ_OK)
                st = stl_expect(c, &t, "outer", "after the facet normal");
            if (st == THZ_OK)
                st = stl_expect(c, &t, "loop", "after 'outer'");
            for (int v = 0; v < 3 && st == THZ_OK; v++) {
                st = stl_expect(c, &t, "vertex", "in a facet of three vertices");
                if (st == THZ_OK)
                    st = stl_numbers(c, &t, "vertex");
            }
            if (st == THZ_OK)
                st = stl_expect(c, &t, "endloop", "after a facet's three vertices");
            if (st == THZ_OK)
                st = stl_expect(c, &t, "endfacet", "after 'endloop'");
            if (st == THZ_OK)
                st = mc_polygon(c, 3, w);
        } else {
            return mc_fail(c, w, "expected 'facet' or 'endsolid', found '%.*s'", MC_SHOW(tok));
        }
    }
    if (st == THZ_OK && in_solid)
        st = mc_fail(c, (mc_where){false, t.line},
                     "the file ends inside a solid: expected "
                     "'endsolid'");
    return st;
}

static thz_status stl_check(mc_ctx *c, const char *data, size_t size)
{
    uint64_t count = 0;
    if (size >= 84)
        for (int i = 0; i < 4; i++)
            count |= (uint64_t)(unsigned char)data[80 + i] << (8 * i);
    if (size >= 84 && 84 + 50 * count == size) {
        /* binary, as the importer decides: exactly the size the count needs */
        if (count > MESH_MAX_TRIANGLES)
            return mc_fail(c, (mc_where){true, 80}, "%llu triangles, more than the limit of %u",
                           (unsigned long long)count, MESH_MAX_TRIANGLES);
        c->triangles = count;
        c->work = 9 * count;
        /* the corners' coordinates finite, as an ASCII file's numbers must be (NaN
         * reached the import, which named a vertex of its own numbering): a float32's
         * exponent bits all ones; the normal before them is not used */
        const unsigned char *b = (const unsigned char *)data;
        for (uint64_t t = 0; t < count; t++)
            for (uint64_t k = 0; k < 9; k++) {
                uint64_t at = 84 + 50 * t + 12 + 4 * k;
                uint32_t bits = (uint32_t)b[at] | (uint32_t)b[at + 1] << 8 |
                                (uint32_t)b[at + 2] << 16 | (uint32_t)b[at + 3] << 24;
                if (((bits >> 23) & 0xffu) == 0xffu)
                    return mc_fail(c, (mc_where){true, at},
                                   "triangle %llu: vertex %llu has a coordinate that is not a "
                                   "finite number (NaN or infinity)",
                                   (unsigned long long)t + 1, (unsigned long long)k / 3 + 1);
            }
        return THZ_OK;
    }
    mc_span all = {data, data + size}, tok;
    if (mc_token(&all, &tok, 0) && mc_is_ci(tok, "solid") && !memchr(data, '\0', size))
        return stl_check_ascii(c, data, size);
    if (size >= 84)
        return mc_fail(c, (mc_where){true, 80},
                       "a binary STL whose header counts %llu triangles, which take 84 + 50 x "
                       "%llu = %llu bytes, but the file has %zu bytes (truncated or not an STL "
                       "file; an ASCII STL starts with 'solid')",
                       (unsigned long long)count, (unsigned long long)count,
                       (unsigned long long)(84 + 50 * count), size);
    return mc_fail(c, (mc_where){true, 0},
                   "neither an ASCII STL (which starts with 'solid') nor a binary one (at least "
                   "84 bytes); the file has %zu bytes",
                   size);
}

/* ---- dispatch ------------------------------------------------------------------- */

static const struct {
    const char *extension;
    mesh_format format;
} mesh_extensions[] = {
    {"obj", MESH_FORMAT_OBJ},
    {"ply", MESH_FORMAT_PLY},
    {"stl", MESH_FORMAT_STL},
};

thz_status mesh_check_format(const char *path, const char *label, mesh_format *format,
                             thz_error *err)
{
    const char *name = label ? label : path;
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    for (size_t i = 0; dot && i < sizeof mesh_extensions / sizeof mesh_extensions[0]; i++) {
        if (strcasecmp(dot + 1, mesh_extensions[i].extension) == 0) {
            *format = mesh_extensions[i].format;
            return THZ_OK;
        }
    }
    return thz_error_set(err, THZ_ERR_INPUT,
                         "%s: unsupported mesh format '%s': thzmap reads %s, by the file name's "
                         "extension",
                         name, dot ? dot : "(no extension)", mesh_supported_formats);
}

const char *mesh_format_extension(mesh_format format)
{
    for (size_t i = 0; i < sizeof mesh_extensions / sizeof mesh_extensions[0]; i++)
        if (mesh_extensions[i].format == format)
            return mesh_extensions[i].extension;
    return "";
}

thz_status mesh_check(const char *data, size_t size, mesh_format format, const char *label,
                      uint64_t *triangles, thz_error *err)
{
    mc_ctx c = {.label = label, .err = err};
    if (size == 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: the file is empty, expected a mesh", label);
    if (size > MESH_MAX_FILE_BYTES)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: %zu bytes, more than the limit of %llu",
                             label, size, (unsigned long long)MESH_MAX_FILE_BYTES);
    if (format == MESH_FORMAT_OTHER)
        return THZ_OK; /* assimp's alone to read (mesh_check.h) */
    thz_status st = format == MESH_FORMAT_OBJ   ? obj_check(&c, data, size)
                    : format == MESH_FORMAT_PLY ? mc_check_ply(&c, data, size)
                                                : stl_check(&c, data, size);
    if (st == THZ_OK && triangles)
        *triangles = c.triangles;
    return st;
}
