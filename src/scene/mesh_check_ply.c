/* The PLY check (ASCII, binary little- and big-endian): the header, then every
 * declared record against the bytes that follow it. See mesh_check.h. */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

#include "scene/mesh_check.h"
#include "scene/mesh_check_internal.h"

enum { PLY_MAX_ELEMENTS = 32, PLY_MAX_PROPERTIES = 64 };

typedef enum ply_encoding { PLY_ASCII, PLY_LITTLE, PLY_BIG } ply_encoding;

/* The scalar types; both spellings of the PLY specification. */
static const struct {
    const char *name, *alias;
    unsigned size;
    bool integer, is_signed;
} ply_types[] = {
    {"char", "int8", 1, true, true},      {"uchar", "uint8", 1, true, false},
    {"short", "int16", 2, true, true},    {"ushort", "uint16", 2, true, false},
    {"int", "int32", 4, true, true},      {"uint", "uint32", 4, true, false},
    {"float", "float32", 4, false, true}, {"double", "float64", 8, false, true},
};
enum { PLY_N_TYPES = sizeof ply_types / sizeof ply_types[0] };

typedef struct ply_property {
    int type;       /* scalar type, or the item type of a list */
    int count_type; /* the list's count type; -1 for a scalar */
    bool is_index;  /* the face's vertex_indices (or vertex_index) list */
    char name[16];  /* first characters, to find x, y, z */
} ply_property;

typedef struct ply_element {
    char name[32];
    uint64_t count;
    uint64_t line; /* of its `element` line */
    size_t n_props;
    ply_property props[PLY_MAX_PROPERTIES];
} ply_element;

typedef struct ply_header {
    ply_encoding encoding;
    bool has_format;
    size_t n_elements;
    ply_element elements[PLY_MAX_ELEMENTS];
    uint64_t n_vertices;
    size_t body;        /* offset of the first byte after end_header's line */
    uint64_t body_line; /* line number of the body's first line */
} ply_header;

static int ply_type(mc_span tok)
{
    for (int i = 0; i < PLY_N_TYPES; i++)
        if (mc_is(tok, ply_types[i].name) || mc_is(tok, ply_types[i].alias))
            return i;
    return -1;
}

static void ply_copy_name(char *dst, size_t size, mc_span tok)
{
    size_t n = (size_t)(tok.end - tok.p);
    n = n < size - 1 ? n : size - 1;
    memcpy(dst, tok.p, n);
    dst[n] = '\0';
}

/* One `property` line (after the keyword). */
static thz_status ply_property_line(mc_ctx *c, ply_header *h, mc_span rest, mc_where w)
{
    if (h->n_elements == 0)
        return mc_fail(c, w, "a 'property' line before any 'element' line");
    ply_element *e = &h->elements[h->n_elements - 1];
    if (e->n_props == PLY_MAX_PROPERTIES)
        return mc_fail(c, w, "more than %d properties in element '%s'", PLY_MAX_PROPERTIES,
                       e->name);
    ply_property *p = &e->props[e->n_props];
    mc_span tok, name;
    p->count_type = -1;
    if (!mc_token(&rest, &tok, 0))
        return mc_fail(c, w,
                       "expected 'property TYPE NAME' or 'property list COUNT_TYPE "
                       "ITEM_TYPE NAME'");
    if (mc_is(tok, "list")) {
        if (!mc_token(&rest, &tok, 0) || (p->count_type = ply_type(tok)) < 0 ||
            !ply_types[p->count_type].integer)
            return mc_fail(c, w, "expected an integer count type after 'property list'");
        if (!mc_token(&rest, &tok, 0))
            return mc_fail(c, w, "expected the list's item type");
    }
    if ((p->type = ply_type(tok)) < 0)
        return mc_fail(c, w,
                       "unknown property type '%.*s' (expected char, uchar, short, "
                       "ushort, int, uint, float, double or int8 ... float64)",
                       MC_SHOW(tok));
    if (!mc_token(&rest, &name, 0))
        return mc_fail(c, w, "expected the property's name");
    ply_copy_name(p->name, sizeof p->name, name);
    p->is_index = strcmp(e->name, "face") == 0 &&
                  (mc_is(name, "vertex_indices") || mc_is(name, "vertex_index"));
    if (p->is_index && (p->count_type < 0 || !ply_types[p->type].integer))
        return mc_fail(c, w, "the face's '%s' must be a list of integers", p->name);
    e->n_props++;
    return THZ_OK;
}

