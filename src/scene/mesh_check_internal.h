/* What the mesh file checks share (mesh_check.c: dispatch, OBJ and STL;
 * mesh_check_ply.c: PLY): the running totals, located errors and text tokens.
 */
#ifndef THZ_SCENE_MESH_CHECK_INTERNAL_H
#define THZ_SCENE_MESH_CHECK_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* One check in progress. */
typedef struct mc_ctx {
    const char *label; /* the file, in messages */
    thz_error *err;
    uint64_t triangles; /* after triangulation */
    uint64_t work;      /* sum of the squares of the polygons' vertex counts */
} mc_ctx;

/* Where an error is: a 1-based line of a text file or a byte offset of a binary one. */
typedef struct mc_where {
    bool binary;
    uint64_t at;
} mc_where;

/* A piece of the file's text, [p, end). */
typedef struct mc_span {
    const char *p, *end;
} mc_span;

/* THZ_ERR_INPUT: "LABEL:LINE: message" or "LABEL: byte OFFSET: message". */
thz_status mc_fail(mc_ctx *c, mc_where w, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Counts a polygon of n vertices (n >= 3) against the limits of mesh_check.h. */
thz_status mc_polygon(mc_ctx *c, uint64_t n, mc_where w);

/* The next line of [*pos, end), without its '\n' (a '\r' before it is whitespace);
 * false at the end of the text. */
bool mc_line(const char **pos, const char *end, mc_span *line);

/* The next whitespace-separated token of *s (consumed from it); false when none is
 * left. `extra_space` (may be 0) is one more character to treat as whitespace. */
bool mc_token(mc_span *s, mc_span *tok, char extra_space);

/* tok is exactly `word` (case-sensitive, or ASCII-case-insensitive with _ci). */
bool mc_is(mc_span tok, const char *word);
bool mc_is_ci(mc_span tok, const char *word);

/* tok is a whole finite number / a whole decimal integer. */
bool mc_number(mc_span tok, double *value);
bool mc_integer(mc_span tok, long long *value);

/* The first bytes of tok, for messages: printf("'%.*s'", MC_SHOW(tok)). */
#define MC_SHOW(tok) (int)((tok).end - (tok).p > 32 ? 32 : (tok).end - (tok).p), (tok).p

/* A NUL byte in [data, data + size) as a located error; THZ_OK when there is none. */
thz_status mc_check_text(mc_ctx *c, const char *data, size_t size, const char *what);

thz_status mc_check_ply(mc_ctx *c, const char *data, size_t size);

#endif
