/* Mesh files through assimp: Wavefront OBJ (.obj), PLY (.ply, ASCII and binary) and STL
 * (.stl, ASCII and binary), the formats mesh_check.h checks before assimp sees a file
 * (others are refused: an unchecked file could hang the import). Polygons are triangulated and the
 * node transforms baked in; nothing that reorders the winding or invents normals is applied,
 * because the normals follow the winding order (a mesh's front side is where its triangles turn
 * counter-clockwise). Vertices at exactly the same position are merged, so that
 * formats storing each triangle's corners separately (STL) come out connected, and
 * vertices no triangle uses (those of points and lines) are dropped.
 */
#ifndef THZ_SCENE_MESH_IMPORT_H
#define THZ_SCENE_MESH_IMPORT_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "scene/scene.h"

/* Reads the file at path into mesh (positions and indices; mesh_finalize computes the
 * rest). `label` (NULL: path) names the file in messages. THZ_ERR_INPUT when the file
 * is missing, not a regular file, of another format, fails the checks of mesh_check.h,
 * or holds no triangles; THZ_ERR_NOMEM when memory runs out. */
thz_status mesh_import(const char *path, const char *label, thz_mesh *mesh, thz_error *err);

/* What a mesh file may hold that its scene should not (load.c warns of each). */
typedef struct mesh_defects {
    /* triangles with the same three corners as an earlier one (either way round): each
     * counts its area and emits again, so the surface there is too bright */
    size_t repeated;
    /* triangles of no area (corners on one line): they emit and stop nothing */
    size_t degenerate;
    /* directed edges that two of the other triangles run the same way: 0 for a
     * consistently wound mesh (a shared edge runs opposite ways in its two triangles; the
     * same way twice means one is wound the other way and its normal points wrong) */
    size_t winding_conflicts;
    /* edges of one triangle only (no other triangle runs them either way): holes, an open
     * surface's rim, or a file cut short; 0 for a closed mesh */
    size_t open_edges;
} mesh_defects;

/* Counts the defects of an imported mesh into *out; false when out of memory. */
bool mesh_import_defects(const thz_mesh *mesh, mesh_defects *out);

#endif