/* One header line; *done at end_header. */
static thz_status ply_header_line(mc_ctx *c, ply_header *h, mc_span line, mc_where w, bool *done)
{
    mc_span tok, rest = line;
    if (!mc_token(&rest, &tok, 0))
        return THZ_OK;
    if (mc_is(tok, "comment") || mc_is(tok, "obj_info"))
        return THZ_OK;
    if (mc_is(tok, "end_header")) {
        *done = true;
        return THZ_OK;
    }
    if (mc_is(tok, "format")) {
        if (h->has_format)
            return mc_fail(c, w, "a second 'format' line");
        if (!mc_token(&rest, &tok, 0))
            tok = (mc_span){rest.p, rest.p};
        if (mc_is(tok, "ascii"))
            h->encoding = PLY_ASCII;
        else if (mc_is(tok, "binary_little_endian"))
            h->encoding = PLY_LITTLE;
        else if (mc_is(tok, "binary_big_endian"))
            h->encoding = PLY_BIG;
        else
            return mc_fail(c, w,
                           "expected 'format ascii|binary_little_endian|binary_big_endian "
                           "1.0'");
        h->has_format = true;
        return THZ_OK;
    }
    if (mc_is(tok, "element")) {
        if (h->n_elements == PLY_MAX_ELEMENTS)
            return mc_fail(c, w, "more than %d elements", PLY_MAX_ELEMENTS);
        ply_element *e = &h->elements[h->n_elements];
        mc_span name;
        long long count;
        if (!mc_token(&rest, &name, 0) || !mc_token(&rest, &tok, 0) || !mc_integer(tok, &count) ||
            count < 0 || count > (long long)UINT32_MAX)
            return mc_fail(c, w, "expected 'element NAME COUNT' with 0 <= COUNT <= %u", UINT32_MAX);
        if (mc_is(name, "tristrips"))
            return mc_fail(c, w, "triangle strips ('tristrips') are not supported; use faces");
        ply_copy_name(e->name, sizeof e->name, name);
        e->count = (uint64_t)count;
        e->line = w.at;
        e->n_props = 0;
        h->n_elements++;
        return THZ_OK;
    }
    if (mc_is(tok, "property"))
        return ply_property_line(c, h, rest, w);
    return mc_fail(c, w,
                   "unexpected header line '%.*s' (expected format, element, property, "
                   "comment, obj_info or end_header)",
                   MC_SHOW(tok));
}

/* The header up to end_header, bounded by MESH_MAX_PLY_HEADER_BYTES, and what must hold
 * for the body to be read. */
