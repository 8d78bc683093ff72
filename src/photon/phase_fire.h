/* Firing a range of a channel's photons (photon/phase.h says the determinism it keeps):
 * the photons of each batch of PHASE_BATCH in chunks of PHASE_CHUNK over OpenMP threads,
 * each chunk's records and counters merged after the batch in chunk order. phase.c
 * prepares the sources and calls it for a whole phase or a process's share; phase_fire.c
 * fires. Nothing here is public.
 */
#ifndef THZ_PHOTON_PHASE_FIRE_H
#define THZ_PHOTON_PHASE_FIRE_H

#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/air_emission.h"
#include "photon/emission.h"
#include "photon/photon_map.h"
#include "photon/trace.h"
#include "scene/scene.h"

typedef struct phase_fire_args {
    const thz_scene *scene;
    const accel *acc;
    const emission_table *table;
    const air_emission *air; /* the emitting air, or NULL */
    size_t channel;
    uint64_t n_photons;    /* K: the phase's photons (their power is P / K) */
    uint64_t lo, hi;       /* fire photons [lo, hi) of K (lo a multiple of PHASE_BATCH) */
    uint64_t first_photon; /* index of the first photon (its random stream and batch) */
    int threads;
    photon_map_pool *pool;      /* the record array's first memory, or NULL */
    const trace_optics *optics; /* the objects' constant optics, or NULL */
    /* Progress after every batch but the last: the last is the caller's to report, once
     * the map is built, so that a display timing the stages gives the index build to the
     * photons and not to the render that follows. */
    thz_progress_fn progress;
    void *progress_user;
} phase_fire_args;

/* Fires photons first_photon + lo..hi-1, returning their records in photon-index order (a
 * malloc'd array of *out_capacity, never NULL on success) and the summed counters;
 * chunk_out (may be NULL) gets each chunk's counters in order (room for
 * ceil((hi - lo) / PHASE_CHUNK)). */
thz_status phase_fire(const phase_fire_args *a, photon_record **out_records, size_t *out_count,
                      size_t *out_capacity, trace_counters *total, trace_counters *chunk_out,
                      thz_error *err);

#endif
