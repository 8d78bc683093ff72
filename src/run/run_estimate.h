/* The up-front estimate of a simulate run's time: a pilot on a small copy of the first
 * rendered sensor (at most RUN_PILOT_SIDE^2 pixels, one sample each of at most
 * RUN_PILOT_ESTIMATES paths or gather rays, pass 0 twice, the second timed) and, for the
 * integrators that need photons, a pilot photon phase of RUN_PILOT_PHOTONS (or the run's photons,
 * if fewer): on channel 0 alone without a noise target, for every channel with one; photon-map's
 * towards a target fires a pass's photons (at most RUN_PILOT_PHOTONS_PASSES), and its noise is
 * scaled to the sensor's pixels from the pilot's larger ones. Time per path (or gather ray, or
 * sample for photon-map) and per photon (the emission table once), times the run's counts, gives
 * the time; with a noise target the pilot's 95th percentile of the standard error, scaled as
 * 1/sqrt(paths or gather rays), gives the channel's passes. An estimate, not a promise.
 */
#ifndef THZ_RUN_RUN_ESTIMATE_H
#define THZ_RUN_RUN_ESTIMATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "scene/scene.h"

#define RUN_PILOT_SIDE 32u
#define RUN_PILOT_PHOTONS 20000u
/* photon-map's pilot towards a noise target: a pass's photons, at most this many */
#define RUN_PILOT_PHOTONS_PASSES 1000000u
/* paths (path) or gather rays (final-gather) a pilot's sample casts, at most: a 32 x 24
 * sensor's run of 30 000 paths a sample rendered 21 s after a pilot of 12 s at the run's
 * paths */
#define RUN_PILOT_ESTIMATES 64u

typedef struct run_estimate_input {
    const thz_scene *scene;
    const accel *accel;
    const size_t *selected; /* sensors rendered */
    size_t n_selected;
    double target_noise_k; /* 0: one pass */
    int threads;
    struct emission_reach *reach; /* the run's (photon_phase_options), or NULL */
} run_estimate_input;

/* The pilot's copy of sensor (*cam: at most RUN_PILOT_SIDE pixels a side, never more
 * than the sensor's; oversampling 1) and of the scene (*pilot: cam its one sensor, no
 * warnings; photons per channel, paths and gather rays per sample at most
 * RUN_PILOT_PHOTONS and RUN_PILOT_ESTIMATES, never more than the scene's, but paths and
 * gather rays at least 2, whose spread tells the noise): a pilot does no more work than
 * the run but for that. *pilot borrows the scene's objects and cam. */
void run_estimate_pilot(const thz_scene *scene, const thz_sensor *sensor, thz_scene *pilot,
                        thz_sensor *cam);

typedef struct run_estimate {
    double seconds_photons, seconds_render; /* the whole run's, s */
    uint32_t passes;                        /* the most a channel needs */
    /* photon-map with a noise target: the most one channel's photon passes hold, bytes
     * (0 without passes), and whether a channel's passes stop at the memory they may
     * hold (run_passes_memory_limit_bytes) before its target, their count then that */
    uint64_t passes_bytes;
    bool memory_stop;
} run_estimate;

/* The estimate of the run of in. */
thz_status run_estimate_time(const run_estimate_input *in, run_estimate *out, thz_error *err);

#endif