static thz_status ply_read_header(mc_ctx *c, const char *data, size_t size, ply_header *h)
{
    size_t limit = size < MESH_MAX_PLY_HEADER_BYTES ? size : MESH_MAX_PLY_HEADER_BYTES;
    const char *pos = data, *end = data + limit;
    mc_span line, tok;
    uint64_t line_no = 0;
    bool done = false;
    while (!done && mc_line(&pos, end, &line)) {
        mc_where w = {false, ++line_no};
        if (pos == end && line.end == end && limit < size)
            break; /* cut by the limit: not a whole line */
        if (memchr(line.p, '\0', (size_t)(line.end - line.p)))
            return mc_fail(c, w, "a NUL byte: binary data where the PLY header is text");
        thz_status st;
        if (line_no == 1) {
            mc_span rest = line;
            if (!mc_token(&rest, &tok, 0) || !mc_is(tok, "ply") || mc_token(&rest, &tok, 0))
                return mc_fail(c, w, "expected 'ply' on the first line of a PLY file");
            continue;
        }
        st = ply_header_line(c, h, line, w, &done);
        if (st != THZ_OK)
            return st;
    }
    if (!done) {
        if (limit < size)
            return mc_fail(c, (mc_where){true, limit},
                           "no 'end_header' line in the first %u bytes: not a PLY header",
                           MESH_MAX_PLY_HEADER_BYTES);
        return mc_fail(c, (mc_where){false, line_no},
                       "the file ends in the PLY header: expected an 'end_header' line");
    }
    if (!h->has_format)
        return mc_fail(c, (mc_where){false, line_no}, "the header has no 'format' line");
    h->body = (size_t)(pos - data);
    h->body_line = line_no + 1;
    bool xyz[3] = {false, false, false};
    for (size_t i = 0; i < h->n_elements; i++) {
        ply_element *e = &h->elements[i];
        mc_where w = {false, e->line};
        if (e->count > 0 && e->n_props == 0)
            return mc_fail(c, w, "element '%s' declares %llu records but no properties", e->name,
                           (unsigned long long)e->count);
        bool has_index = false;
        for (size_t k = 0; k < e->n_props; k++) {
            has_index |= e->props[k].is_index;
            for (int a = 0; strcmp(e->name, "vertex") == 0 && a < 3; a++)
                if (e->props[k].count_type < 0 && e->props[k].name[0] == "xyz"[a] &&
                    e->props[k].name[1] == '\0')
                    xyz[a] = true;
        }
        if (strcmp(e->name, "vertex") == 0)
            h->n_vertices = e->count;
        if (strcmp(e->name, "face") == 0 && !has_index)
            return mc_fail(c, w, "element 'face' has no 'vertex_indices' list");
    }
    if (!xyz[0] || !xyz[1] || !xyz[2])
        return mc_fail(c, (mc_where){false, line_no},
                       "the header declares no 'vertex' element with properties x, y and z");
    return THZ_OK;
}

/* The declared records against the bytes after the header, at their smallest: each
 * scalar its size (ASCII: 2 bytes, a digit and a separator), each list its count. */
static thz_status ply_check_sizes(mc_ctx *c, const ply_header *h, size_t size)
{
    uint64_t need = 0, have = size - h->body;
    for (size_t i = 0; i < h->n_elements; i++) {
        const ply_element *e = &h->elements[i];
        uint64_t record = 0;
        for (size_t k = 0; k < e->n_props; k++) {
            const ply_property *p = &e->props[k];
            unsigned bytes = ply_types[p->count_type >= 0 ? p->count_type : p->type].size;
            record += h->encoding == PLY_ASCII ? 2u : bytes;
        }
        need += e->count * record; /* <= 2^32 * 64 * 8 each: no overflow */
        if (need > have)
            return mc_fail(c, (mc_where){false, e->line},
                           "element '%s' declares %llu records of at least %llu bytes, which "
                           "with those before it need at least %llu bytes, but the file has %llu "
                           "bytes after its header (truncated, or a wrong count)",
                           e->name, (unsigned long long)e->count, (unsigned long long)record,
                           (unsigned long long)need, (unsigned long long)have);
    }
    return THZ_OK;
}

/* A binary integer of type t at p. */
static long long ply_get_int(const unsigned char *p, int t, bool big)
{
    unsigned n = ply_types[t].size;
    uint64_t v = 0;
    for (unsigned i = 0; i < n; i++)
        v |= (uint64_t)p[big ? i : n - 1 - i] << (8 * (n - 1 - i));
    if (ply_types[t].is_signed && n < 8 && (v >> (8 * n - 1)) & 1u)
        return (long long)v - (long long)((uint64_t)1 << (8 * n));
    return (long long)v;
}

/* Whether the float or double at p (PLY type t, its bytes in the file's order) is finite:
 * its exponent bits are not all ones (NaN, infinity). */
static bool ply_finite(const unsigned char *p, int t, bool big)
{
    unsigned n = ply_types[t].size;
    uint64_t v = 0;
    for (unsigned i = 0; i < n; i++)
        v |= (uint64_t)p[big ? i : n - 1 - i] << (8 * (n - 1 - i));
    return n == 4 ? ((v >> 23) & 0xffu) != 0xffu : ((v >> 52) & 0x7ffu) != 0x7ffu;
}

