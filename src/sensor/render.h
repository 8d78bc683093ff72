/* The rendering phase (physics.md "Rendering phase", eq. 11-13): for every pixel
 * sample of a sensor, the radiance reaching the pinhole in one channel, and from its
 * pixel mean the channel images L_c, P_c, Tb_c and N_c; plus the truth images.
 *
 * Integrators: the per-sample radiance is computed by the integrator the scene's
 * `render.integrator` names (an internal table of per-sample radiance functions, so
 * `final-gather` and `path` slot in beside `photon-map`). Only `photon-map` is
 * implemented; the others fail with THZ_ERR_INPUT.
 *
 * Band means: every photon term is evaluated at the photon's own frequency (its
 * reflectance or BTDF, the straight-shell path weight and the atmospheric
 * transmittance all at nu_p); the emission term is the deterministic band mean by the
 * channel's quadrature. So L_c estimates the band mean of L exp(-alpha d).
 *
 * Gather: the photons of the object hit (the paper's rule), on the side seen (and the
 * other side for `diffuse` shells), within the footprint disk, and, beyond the spec's
 * wording, only those whose incoming direction agrees with that side of the triangle
 * hit, so that the opposite face of a thin solid does not leak into a wide disk.
 * Open edges under-estimate and concave edges over-estimate (physics.md).
 *
 * Determinism: no random numbers; each pixel is computed by one thread into its own
 * slot, so the images are bit-identical for any thread count.
 */
#ifndef THZ_SENSOR_RENDER_H
#define THZ_SENSOR_RENDER_H

#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/photon_map.h"
#include "scene/scene.h"
#include "sensor/images.h"

/* A sample ray continues through at most this many `straight` shells; beyond, what
 * lies behind is dropped (counted in render_stats.truncated_paths). */
#define RENDER_MAX_CROSSINGS 32

typedef struct render_options {
    int threads;              /* OpenMP threads, 0: all */
    thz_progress_fn progress; /* stage "render": done/total = rows of this sensor; may be NULL */
    void *progress_user;
} render_options;

/* Counts of one render_sensor_channel call; add them up across calls. */
typedef struct render_stats {
    uint64_t samples;           /* sample rays cast */
    uint64_t escaped_samples;   /* rays that hit nothing (radiance 0) */
    uint64_t back_face_samples; /* rays that saw the back of a one-sided solid (radiance 0) */
    uint64_t widened_gathers;   /* footprints with < k photons, widened to the k-th nearest */
    uint64_t starved_gathers;   /* objects with < k photons where the gather looked: term 0 */
    uint64_t truncated_paths;   /* rays cut after RENDER_MAX_CROSSINGS straight shells */
    double seconds;             /* wall time (not reproducible) */
} render_stats;

/* The integrator's name as in the scene file ("photon-map", "final-gather", "path"). */
const char *render_integrator_name(thz_integrator integrator);

/* Parses an integrator name; false if unknown. */
bool render_integrator_parse(const char *name, thz_integrator *out);

/* THZ_OK if `integrator` is implemented; otherwise THZ_ERR_INPUT
 * "integrator 'X' is not implemented yet". Call before a run starts. */
thz_status render_integrator_check(thz_integrator integrator, thz_error *err);

/* Whether the integrator needs a photon map (all but `path`). */
bool render_integrator_needs_photons(thz_integrator integrator);

/* Renders channel `channel` of sensor `sensor` into `images` (initialised with
 * sensor_images_init for that sensor's resolution and the scene's channel count): the
 * channel's planes of radiance, power, brightness_temperature, normalized and, when
 * images->radiance_stderr is set, the standard error of L_c estimated from the
 * gathered photons (Poisson: sum of squared photon terms over A_g^2). `map` is the
 * photon map of that channel. `stats` (may be NULL) is overwritten.
 * THZ_ERR_CANCELLED if the progress callback asks to stop. */
thz_status render_sensor_channel(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, size_t sensor, sensor_images *images,
                                 const render_options *opt, render_stats *stats, thz_error *err);

/* Fills the truth images of `sensor` (temperature_k, distance_m, object_id, visual_rgb)
 * from the first hit of the ray through each pixel's centre: 0, 0, -1 and black where
 * it hits nothing; visual = material colour x (0.25 + 0.75 |cos theta|). */
thz_status render_sensor_truth(const thz_scene *scene, const accel *a, size_t sensor,
                               sensor_images *images, const render_options *opt, thz_error *err);

#endif
