/* Ray casting against the scene's triangles (the only module that includes Embree).
 *
 * One Embree geometry per object, so a hit names its object. Self-intersection rule
 * (documented and tested on 0.1 mm shells): a ray leaving a surface passes the
 * (object, triangle) it leaves from in `ignore` and is filtered against it, and its
 * origin is offset along the geometric normal to the side it leaves on by a distance
 * relative to the size of the hit point's coordinates; see accel.c for the exact numbers.
 */
#ifndef THZ_ACCEL_ACCEL_H
#define THZ_ACCEL_ACCEL_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/vec3.h"
#include "scene/scene.h"

typedef struct accel accel;

typedef struct accel_hit {
    double distance_m; /* along the unit ray direction */
    uint32_t object;   /* index into scene->objects */
    uint32_t triangle; /* index into that object's mesh */
    int side;          /* 0: arrived on the front (normal) side, 1: on the back */
    double cos_theta;  /* |cos| between the ray and the triangle normal, in (0, 1] */
    vec3 position_m;   /* hit point */
} accel_hit;

/* Builds the acceleration structure for the scene (borrowed; must outlive it). */
thz_status accel_create(const thz_scene *scene, accel **out, thz_error *err);

/* The instruction set accel_create caps Embree's kernels at (Embree's `max_isa`):
 * THZMAP_EMBREE_MAX_ISA's, avx2 when unset or empty; THZ_ERR_INPUT for a value that names
 * none. For a caller that makes an Embree device of its own to compare with (the
 * benchmark's probe). */
thz_status accel_max_isa(const char **isa, thz_error *err);
void accel_destroy(accel *a);

/* Sentinel for "nothing to ignore". */
#define ACCEL_NO_OBJECT UINT32_MAX

/* Closest hit along origin + t*dir, t in (0, max_distance_m], ignoring triangle
 * (ignore_object, ignore_triangle) (pass ACCEL_NO_OBJECT for none). dir is unit.
 * Returns false if nothing is hit. Thread-safe. */
bool accel_intersect(const accel *a, vec3 origin_m, vec3 dir, double max_distance_m,
                     uint32_t ignore_object, uint32_t ignore_triangle, accel_hit *hit);

/* The origin for a ray leaving `hit` into the hemisphere of `dir`: the hit point offset
 * slightly along the normal towards dir. */
vec3 accel_offset_origin(const accel *a, const accel_hit *hit, vec3 dir);

#endif
