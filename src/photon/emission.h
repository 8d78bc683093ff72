/* Emission sampling of the photon phase (physics.md "Photon phase", eq. 5-6).
 *
 * Scheme (unbiased for the band mean, as physics.md allows): a photon's frequency nu is
 * drawn from the channel response g_c alone; at that nu its source object is chosen
 * with probability proportional to pi eps-bar(nu) A B_nu(T) times the number of
 * emitting sides (recomputed per photon, exactly, at the photon's own frequency: no
 * tabulation in frequency, so narrow material lines are integrated; one Planck
 * evaluation per group of sources, see emission_group); then one of its emitting sides
 * uniformly, a triangle by an area CDF
 * (binary search), a point uniformly on the triangle, and a direction with
 * mu ~ eps(mu) mu about the emitting side's normal and uniform azimuth. The photon
 * carries Phi(nu) = P_A(nu) / K, so the mean of Phi over photons is the band mean
 * P-bar_A / K and every band-mean estimate built from the photons is unbiased.
 *
 * Emitting sides: both sides of shells and two-sided solids, the front side of one-sided
 * solids; objects at 0 K (or without area) emit nothing.
 */
#ifndef THZ_PHOTON_EMISSION_H
#define THZ_PHOTON_EMISSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/rng.h"
#include "core/vec3.h"
#include "scene/scene.h"

/* One emitting object. */
typedef struct emission_source {
    uint32_t object;         /* index into scene->objects */
    int sides;               /* 1 or 2 emitting sides */
    double area_m2;          /* total area of one side */
    bool constant_optics;    /* R, alpha_M and eps do not depend on frequency */
    double weight;           /* constant optics: pi eps-bar A sides (times B_nu(T) = power) */
    double *triangle_cdf;    /* n_triangles cumulative areas, last = total */
} emission_source;

/* Sources sharing a temperature and constant optics form one group, so that a photon
 * costs one Planck evaluation per group, not per object: the group is drawn by its
 * power at the photon's frequency, the source within it by its frequency-independent
 * weight (CDF over the group's sources). A source whose optics vary with frequency is
 * a group of its own, its eps-bar evaluated at each photon's frequency. */
typedef struct emission_group {
    double temperature_k;
    size_t first, count; /* range of emission_table.order */
    double weight;       /* sum of the sources' weights (constant optics) */
    double *cdf;         /* count cumulative weights (count > 1) */
} emission_group;

/* Sampling tables of one channel. Read-only after init: shared by all threads. */
typedef struct emission_table {
    const thz_scene *scene;
    size_t channel;
    uint64_t n_photons; /* K: each photon carries P_A(nu) / K */
    size_t n_sources;
    emission_source *sources;
    size_t n_groups;
    emission_group *groups;
    size_t *order; /* source indices, grouped */
} emission_table;

/* A photon as emitted. */
typedef struct emission_photon {
    double freq_hz;
    double power_w_per_hz; /* Phi(nu) = P_A(nu) / K; 0 when nothing emits at nu */
    vec3 position_m;       /* on the triangle */
    vec3 dir;              /* unit, into the emitting side's hemisphere */
    uint32_t object;
    uint32_t triangle;
    int side;              /* 0 front, 1 back */
} emission_photon;

thz_status emission_table_init(emission_table *t, const thz_scene *scene, size_t channel,
                               uint64_t n_photons, thz_error *err);
void emission_table_fini(emission_table *t);

/* P_A(freq_hz) over the table's sources, writing each group's power
 * pi eps-bar A sides B_nu(T) into weights[0..n_groups-1] (caller's scratch). */
double emission_group_weights(const emission_table *t, double freq_hz, double *weights);

/* Draws one photon from rng. `scratch` holds n_sources doubles (>= n_groups; per thread,
 * nothing is allocated here). Returns false when P_A(nu) = 0 at the drawn frequency: the
 * photon then has power 0 and nothing else is set. */
bool emission_sample(const emission_table *t, rng_stream *rng, double *scratch,
                     emission_photon *out);

/* A unit direction about unit normal n with cos(theta) = mu and azimuth 2 pi u. */
vec3 emission_direction(vec3 n, double mu, double u);

/* Adapter: rng_uniform as an optics_uniform_fn (ctx is the rng_stream). */
double emission_uniform(void *rng);

#endif
