/* The integrators' interface (physics.md "Integrators", docs/integrators.md): each
 * integrator is one file (integrator_*.c) with one function, the estimates of the
 * radiance along one sample ray, and one row of the table in integrators.c. The pixel
 * loop, sample placement, statistics and truth maps are render.c's, render_accum.c's and
 * truth.c's; the band terms render_terms.c's.
 */
#ifndef THZ_SENSOR_INTEGRATOR_H
#define THZ_SENSOR_INTEGRATOR_H

#include <stdbool.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/sampling.h"
#include "photon/photon_map.h"
#include "sensor/render_terms.h"

/* Counters and the photon-map variance of one sample. */
typedef struct render_sample {
    double variance; /* photon-map: estimated variance of its radiance (Poisson) */
    /* photon-map: the bound of perfect correlation on the covariances of its density
     * estimates (2 sum_{i<j} sd_i sd_j; 0 for one), and the sum of their standard errors:
     * one photon is recorded on a straight shell and again behind it */
    double covariance_bound, sd_sum;
    double batch[PHOTON_MAP_BATCHES]; /* the photon terms of each batch (in the radiance) */
    unsigned escaped, back_face, widened, starved, truncated;
    uint32_t back_object; /* with back_face: the object whose back it saw */
    uint64_t paths;
} render_sample;

/* The set of estimate j's strata (render_stratum), kept while the thread renders the
 * set's samples, which draw it from the same stream: key is the set's stream index. */
typedef struct render_strata {
    uint64_t key;
    sampling_set set;
} render_strata;
#define RENDER_STRATA_NONE UINT64_MAX

/* Where a sample's estimates go: est[j] += weight x (estimate j), j < n_est. */
typedef struct render_target {
    double *est;
    uint32_t n_est;
    double *batch;      /* final-gather with batches: += weight x each batch's photon terms */
    double *disk_var;   /* and += weight^2 x their disks' Poisson variance; else NULL */
    double weight;      /* 1 / n^2 */
    uint64_t rng_index; /* first index of this sample's random streams (x n_est) */
    uint32_t stratum, n_strata; /* the sample's place among its pixel's n_strata samples */
    render_strata *strata;      /* n_est sets of the thread's own (crossings 0), or NULL */
} render_target;

/* An integrator: the estimates of one sample ray. `sample_sr` is the sample's solid
 * angle Omega_S / n^2. */
typedef void (*render_sample_fn)(const render_context *ctx, vec3 origin_m, vec3 dir,
                                 double sample_sr, const render_target *t, render_sample *out);

static inline void render_add_all(const render_target *t, double v)
{
    for (uint32_t j = 0; j < t->n_est; j++)
        t->est[j] += t->weight * v;
}

/* The stratum of estimate j's first scattered direction (final-gather's gather ray, path's
 * first bounce) at the vertex after `crossings` straight shells: the j-th ones of a pixel's
 * samples, in sets of up to SAMPLING_STRATA_MAX, are stratified together, from the set's
 * own stream (RNG_PURPOSE_GATHER_STRATA; a fresh set for every j, so that the estimates
 * stay independent). False where the sample's set has one member. */
bool render_stratum(const render_context *ctx, const render_target *t, uint32_t j,
                    uint32_t crossings, sampling_stratum *out);

typedef struct render_integrator {
    thz_integrator id; /* its name: scene_integrator_names[id] */
    render_sample_fn sample;
    bool needs_photons;
    uint32_t purpose; /* RNG purpose; 0: no random numbers (one pass) */
} render_integrator;

/* The table's row of integrator `id`, or NULL. */
const render_integrator *render_integrator_find(thz_integrator id);

void render_photon_map_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
                              const render_target *t, render_sample *out);
void render_final_gather_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                double sample_sr, const render_target *t, render_sample *out);
void render_path_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
                        const render_target *t, render_sample *out);

/* The photon-map radiance along a ray (integrator_photon_map.c), also final-gather's
 * gather rays: `path` and `distance_m` carry what lies between the sensor and origin_m,
 * `scatter` (may be NULL) the first vertex's weight. */
double render_photon_map_trace(const render_context *ctx, vec3 origin_m, vec3 dir,
                               uint32_t ignore_object, uint32_t ignore_triangle, render_path path,
                               double distance_m, const render_scatter *scatter, double sample_sr,
                               render_sample *out);

/* A `straight` shell that is also a mirror splits a ray in two; beyond this many
 * entries of the path the mirror branch is dropped (counted in truncated_paths). */
#define RENDER_MIRROR_BRANCHES 8

/* At a hit of a mirror (`specular` reflection, R > 0 somewhere): appends the bounce
 * (R(theta)) to path, turns *dir into the mirrored direction and *origin_m into its start,
 * and returns true; false for other surfaces (and when the path is full: counted as
 * truncated). */
bool render_mirror(const render_context *ctx, const accel_hit *hit, render_path *path, vec3 *dir,
                   vec3 *origin_m, render_sample *out);

/* The density estimate at a hit (gather.c): adds L_R (+ L_T for diffuse shells) to
 * *radiance and its Poisson variance and batch terms to *out. */
void render_gather(const render_context *ctx, const accel_hit *hit, vec3 ray_dir,
                   const render_path *path, const render_scatter *scatter, double distance_m,
                   double sample_sr, bool diffuse_shell, double *radiance, render_sample *out);

#endif