/* A list count, checked against its bound. */
static thz_status ply_list_count(mc_ctx *c, const ply_element *e, const ply_property *p,
                                 long long n, mc_where w)
{
    uint64_t bound = p->is_index ? MESH_MAX_POLYGON_VERTICES : MESH_MAX_LIST_VALUES;
    if (p->is_index && n == 0) /* assimp's triangulation aborts the process on it */
        return mc_fail(c, w, "a face of no vertices in element '%s'", e->name);
    if (n < 0 || (uint64_t)n > bound)
        return mc_fail(c, w, "a '%s' list of %lld values in element '%s', expected 0 to %llu%s",
                       p->name, n, e->name, (unsigned long long)bound,
                       p->is_index ? " (a polygon's vertices; split larger ones)" : "");
    return THZ_OK;
}

/* A vertex index of a face. */
static thz_status ply_index(mc_ctx *c, const ply_header *h, long long v, mc_where w)
{
    if (v < 0 || (uint64_t)v >= h->n_vertices)
        return mc_fail(c, w, "vertex index %lld, expected 0 to %lld (the file has %llu vertices)",
                       v, (long long)h->n_vertices - 1, (unsigned long long)h->n_vertices);
    return THZ_OK;
}

/* Record r of e, binary, from *at: list counts bounded, face indices checked, floats
 * finite (as an ASCII file's numbers must be). Returns THZ_ERR_LIMIT, without a message,
 * when the file ends inside it. */
static thz_status ply_binary_record(mc_ctx *c, const ply_header *h, const ply_element *e,
                                    uint64_t r, const unsigned char *b, size_t size, uint64_t *at)
{
    bool big = h->encoding == PLY_BIG;
    for (size_t k = 0; k < e->n_props; k++) {
        const ply_property *p = &e->props[k];
        unsigned isize = ply_types[p->type].size;
        long long n = 1;
        if (p->count_type >= 0) {
            unsigned csize = ply_types[p->count_type].size;
            if (*at + csize > size)
                return THZ_ERR_LIMIT;
            n = ply_get_int(b + *at, p->count_type, big);
            thz_status st = ply_list_count(c, e, p, n, (mc_where){true, *at});
            if (st != THZ_OK)
                return st;
            *at += csize;
        }
        if (*at + (uint64_t)n * isize > size)
            return THZ_ERR_LIMIT;
        for (long long j = 0; !ply_types[p->type].integer && j < n; j++) {
            uint64_t where = *at + (uint64_t)j * isize;
            if (!ply_finite(b + where, p->type, big))
                return mc_fail(c, (mc_where){true, where},
                               "expected a finite number for '%s' of record %llu of element "
                               "'%s', found NaN or infinity",
                               p->name, (unsigned long long)r + 1, e->name);
        }
        for (long long j = 0; p->is_index && j < n; j++) {
            uint64_t where = *at + (uint64_t)j * isize;
            thz_status st =
                ply_index(c, h, ply_get_int(b + where, p->type, big), (mc_where){true, where});
            if (st != THZ_OK)
                return st;
        }
        if (p->is_index && n >= 3) {
            thz_status st = mc_polygon(c, (uint64_t)n, (mc_where){true, *at});
            if (st != THZ_OK)
                return st;
        }
        *at += (uint64_t)n * isize;
    }
    return THZ_OK;
}

