/* The tracing limit: a raw Embree probe (issue 6, item 2).
 *
 * Casts a given number of rays against the scene's triangles with nothing but Embree:
 * no filter callback, no hit-point reconstruction, no shading, no records. The rays are
 * of the photon phase's kind: origins uniform over the emitting surfaces (sides by
 * area, as emission picks them, ignoring temperatures and optics), offset off the
 * surface like accel_offset_origin, directions cosine-distributed about the emitting
 * side's normal. The Embree scene is built exactly as src/accel builds it (one
 * geometry per object, robust traversal, high build quality), so the probe and the
 * photon phase traverse the same BVH.
 *
 * A pool of rays is generated first and cast cyclically until the count is reached,
 * so the time measured is the casting alone, on `threads` OpenMP threads in chunks of
 * the photon phase's size.
 */
#ifndef THZ_BENCH_PROBE_H
#define THZ_BENCH_PROBE_H

#include <stdint.h>

#include "core/error.h"
#include "scene/scene.h"

typedef struct bench_probe_result {
    uint64_t rays;        /* rays cast */
    uint64_t hits;        /* of which hit something */
    uint64_t pool;        /* distinct rays generated */
    double seconds;       /* wall time of the casting loop */
    double seconds_build; /* Embree scene build */
} bench_probe_result;

/* Casts n_rays rays on `threads` threads (0: all). */
thz_status bench_probe_run(const thz_scene *scene, uint64_t n_rays, int threads,
                           bench_probe_result *out, thz_error *err);

#endif
