/* Orchestration of a whole run, the library API behind `thzmap simulate` and
 * `thzmap render` (scene-format.md "Command line"):
 *
 *   simulate: check the integrator and memory (refusing before any work) -> build the
 *             ray-casting structure -> per channel: photon phase, render every sensor,
 *             keep the photon map only when it is to be saved.
 *   render:   from photon maps read before (io/photon_map_file.h) -> render the chosen
 *             sensors.
 *   write:    every output file of a finished run into a staging directory, which the
 *             caller commits into OUTDIR (io/output.h; run_output.c).
 *
 * With the `path` integrator simulate fires no photons. With a noise target
 * (run_target_noise_k), each channel gets passes 0, 1, 2, ... (each deterministic)
 * until the 95th percentile over its pixels of the standard error of Tb_c is at most
 * the target (K), or max_seconds have passed.
 *
 * A failed or cancelled run (progress callback returning non-zero: THZ_ERR_CANCELLED)
 * returns nothing; a failed or cancelled write leaves no result files in OUTDIR.
 * Results are bit-identical for any thread count.
 */
#ifndef THZ_RUN_RUN_H
#define THZ_RUN_RUN_H

#include <stdbool.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/emission_reach.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "photon/photon_stats.h"
#include "run/run_noise.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "sensor/render.h"

/* Overrides of scene settings (applied by run_apply_overrides to a copy of the scene). */
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
    bool memory_stop;          /* photon-map's passes stop at their memory before the target */
    double target_noise_k;     /* 0: none */
    const char *target_source; /* run_target_noise_k's *source */
} run_plan;

typedef struct run_options {
    int threads;             /* OpenMP threads, 0: all */
    bool keep_photon_maps;   /* simulate: keep every channel's map in the run (to save it) */
    const char *sensor_name; /* only this sensor; NULL: all */
    /* simulate: the processes sharing each photon phase (photon/phase.h); NULL: alone */
    const struct photon_phase_team *team;
    /* the processes sharing each render pass by pixel tiles (sensor/render_tiles.h);
       NULL: alone */
    const struct render_team *render_team;
    thz_progress_fn progress; /* stages "photons", "render", "output"; may be NULL */
    void *progress_user;
    thz_warning_fn warning; /* each run warning as it is added; may be NULL */
    void *warning_user;
    double seconds_load;   /* time the caller spent loading the scene, for the summary */
    double target_noise_k; /* > 0: add passes to each channel until the 95th percentile of
                              the per-pixel standard error of Tb_c, over the rendered
                              sensors, is at most this (K); overrides the scene's */
    double max_seconds;    /* > 0: stop adding passes once a channel has rendered this
                              long (s); makes the stopping point time-dependent;
                              overrides the scene's render.max_seconds */
    /* simulate: called once before the work starts with the estimate (its pilot costs
       a moment, so only when set); may be NULL */
    void (*plan)(void *user, const run_plan *plan);
    void *plan_user;
} run_options;

/* The photon maps a render run reads: one per channel (borrowed), their photon-phase
 * statistics, and the seed and photon count they were fired with. Or, with maps NULL,
 * next_map hands over each channel's map when the run comes to it (channels 0, 1, ...
 * in order; the run destroys it after rendering that channel), so that a render holds
 * one channel's map at a time (io/photon_map_file.h: photon_map_file_next);
 * next_map_bytes is the largest one's size, for the memory estimate. */
typedef struct run_photons {
    photon_map *const *maps;
    const photon_stats *stats;
    uint64_t seed;
    uint64_t photons_per_channel;
    thz_status (*next_map)(void *user, photon_map **map, thz_error *err);
    void *next_user;
    uint64_t next_map_bytes;
} run_photons;

/* What a finished run reports back (for the CLI's closing line). */
typedef struct run_result {
    size_t n_channels;
    size_t n_sensors;       /* sensors rendered */
    uint64_t photons_fired; /* over all channels (0 for render) */
    uint64_t photons_stored;
    uint64_t back_face_samples;   /* over all sensors and channels */
    size_t n_warnings;            /* run warnings written to summary.json */
    double worst_median_stderr_k; /* largest over channels of the median per-pixel standard
                                     error of Tb_c, K (0 if not estimated, INFINITY
                                     if unknown: run_noise) */
    double worst_p95_stderr_k;    /* the same for the 95th percentile, K */
    size_t worst_object;          /* object whose pixels' p95 is largest (over channels), or
                                     SIZE_MAX when no object was seen */
    size_t worst_object_channel;
    double worst_object_p95_stderr_k; /* K */
    uint32_t max_passes;              /* most render passes of any channel */
    double seconds;                   /* wall time of the run */
} run_result;

/* Everything one run owns, from its start to its written outputs; freed in one place
 * (run_state_fini). run_simulate and run_render fill it; run_write writes it. It must
 * not move while a run fills it (opt points into it). */