static thz_status ply_walk_binary(mc_ctx *c, const ply_header *h, const char *data, size_t size)
{
    const unsigned char *b = (const unsigned char *)data;
    uint64_t at = h->body;
    for (size_t i = 0; i < h->n_elements; i++) {
        const ply_element *e = &h->elements[i];
        bool fixed = true, floats = false;
        uint64_t record = 0;
        for (size_t k = 0; k < e->n_props; k++) {
            fixed &= e->props[k].count_type < 0;
            floats |= !ply_types[e->props[k].type].integer;
            record += ply_types[e->props[k].type].size;
        }
        if (fixed && !floats) { /* ply_check_sizes made sure they fit */
            at += e->count * record;
            continue;
        }
        for (uint64_t r = 0; r < e->count; r++) {
            thz_status st = ply_binary_record(c, h, e, r, b, size, &at);
            if (st == THZ_ERR_LIMIT)
                return mc_fail(c, (mc_where){true, size},
                               "the file ends inside record %llu of the %llu of element '%s'",
                               (unsigned long long)r + 1, (unsigned long long)e->count, e->name);
            if (st != THZ_OK)
                return st;
        }
    }
    return THZ_OK;
}

/* One ASCII record: the values of line. */
static thz_status ply_ascii_record(mc_ctx *c, const ply_header *h, const ply_element *e,
                                   mc_span line, mc_where w)
{
    mc_span tok;
    for (size_t k = 0; k < e->n_props; k++) {
        const ply_property *p = &e->props[k];
        long long n = 1;
        if (p->count_type >= 0) {
            if (!mc_token(&line, &tok, 0) || !mc_integer(tok, &n))
                return mc_fail(c, w, "expected the count of the '%s' list of element '%s'", p->name,
                               e->name);
            thz_status st = ply_list_count(c, e, p, n, w);
            if (st != THZ_OK)
                return st;
        }
        for (long long j = 0; j < n; j++) {
            double v;
            long long iv;
            bool ok = mc_token(&line, &tok, 0) &&
                      (p->is_index ? mc_integer(tok, &iv) : mc_number(tok, &v));
            if (!ok)
                return mc_fail(c, w, "expected %s for '%s' of element '%s'%s",
                               p->is_index ? "an integer vertex index" : "a finite number", p->name,
                               e->name, line.p == line.end ? ", the line ends" : "");
            if (p->is_index) {
                thz_status st = ply_index(c, h, iv, w);
                if (st != THZ_OK)
                    return st;
            }
        }
        if (p->is_index && n >= 3) {
            thz_status st = mc_polygon(c, (uint64_t)n, w);
            if (st != THZ_OK)
                return st;
        }
    }
    if (mc_token(&line, &tok, 0))
        return mc_fail(c, w, "more values than element '%s' declares, from '%.*s'", e->name,
                       MC_SHOW(tok));
    return THZ_OK;
}

static thz_status ply_walk_ascii(mc_ctx *c, const ply_header *h, const char *data, size_t size)
{
    thz_status st = mc_check_text(c, data + h->body, size - h->body, "an ASCII PLY body");
    const char *pos = data + h->body, *end = data + size;
    uint64_t line_no = h->body_line - 1;
    mc_span line, tok;
    for (size_t i = 0; i < h->n_elements && st == THZ_OK; i++) {
        const ply_element *e = &h->elements[i];
        for (uint64_t r = 0; r < e->count && st == THZ_OK; r++) {
            bool found = false;
            while (!found && mc_line(&pos, end, &line)) {
                line_no++;
                mc_span probe = line;
                found = mc_token(&probe, &tok, 0); /* blank lines are skipped */
            }
            if (!found)
                return mc_fail(c, (mc_where){false, line_no},
                               "the file ends after %llu of the %llu records of element '%s'",
                               (unsigned long long)r, (unsigned long long)e->count, e->name);
            st = ply_ascii_record(c, h, e, line, (mc_where){false, line_no});
        }
    }
    return st;
}

thz_status mc_check_ply(mc_ctx *c, const char *data, size_t size)
{
    ply_header *h = thz_calloc(1, sizeof *h); /* ~60 KB: not on the stack */
    if (!h)
        return thz_error_set(c->err, THZ_ERR_NOMEM, "%s: out of memory while checking it",
                             c->label);
    thz_status st = ply_read_header(c, data, size, h);
    if (st == THZ_OK)
        st = ply_check_sizes(c, h, size);
    if (st == THZ_OK)
        st = h->encoding == PLY_ASCII ? ply_walk_ascii(c, h, data, size)
                                      : ply_walk_binary(c, h, data, size);
    free(h);
    return st;
}
