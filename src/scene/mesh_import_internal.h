/* What the files of the mesh import share: mesh_import.c (the caller's process: the file
 * read and checked, the import child started, the mesh it wrote read back),
 * mesh_import_child.c (the child: assimp on the checked bytes, the node tree baked into
 * one mesh), mesh_import_weld.c (vertices at one position merged). mesh_import_defects.c
 * counts a mesh's defects (mesh_import.h). Nothing here is public.
 */
#ifndef THZ_SCENE_MESH_IMPORT_INTERNAL_H
#define THZ_SCENE_MESH_IMPORT_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "scene/mesh_check.h"
#include "scene/scene.h"

/* What the import child needs, and the file (a memfd) it writes the mesh into. */
typedef struct mesh_job {
    const char *name;
    const char *data;
    size_t size;
    mesh_format format;
    char extension[16]; /* what assimp is told the file is */
    int fd;
} mesh_job;

/* The child: imports, then writes the vertex and triangle counts (uint64 each), the
 * positions (3 floats per vertex) and the indices (3 per triangle) into job->fd. */
thz_status mesh_import_child(void *arg, thz_error *err);

/* Keeps the vertices that triangles use (those of points and lines have no surface and
 * would widen the bounding box), merging those at the same position, and renumbers
 * them in position order. */
bool mesh_import_weld(thz_mesh *mesh);

#endif
