/* Orchestration of a whole run, the library API behind `thzmap simulate` and
 * `thzmap render` (scene-format.md "Command line"):
 *
 *   simulate: check the integrator and memory (refusing before any work) -> build the
 *             ray-casting structure -> per channel: photon phase, render every sensor,
 *             keep the photon map only when it is to be saved -> write every output
 *             file into a staging directory -> move them into OUTDIR.
 *   render:   read a saved photon map (refusing one made from another scene) -> render
 *             the chosen sensors -> outputs as above.
 *
 * With the `path` integrator simulate fires no photons. With a noise target
 * (run_target_noise_k), each channel gets passes 0, 1, 2, ... (each deterministic)
 * until the 95th percentile over its pixels of the standard error of Tb_c is at most
 * the target (K), or max_seconds have passed.
 *
 * A failed or cancelled run (progress callback returning non-zero: THZ_ERR_CANCELLED)
 * leaves no result files in OUTDIR. Results are bit-identical for any thread count.
 */
#ifndef THZ_RUN_RUN_H
#define THZ_RUN_RUN_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "scene/scene.h"

/* Command-line overrides of scene settings (applied by run_apply_overrides). */
typedef struct run_overrides {
    uint64_t photons; /* photons.per_channel; 0 keeps the scene's */
    bool has_seed;
    uint64_t seed; /* photons.seed */
    bool has_integrator;
    thz_integrator integrator; /* render.integrator */
} run_overrides;

/* What a simulate run is about to do, told before it starts (run_estimate.h). */
typedef struct run_plan {
    double seconds_photons, seconds_render; /* estimated, s */
    uint32_t passes;                        /* estimated passes per channel */
    uint64_t memory_bytes;                  /* estimated peak, bytes */
    uint64_t available_bytes;               /* physical memory, 0 if unknown */
    double target_noise_k;                  /* 0: none */
    const char *target_source;              /* run_target_noise_k's *source */
} run_plan;

typedef struct run_options {
    const char *outdir;          /* required: where the result files go */
    int threads;                 /* OpenMP threads, 0: all */
    bool save_photon_map;        /* simulate: also write photon-map.thzpm and photon-map.ply */
    uint64_t ply_max_points;     /* photons in photon-map.ply at most; 0: PLY_DEFAULT_MAX_POINTS */
    const char *photon_map_path; /* render: the photon-map file to read (required) */
    const char *sensor_name;     /* render: only this sensor; NULL: all */
    thz_progress_fn progress;    /* stages "photons", "render", "output"; may be NULL */
    void *progress_user;
    /* called with each run warning as it arises (also written to summary.json), from the
       calling thread; may be NULL */
    void (*warning)(void *user, const char *message);
    void *warning_user;
    /* simulate: called once before the work starts with the estimate (its pilot costs
       a moment, so only when set); user: warning_user */
    void (*plan)(void *user, const run_plan *plan);
    double seconds_load;   /* time the caller spent loading the scene, for the summary */
    double target_noise_k; /* > 0: add passes to each channel until the 95th percentile of
                              the per-pixel standard error of Tb_c, over the rendered
                              sensors, is at most this (K); overrides the scene's */
    double max_seconds;    /* > 0: stop adding passes once a channel has rendered this
                              long (s); makes the stopping point time-dependent;
                              overrides the scene's render.max_seconds */
} run_options;

/* What a finished run reports back (for the CLI's closing line). */
typedef struct run_result {
    size_t n_channels;
    size_t n_sensors;       /* sensors rendered */
    uint64_t photons_fired; /* over all channels (0 for render) */
    uint64_t photons_stored;
    uint64_t back_face_samples;   /* over all sensors and channels */
    size_t n_warnings;            /* run warnings written to summary.json */
    double worst_median_stderr_k; /* largest over channels of the median per-pixel standard
                                     error of Tb_c, K (0 if not estimated) */
    double worst_p95_stderr_k;    /* the same for the 95th percentile, K */
    size_t worst_object;          /* object whose pixels' p95 is largest (over channels), or
                                     SIZE_MAX when no object was seen */
    size_t worst_object_channel;
    double worst_object_p95_stderr_k; /* K */
    uint32_t max_passes;              /* most render passes of any channel */
    double seconds;                   /* wall time of the run */
} run_result;

/* THZ_ERR_INPUT unless the noise target and the time limit are positive (or 0: none).
 * Every integrator takes a target in simulate (photon-map by photon passes); render
 * refuses one for photon-map, which would need photons. */
thz_status run_check_options(const run_options *opt, thz_error *err);

/* The noise target where the user gives no count (photons.per_channel or --photons for
 * photon-map and final-gather, render.paths_per_sample for path) and no target, K. */
#define RUN_DEFAULT_TARGET_NOISE_K 0.1

/* The run's noise target in K (0: none, one pass): the command line's, else the
 * scene's render.target_noise_k, else the default when no count is given. render
 * with photon-map has none but the command line's (which it refuses). *source (may be
 * NULL) gets "command line", "scene", "default" or NULL. */
double run_target_noise_k(const thz_scene *scene, const run_options *opt, bool render,
                          const char **source);

/* Applies the overrides to the scene (before run_simulate / run_render). */
void run_apply_overrides(thz_scene *scene, const run_overrides *ov);

/* Bytes of memory a run needs, as estimated before it starts: the photon maps held at
 * once (all channels when saving, else the largest) plus a transient copy while one is
 * built, and every rendered sensor's images. Also names the setting to lower: the
 * scene key of the larger part. */
typedef struct run_memory {
    uint64_t photon_bytes;
    uint64_t image_bytes;
    uint64_t total_bytes;
    uint64_t available_bytes; /* physical memory, 0 if unknown */
} run_memory;

/* THZ_OK, or THZ_ERR_LIMIT when `need` exceeds 90 % of the machine's memory, with a
 * message naming `photons.per_channel` or `sensors[i].resolution`. */
thz_status run_check_memory(const thz_scene *scene, const run_memory *need, thz_error *err);

/* The same for the images of every sensor alone (what `validate` can tell without
 * building anything); the message starts with the scene file. */
thz_status run_check_scene_memory(const thz_scene *scene, thz_error *err);

thz_status run_simulate(const thz_scene *scene, const run_options *opt, run_result *result,
                        thz_error *err);
thz_status run_render(const thz_scene *scene, const run_options *opt, run_result *result,
                      thz_error *err);

#endif
