/* The mesh file check: every mesh file is read into memory and checked here before
 * assimp sees it, so that no file, however malformed, can make the import hang, crash
 * or exhaust memory (assimp's PLY reader spins forever without `end_header` and
 * allocates whatever a header declares; its triangulation takes time quadratic in a
 * polygon's vertex count). Only the formats checked here are imported: Wavefront OBJ
 * (.obj), PLY (.ply: ASCII, binary little- and big-endian) and STL (.stl: ASCII and
 * binary), chosen by the file name's extension.
 *
 * What is checked, before anything is allocated from the file's numbers:
 * - OBJ: text; `v` lines hold three finite numbers; every index of `f`, `l` and `p`
 *   names an existing `v`, `vt` or `vn` (1-based or negative, relative); a polygon has
 *   at most MESH_MAX_POLYGON_VERTICES vertices.
 * - PLY: `ply`, one `format`, `element`/`property` lines and `end_header` within
 *   MESH_MAX_PLY_HEADER_BYTES; the declared records must fit in the file (binary: their
 *   exact sizes, list by list; ASCII: one record per line, the declared number of values,
 *   at least 2 bytes per value); list counts bounded; `vertex` has x, y and z; face
 *   indices name existing vertices; every float or double value finite (binary too).
 * - STL: binary exactly when 84 + 50 × (its triangle count) is the file's size, every
 *   corner's coordinate finite; else ASCII with `solid`, `facet normal`, `outer loop`,
 *   three `vertex`, `endloop`, `endfacet`, `endsolid`, every coordinate a finite number.
 * - All: at most MESH_MAX_TRIANGLES triangles after triangulation, and a total
 *   triangulation work (the sum of the squares of the polygons' vertex counts) of at
 *   most MESH_MAX_POLYGON_WORK.
 * Errors are THZ_ERR_INPUT naming the file and the line (text) or byte offset (binary),
 * and what was expected there.
 */
#ifndef THZ_SCENE_MESH_CHECK_H
#define THZ_SCENE_MESH_CHECK_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* Limits (docs/scene-format.md, "mesh"). */
#define MESH_MAX_FILE_BYTES ((uint64_t)1 << 30)   /* 1 GiB */
#define MESH_MAX_TRIANGLES (1u << 24)             /* 16 777 216, after triangulation */
#define MESH_MAX_POLYGON_VERTICES 1024u           /* a 1024-gon triangulates in ~20 ms */
#define MESH_MAX_POLYGON_WORK ((uint64_t)1 << 28) /* sum of n^2: ~4 s of triangulation */
#define MESH_MAX_PLY_HEADER_BYTES 65536u
#define MESH_MAX_LIST_VALUES (8u * MESH_MAX_POLYGON_VERTICES) /* other PLY lists */

/* OBJ, PLY and STL are checked before assimp reads them; MESH_FORMAT_OTHER is any other
 * format assimp reads (by the extension), which only assimp checks, in its child process
 * with a time and a memory limit (mesh_import.c, mesh_import_child.c). */
typedef enum mesh_format {
    MESH_FORMAT_OBJ,
    MESH_FORMAT_PLY,
    MESH_FORMAT_STL,
    MESH_FORMAT_OTHER
} mesh_format;

/* "Wavefront OBJ (.obj), PLY (.ply) or STL (.stl)": the supported list, for messages. */
extern const char *const mesh_supported_formats;

/* The format of the file `path` from its extension (case-insensitive); THZ_ERR_INPUT
 * naming `label` (NULL: path) and the checked formats when it is none of them (the
 * importer then asks assimp whether it reads the extension). */
thz_status mesh_check_format(const char *path, const char *label, mesh_format *format,
                             thz_error *err);

/* The extension assimp is told ("obj", "ply", "stl"; "" for MESH_FORMAT_OTHER). */
const char *mesh_format_extension(mesh_format format);

/* Checks the file's bytes data[0..size) as `format` (see the top of this header;
 * MESH_FORMAT_OTHER: its size only).
 * `label` names the file in messages. *triangles (may be NULL) receives the number of
 * triangles the file holds after triangulation. */
thz_status mesh_check(const char *data, size_t size, mesh_format format, const char *label,
                      uint64_t *triangles, thz_error *err);

#endif
