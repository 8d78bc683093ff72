/* The rendering phase (physics.md "Rendering phase", eq. 11-13, and "Integrators"): for
 * every pixel sample of a sensor, the radiance reaching the pinhole in one channel, and
 * from its pixel mean the channel images L_c, P_c, Tb_c and N_c; plus the truth images.
 *
 * Integrators (the table in integrators.c, one file each; docs/integrators.md):
 *   photon-map:   the paper's density estimate over the sample's footprint; deterministic
 *                 given the photon map; one pass.
 *   final-gather: at the first non-straight hit, `gather_rays` secondary rays (cosine for
 *                 reflection, by the BTDF T(theta) cos(theta) for diffuse shells) each
 *                 adding L_e + L_R + L_T from the photon map at its own hit, with the
 *                 k-nearest-photon radius there (k = max(gather_min_photons,
 *                 RENDER_SECONDARY_K)); from a deviation map (photon_map.h) the terms are
 *                 those of L - B(T0) and the sample adds B(T0).
 *   path:         backward Monte Carlo without a photon map, `paths_per_sample` paths per
 *                 sample, frequency drawn from g_c per path; written as the transport of
 *                 L - B_nu(T0) (T0: a reference temperature of the scene) so that every
 *                 path of an isothermal enclosure at T0 returns exactly the band mean of
 *                 B(T0); unbiased for any scene (see integrator_path.c).
 *
 * Passes and the noise estimate: a pass gives every pixel J independent, identically
 * distributed estimates (J = paths_per_sample or gather_rays; estimate j is the mean over
 * the pixel's n x n samples of their j-th path or gather ray). A render_accum merges the
 * passes per pixel (mean and sum of squared deviations); the standard error of the pixel
 * mean is sqrt(sample variance / N). Pass p draws its random numbers from
 * rng_init(seed, channel, RNG_PURPOSE_PATH or _GATHER, index) with index the fold of
 * (pass, sensor, sample, j), so any pass is bit-identical for any thread count.
 * photon-map has one pass and keeps the Poisson estimate: sum of squared photon terms over
 * A_g^2 (the photon map's own noise, which the renderer cannot resample).
 *
 * Band means: photon terms are evaluated at the photon's own frequency; the emission of
 * photon-map (and of final-gather's first hit) is the deterministic band mean by the
 * channel's quadrature; path and final-gather's secondary emission sample nu from g_c.
 *
 * Gather (photon-map): the photons of the object hit (the paper's rule), on the side seen
 * (and the other side for `diffuse` shells), within the footprint disk, and, beyond the
 * spec's wording, only those whose incoming direction agrees with that side of the
 * triangle hit, so that the opposite face of a thin solid does not leak into a wide disk.
 * Open edges under-estimate and concave edges over-estimate (physics.md).
 *
 * Determinism: each pixel is computed by one thread into its own slot, and its random
 * numbers depend only on the indices above: bit-identical for any thread count.
 */
#ifndef THZ_SENSOR_RENDER_H
#define THZ_SENSOR_RENDER_H

#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/photon_map.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "sensor/render_accum.h"

/* A sample ray continues through at most this many `straight` shells and mirror
 * reflections in a row; beyond, what lies behind is dropped (counted in
 * render_stats.truncated_paths). */
#define RENDER_MAX_CROSSINGS 32

/* final-gather's density estimate at a secondary hit uses the disk of the k-th nearest
 * photon with k = max(gather_min_photons, RENDER_SECONDARY_K): a gather ray's noise is
 * R/sqrt(k - 1) of the radiance there, so a larger k trades blur for fewer rays. The
 * lookups' cost grows with k (they wait on memory for every record they read), faster
 * than the rays k saves: on the paper's scene (0.2 THz, 8 M photons, time to an objects'
 * RMS of 0.05 K) k = 32 renders in 0.74 x the time of k = 64, k = 24 in 0.65 x, at a
 * map floor of 0.026 and 0.028 K against 0.023 K (docs/integrators.md). */
#ifndef RENDER_SECONDARY_K
#define RENDER_SECONDARY_K 32
#endif

/* final-gather: a gather ray ending on an object whose R + T (its largest hemispherical
 * mean over the channel, or its reflectivity's largest value) is s looks up the photons
 * there with probability min(1, s / RENDER_GATHER_LOOKUP_FULL), the estimate weighted by
 * the inverse (Russian roulette, unbiased); from a map of L always. A wall of R = 0.1
 * reflects little of the deviation that reaches it, so its lookup, the dearest part of a
 * gather ray, is worth little of the noise: on the paper's scene (0.2 THz, 32 gather
 * rays, 1 M photons) 0.5 took the render from 4.08 to 2.27 s at an objects' RMS of 0.0762
 * against 0.0758 K; 0.3 gave 2.42 s and 0.0759 K, 1 gave 1.41 s and 0.0888 K. From a map
 * of L a wall's photon term is R B(T), no small part of what a gather ray brings. */
#define RENDER_GATHER_LOOKUP_FULL 0.5

/* A `path` is cut after this many hits (counted in truncated_paths; the radiance beyond
 * is taken as B(T0), the control variate's value). */
#define RENDER_MAX_BOUNCES 10000

typedef struct render_options {
    int threads;   /* OpenMP threads, 0: all */
    bool use_seed; /* seed the random streams with `seed`, not photons.seed (render
                      from a saved map uses the map's seed) */
    uint64_t seed;
    thz_progress_fn progress; /* stage "render": done/total = rows of this sensor; may be NULL */
    void *progress_user;
    /* path: use T0 = path_t0_k (K, >= 0) instead of scene_reference_temperature_k. Any T0
     * gives the same expected image (only the noise changes); the identity tests use it
     * so that reflected and transmitted terms do not vanish against B(T0). */
    bool path_t0_set;
    double path_t0_k;
    /* final-gather: cosine gather rays only, without the photon guide (guide.h); for the
     * tests and measurements that compare the two */
    bool unguided;
    /* pixel tiles shared by processes (render_tiles.h): render only member's tiles of
     * `members`; members 0 or 1: every pixel */
    size_t member, members;
} render_options;