typedef struct run_state {
    const thz_scene *scene;    /* borrowed: the scene with the run's overrides */
    run_options options;       /* a copy of the caller's */
    const run_options *opt;    /* = &options */
    const char *command;       /* "simulate" or "render" */
    accel *accel;              /* during the run only */
    size_t n_selected;         /* sensors rendered */
    size_t *selected;          /* their indices into scene->sensors */
    sensor_images *images;     /* one per selected sensor */
    uint64_t *back_face;       /* per scene sensor: samples that saw a back face */
    render_stats *render_sum;  /* per selected sensor: counts over all channels */
    render_stats *last;        /* [channel * n_selected + i]: the channel's last render pass
                                  (every pass casts the same sample rays, so the counts are
                                  a channel's, not the number of passes') */
    photon_map **maps;         /* per channel: kept for saving (simulate) */
    photon_map_pool pool;      /* memory of the maps not kept, for the next channel's */
    emission_reach reach;      /* the back sides' reach shares of its deviation maps */
    photon_stats *stats;       /* per channel (simulate), or the read maps' (render) */
    run_noise *noise;          /* per channel */
    run_noise *object_noise;   /* [channel * n_objects + object] */
    double target_noise_k;     /* the run's target (run_target_noise_k), 0: none */
    const char *target_source; /* "command line", "scene", "default" or NULL */
    double max_seconds;        /* the command line's, else the scene's; 0: none */
    uint64_t memory_bytes;     /* estimated before the run (run_memory total) */
    uint32_t *passes;          /* per channel: render passes */
    double *seconds_channel;   /* per channel: render time, s */
    uint64_t seed;             /* of the photons rendered (scene's, or the map file's) */
    uint64_t photons_per_channel;
    size_t n_warnings;
    char **warnings;
    bool told_unestimated; /* run_write's warning that the standard errors read 0 */
    double seconds_accel, seconds_photons, seconds_render, seconds_output;
    run_result result; /* the totals, filled when the run succeeded */
} run_state;

/* THZ_ERR_INPUT unless the noise target and the time limit are positive (or 0: none).
 * Every integrator takes a target in simulate (photon-map by photon passes); render
 * refuses one for photon-map, which would need photons. */
thz_status run_check_options(const run_options *opt, thz_error *err);

/* The noise target where the user gives no count (photons.per_channel or --photons for
 * photon-map and final-gather, render.paths_per_sample for path) and no target, K. */
#define RUN_DEFAULT_TARGET_NOISE_K 0.1

/* Ward's alpha below which photon-map runs warn that it does not resolve the lobe (run.c):
 * a furnace's sphere read 0.77 of its radiance at alpha 0.05 with 50 000 photons, and
 * 0.50 at 0.001 with 1 M, each with a standard error of under 1 %; a plate of R 0.7
 * mirroring a small 400 K cube, against an independent quadrature, 4 M photons a
 * channel: pixels off by up to 79 standard errors at alpha 0.15 (chi2/n 224), 20 at 0.2
 * (15), 5 at 0.3 (2.1), 3.4 at 0.5 (1.0-1.4). */
#define RUN_WARD_ALPHA_PHOTON_MAP 0.3

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
    uint64_t image_bytes;         /* the images, their statistics, the renderer's tables */
    uint64_t held_bytes;          /* what the process holds already: the scene, its meshes'
                                   * ray-casting structure (thz_process_memory_bytes) */
    uint64_t total_bytes;         /* all three */
    uint64_t available_bytes;     /* thz_memory_limit_bytes, 0 if unknown */
    uint64_t map_photons;         /* photon_bytes are a map read (render), not fired: its
                                   * photons per channel; 0 when fired */
    uint64_t mapped_bytes;        /* the address space mapped already (thz_address_space_bytes),
                                   * and the stacks and arenas of the threads still to start */
    uint64_t address_limit_bytes; /* thz_address_space_limit_bytes, 0 if unlimited */
} run_memory;

/* THZ_OK, or THZ_ERR_LIMIT when `need` exceeds 90 % of the memory the process may have
 * (thz_memory_limit_bytes), or, under ulimit -v, its photon maps and images beside what
 * is mapped already exceed 90 % of the address-space limit, with a message naming
 * `photons.per_channel` (a map read: a map of fewer photons), `sensors[i].resolution` or
 * the scene's size; under ulimit -v also the limit, and the limit that would do. */
thz_status run_check_memory(const thz_scene *scene, const run_memory *need, thz_error *err);

/* The same for each sensor's images alone (what loading can tell without building
 * anything): THZ_ERR_LIMIT naming the scene file and sensors[i].resolution. */
thz_status run_check_scene_memory(const thz_scene *scene, thz_error *err);

/* Bytes the photon maps of channel `only` (SIZE_MAX: every channel) take while fired:
 * all of them and the largest's build scratch when keep_all, else the largest (with the
 * pool's spare quarter) and its scratch. reach as photon_phase_options (may be NULL). */
thz_status run_photon_map_bytes(const thz_scene *scene, const accel *acc, size_t only,
                                bool keep_all, emission_reach *reach, uint64_t *out,
                                thz_error *err);

