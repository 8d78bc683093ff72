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

#include <stddef.h>

#include "core/error.h"
#include "scene/scene.h"

/* Reads the file at path into mesh (positions and indices; mesh_finalize computes the
 * rest). `label` (NULL: path) names the file in messages. THZ_ERR_INPUT when the file
 * is missing, not a regular file, of another format, fails the checks of mesh_check.h,
 * or holds no triangles; THZ_ERR_NOMEM when memory runs out. */
thz_status mesh_import(const char *path, const char *label, thz_mesh *mesh, thz_error *err);

/* Number of directed edges used by more than one triangle (in the same direction):
 * 0 for a consistently wound mesh. An edge shared by two triangles must run in
 * opposite directions in them; the same direction twice means one of them is wound
 * the other way, and its normal points to the wrong side. Returns SIZE_MAX on
 * allocation failure. */
size_t mesh_import_winding_conflicts(const thz_mesh *mesh);

#endif
