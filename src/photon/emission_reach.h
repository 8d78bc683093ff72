/* The reach shares of one-sided solids' back sides: the sources EMISSION_BACK of a
 * deviation map (T0 > 0; emission.h) carry -pi A r B0, r the share of cosine rays from
 * uniform points of the back side whose first hit is a front face, estimated from
 * EMISSION_REACH_RAYS rays per object.
 *
 * The shares depend on the scene's geometry and seed only (the rays' streams are channel
 * 0's), not on the channel or T0: a run computes them once and every emission table of the
 * run (each channel's, and its estimates' pilots') takes them from there. Computed per
 * table, serially, 2,025 small boxes (three tables: two pilots and the channel) made a
 * final-gather run of one channel take 24 s on one core, and a stop waited for them; now
 * 5.2 s, 3.7 s of it the shares once, on two cores.
 * The rays run over the threads, an integer count per object, so the shares are the same
 * for any number of threads; progress (stage "prepare", objects done) is reported, and a
 * stop asked, between rounds of objects.
 */
#ifndef THZ_PHOTON_EMISSION_REACH_H
#define THZ_PHOTON_EMISSION_REACH_H

#include <stdbool.h>
#include <stddef.h>

#include "accel/accel.h"
#include "core/error.h"
#include "scene/scene.h"

typedef struct emission_reach {
    bool done;        /* computed (share may still be NULL: no object needs one) */
    double *share;    /* [n_objects]: object i's r where emission_reach_needed, else 1 */
    size_t n_objects; /* of the scene they were computed for */
    double seconds;   /* wall time of the computation */
} emission_reach;

/* Whether object i's back side is a source of a deviation map: a one-sided solid with
 * area. */
bool emission_reach_needed(const thz_scene *scene, size_t i);

/* Computes r's shares for scene (acc: its ray caster) with `threads` OpenMP threads (0:
 * all) unless r is done already. progress (may be NULL) gets, on the calling thread, stage
 * "prepare" of channel 0, done/total in objects: 0 before the first round, then after each;
 * non-zero stops it (THZ_ERR_CANCELLED; r is then left not done). */
thz_status emission_reach_compute(emission_reach *r, const thz_scene *scene, const accel *acc,
                                  int threads, thz_progress_fn progress, void *progress_user,
                                  thz_error *err);

/* Whether the scene's deviation maps need reach shares (an object emission_reach_needed). */
bool emission_reach_any(const thz_scene *scene);

void emission_reach_fini(emission_reach *r);

#endif