/* Estimates the memory of the run in rs (what the process holds already, its selected
 * sensors' images and the renderer's tables, and, when `photons`, the photon maps it
 * fires, else the map_bytes of maps the run reads one at a time, of map_photons photons
 * per channel), stores it in
 * rs->memory_bytes and refuses the run as run_check_memory does. */
thz_status run_check_run_memory(run_state *rs, bool photons, uint64_t map_bytes,
                                uint64_t map_photons, thz_error *err);

/* Fire and render (simulate) or render from `in` (render; NULL only for path) into rs,
 * nothing written. On failure rs is finalised. */
/* What run_simulate checks before it fires a photon, alone: the ray-casting structure
 * built, the photons' memory estimated (a pilot per channel) and the run refused as
 * run_check_run_memory does; nothing kept. */
thz_status run_check_simulate(const thz_scene *scene, const run_options *opt, thz_error *err);

thz_status run_simulate(const thz_scene *scene, const run_options *opt, run_state *rs,
                        thz_error *err);
thz_status run_render(const thz_scene *scene, const run_options *opt, const run_photons *in,
                      run_state *rs, thz_error *err);

/* The photon map's files in an output directory (run_write_options.photon_map). */
#define RUN_PHOTON_MAP_FILE "photon-map.thzpm"
#define RUN_PHOTON_PLY_FILE "photon-map.ply"

/* What run_write adds to the files of every sensor and summary.json. */
typedef struct run_write_options {
    bool photon_map;          /* photon-map.thzpm and photon-map.ply (needs kept maps) */
    uint64_t ply_max_points;  /* photons in photon-map.ply at most; 0: PLY_DEFAULT_MAX_POINTS */
    thz_progress_fn progress; /* stage "output"; may be NULL */
    void *progress_user;
} run_write_options;

/* Writes every output file of a finished run into `dir` (a staging directory: see
 * io/output.h); THZ_ERR_CANCELLED when the progress callback asks. Records the time
 * it took in rs->seconds_output. */
thz_status run_write(run_state *rs, const char *dir, const run_write_options *wo, thz_error *err);

/* summary.json's text for a finished run (malloc'd; NULL and err set on failure). */
char *run_summary_text(const run_state *rs, thz_error *err);

void run_state_fini(run_state *rs);

/* T0 of channel c's photon map as simulate fires it (photon_map.h): final-gather's
 * deviation map takes the renderer's reference temperature, photon-map 0. */
double run_photon_t0_k(const thz_scene *scene, size_t c);

/* ---- Internal to src/run/ ---- */

/* Adds a run warning (summary.json "warnings", and run_options.warning). */
thz_status run_add_warning(run_state *rs, thz_error *err, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Renders channel c of every selected sensor from map (NULL for path): one pass, or,
 * with a noise target and an integrator with passes, passes until the 95th percentile
 * of the channel's standard error reaches it, the time limit passes, or final-gather's
 * photon map alone keeps it above (run_passes.c). */
thz_status run_render_channel(run_state *rs, size_t c, const photon_map *map, thz_error *err);

/* photon_phase_prepare for the deviation maps (T0 > 0, run_photon_t0_k) of channel `only`
 * of scene (SIZE_MAX: every channel), before the estimates' pilots need po->reach;
 * nothing where none fires one (run.c). */
thz_status run_prepare_reach(const thz_scene *scene, const accel *acc, size_t only,
                             const photon_phase_options *po, thz_error *err);

/* photon-map with a noise target: photon passes, rendered at checks from the merge of all
 * so far, until the target, the time limit or half the memory; *out_map the merged map
 * (run_passes.c). */
thz_status run_photon_passes(run_state *rs, size_t c, photon_map **out_map, thz_error *err);

/* The next check after one at pass n whose noise asks for `need` passes in all: at most
 * a quarter more than n, at least n + 1 (run_photon_passes). */
uint32_t run_photon_next_check(uint32_t n, double need);

/* The memory the photon passes of one channel may hold, bytes (half of what the process
 * may have, thz_memory_limit_bytes: the machine's, or less under ulimit -v or a cgroup
 * limit; 0 if unknown), and what they hold per pass: the passes' maps and a merge of
 * them, twice the records, their indexes and the merge's index scratch (3/8 of its
 * records):
 * RUN_PASSES_MAP_FACTOR x one pass's map. 2.2 left the scratch out: the walkthrough's
 * room, stopped at 202 passes of 28 MB maps, peaked at 13.4 GB against a limit of
 * 12.6 GB (11.75 GiB). */
double run_passes_memory_limit_bytes(void);
#define RUN_PASSES_MAP_FACTOR 2.45

/* How many checks run_photon_passes renders before `passes` passes if every check asks
 * for more than a quarter more (the most; the time estimate's count of renders). */
uint32_t run_photon_checks(uint32_t passes);

/* The passes those checks merge, summed over the checks after the first (each merges
 * every pass so far): the time estimate's count of merged photons, in passes. */
double run_photon_merged_passes(uint32_t passes);

#endif