/* Cancelling inside a parallel pixel loop, so that a run stops within a second however
 * long a row takes: each thread calls render_poll_stop for each pixel; on thread 0 (the
 * caller's, where the callback may run) it calls the progress callback, at most every
 * RENDER_POLL_S, reporting `done` of `total` rows (with `columns` set, the rows' worth of
 * pixels counted by render_poll_pixel_done); once that asks to stop, it returns true on
 * every thread, which then skip their pixels. */
#define RENDER_POLL_S 0.1

typedef struct render_poll {
    const render_options *opt;
    const thz_scene *scene;
    size_t channel;
    uint64_t done, total;
    uint64_t columns; /* pixels per row, or 0: `done` alone */
    double next_s;    /* thread 0 only */
    uint64_t calls;   /* thread 0 only */
    /* read by every thread for every pixel: on a cache line of its own, apart from
     * what thread 0 writes (calls) */
    _Alignas(64) _Atomic int stop;
    _Alignas(64) _Atomic uint64_t pixels; /* pixels done, written by every thread */
} render_poll;

bool render_poll_stop(render_poll *poll);
void render_poll_pixel_done(render_poll *poll);

/* Counts of one render_sensor_channel call; add them up across calls. */
typedef struct render_stats {
    uint64_t samples;           /* sample rays cast (per pass) */
    uint64_t escaped_samples;   /* rays that hit nothing (radiance 0) */
    uint64_t back_face_samples; /* rays that saw the back of a one-sided solid (radiance 0) */
    /* the lowest and the highest index of the objects whose back those rays saw (the
     * warning names them; 0 and 0 while back_face_samples is 0) */
    uint64_t back_face_object_lo, back_face_object_hi;
    uint64_t widened_gathers; /* footprints with < k photons, widened to the k-th nearest */
    uint64_t starved_gathers; /* objects with < k photons where the gather looked: term 0 */
    uint64_t truncated_paths; /* rays cut after RENDER_MAX_CROSSINGS straight shells and
                                 mirror reflections, or paths after RENDER_MAX_BOUNCES hits */
    uint64_t paths;           /* path: paths traced; final-gather: gather rays cast */
    double seconds;           /* wall time (not reproducible) */
} render_stats;

/* The integrator's name as in the scene file ("photon-map", "final-gather", "path"). */
const char *render_integrator_name(thz_integrator integrator);

/* Parses an integrator name; false if unknown. */
bool render_integrator_parse(const char *name, thz_integrator *out);

/* THZ_OK if `integrator` is implemented; otherwise THZ_ERR_INPUT. Call before a run. */
thz_status render_integrator_check(thz_integrator integrator, thz_error *err);

/* Whether the integrator needs a photon map (all but `path`). */
bool render_integrator_needs_photons(thz_integrator integrator);

/* Whether more passes lower the noise (final-gather, path; not photon-map). */
bool render_integrator_has_passes(thz_integrator integrator);

/* Independent estimates a pass gives each pixel: paths_per_sample, gather_rays, or 1. */
uint32_t render_estimates_per_pass(const thz_scene *scene);

/* The per-channel state of the renderer (render_context.h): tables that depend only on
 * the scene, the channel, the photon map and opt's seed and path T0, built once per
 * channel and shared by its passes and sensors (read-only: any thread). */
typedef struct render_context render_context;

/* Builds channel `channel`'s state for the scene's integrator; `map` (borrowed, must
 * outlive it) is the channel's photon map, NULL for path. The scene and accel are
 * borrowed too. Only opt's use_seed, seed and path T0 are read. */
thz_status render_context_create(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, const render_options *opt, render_context **out,
                                 thz_error *err);

/* NULL does nothing. */
void render_context_destroy(render_context *ctx);

/* The bytes a channel's context takes, for the run's memory estimate: its tables per
 * object and quadrature node (74 KB an object: 20 000 boxes took 1.4 GiB that the
 * estimate left out) and final-gather's table per pair of objects. */
uint64_t render_context_bytes(const thz_scene *scene);

/* Renders pass `pass` of the context's channel for sensor `sensor` and merges it into
 * `acc` (initialised for that sensor's pixel count; pass 0 first, then 1, 2, ... in
 * order). photon-map refuses pass > 0 (THZ_ERR_INPUT). `stats` (may be NULL) is
 * overwritten with this pass's counts. Only opt's threads and progress are read.
 * THZ_ERR_CANCELLED if the progress callback asks to stop. */
thz_status render_context_pass(const render_context *ctx, size_t sensor, uint32_t pass,
                               render_accum *acc, const render_options *opt, render_stats *stats,
                               thz_error *err);

/* render_context_pass with a context built for this call alone (render_context_create
 * with map, channel and opt). */
thz_status render_sensor_channel_pass(const thz_scene *scene, const accel *a, const photon_map *map,
                                      size_t channel, size_t sensor, uint32_t pass,
                                      render_accum *acc, const render_options *opt,
                                      render_stats *stats, thz_error *err);

/* One pass into `images` (initialised with sensor_images_init for that sensor's
 * resolution and the scene's channel count): render_sensor_channel_pass with pass 0 and
 * render_accum_write. */
thz_status render_sensor_channel(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, size_t sensor, sensor_images *images,
                                 const render_options *opt, render_stats *stats, thz_error *err);

#endif
