/* The analytic shapes of scene-format.md, tessellated into triangle meshes in the
 * object's own coordinates. Triangles wind counter-clockwise seen from their front
 * side, so the normals mesh_finalize derives point outwards (inwards for a box with
 * `inward`), and closed shapes share their vertices so that every edge is used once
 * in each direction. Each function replaces what `mesh` held (call mesh_fini first
 * if it held anything) and fills positions and indices only.
 */
#ifndef THZ_SCENE_PRIMITIVES_H
#define THZ_SCENE_PRIMITIVES_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "scene/scene.h"

/* Limits that keep a tessellation within memory and uint32 indices. */
#define PRIMITIVE_MIN_SEGMENTS 3u
#define PRIMITIVE_MAX_SEGMENTS 1000000u
#define PRIMITIVE_MAX_SUBDIVISIONS 8u

/* Allocates a mesh of n_vertices (plus the 4 floats of padding Embree reads past the
 * last vertex) and n_triangles, contents uninitialised except the padding (zero).
 * Shared with the mesh importer. */
thz_status primitive_mesh_alloc(thz_mesh *mesh, size_t n_vertices, size_t n_triangles,
                                thz_error *err);

/* double -> float without the undefined behaviour of out-of-range conversions: values
 * beyond float's range become infinite (and the loader refuses the object). Shared with
 * the transforms. */
float primitive_to_float(double x);

/* Box of size_m centred on the origin; 8 vertices, 12 triangles. */
thz_status primitive_box(thz_mesh *mesh, const double size_m[3], bool inward, thz_error *err);

/* Cylinder of radius r around +z, from z = 0 to z = height; `segments` sides; with
 * caps a closed solid. */
thz_status primitive_cylinder(thz_mesh *mesh, double radius_m, double height_m, bool caps,
                              unsigned segments, thz_error *err);

/* Icosphere centred on the origin: an icosahedron with each triangle split into four
 * `subdivisions` times, vertices projected onto the sphere (20 * 4^s triangles). */
thz_status primitive_sphere(thz_mesh *mesh, double radius_m, unsigned subdivisions, thz_error *err);

/* Rectangle size_m[0] x size_m[1] in the xy plane, centred, normal +z. */
thz_status primitive_rectangle(thz_mesh *mesh, const double size_m[2], thz_error *err);

/* Disk (regular polygon of `segments` sides inscribed in the circle) in the xy plane,
 * centred, normal +z. */
thz_status primitive_disk(thz_mesh *mesh, double radius_m, unsigned segments, thz_error *err);

#endif
