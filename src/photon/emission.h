/* Emission sampling of the photon phase (physics.md "Photon phase", eq. 5-6).
 *
 * Scheme (unbiased for the band mean, as physics.md allows): a photon's frequency nu is
 * drawn from the channel response g_c alone. At that nu the sources are grouped (see
 * emission_group) and each group g has the exact power w_g(nu) = pi eps-bar_g(nu) A_g
 * B_nu(T_g) (times its sides). Evaluating every w_g at every photon's frequency costs
 * an optics evaluation per group (an exponential integral for shells) and was most of
 * the photon phase's time, so the group is drawn instead from a tabulation q_g(nu) of
 * the same weights (linear interpolation on a fine grid over the band, floored so that
 * q_g > 0 wherever w_g may be), and the photon carries
 *     Phi = w_g(nu) Q(nu) / (q_g(nu) K),   Q = sum_g q_g,
 * with w_g evaluated exactly, at the photon's own frequency, for the drawn group only.
 * Then E[Phi | nu] = sum_g w_g(nu) / K = P_A(nu) / K exactly: the tabulation changes
 * only how evenly the power is spread over photons (w / q differs from 1 by the
 * interpolation error, ~1e-7 for smooth optics), never the mean; narrow material lines
 * are still integrated, since w_g is exact. Within the group a source is drawn by its
 * frequency-independent share, one of its emitting sides uniformly, a triangle by an
 * area CDF (binary search), a point uniformly on the triangle, and a direction with
 * mu ~ eps(mu) mu about the emitting side's normal and uniform azimuth.
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
    uint32_t object;      /* index into scene->objects */
    int sides;            /* 1 or 2 emitting sides */
    double area_m2;       /* total area of one side */
    bool constant_optics; /* R, alpha_M and eps do not depend on frequency */
    double weight;        /* constant optics: pi eps-bar A sides (times B_nu(T) = power) */
    double share;         /* weight within its group: `weight` (constant optics) or
                             A sides (variable optics, eps-bar shared by the group) */
    optics_point optics;  /* constant optics: the optics at every frequency */
    double *triangle_cdf; /* n_triangles cumulative areas, last = total */
} emission_source;

/* Sources whose power differs only by a frequency-independent factor form one group, so
 * that a photon needs the exact power of one group only: sources with constant optics
 * and the same temperature, or sources with frequency-dependent optics that share the
 * material, type, thickness, sidedness and temperature (so eps-bar(nu) is the same).
 * The source within the group is drawn by its share (CDF over the group's sources). */
typedef struct emission_group {
    double temperature_k;
    size_t first, count; /* range of emission_table.order */
    bool constant_optics;
    double weight; /* constant: sum of weights; variable: pi sum of A sides */
    double *cdf;   /* count cumulative shares (count > 1) */
} emission_group;

/* Nodes of the tabulated group weights q_g over the band: centre +- 9 sigma (Box-Muller
 * never goes beyond 8.6 sigma), 0.07 sigma apart. */
#define EMISSION_TABLE_NODES 257
#define EMISSION_TABLE_SIGMAS 9.0

/* Sampling tables of one channel. Read-only after init: shared by all threads. */
typedef struct emission_table {
    const thz_scene *scene;
    size_t channel;
    uint64_t n_photons; /* K: each photon carries P_A(nu) / K on average */
    size_t n_sources;
    emission_source *sources;
    size_t n_groups;
    emission_group *groups;
    size_t *order;          /* source indices, grouped */
    double nu0_hz, step_hz; /* node i at nu0 + i step */
    double *cum_q;          /* [node * n_groups + g]: sum of q_g' over g' <= g */
} emission_table;

/* A photon as emitted. */
typedef struct emission_photon {
    double freq_hz;
    double power_w_per_hz; /* Phi(nu) = P_A(nu) / K; 0 when nothing emits at nu */
    vec3 position_m;       /* on the triangle */
    vec3 dir;              /* unit, into the emitting side's hemisphere */
    uint32_t object;
    uint32_t triangle;
    int side; /* 0 front, 1 back */
} emission_photon;

thz_status emission_table_init(emission_table *t, const thz_scene *scene, size_t channel,
                               uint64_t n_photons, thz_error *err);
void emission_table_fini(emission_table *t);

/* P_A(freq_hz) over the table's sources, writing each group's exact power
 * pi eps-bar A sides B_nu(T) into weights[0..n_groups-1] (caller's scratch). */
double emission_group_weights(const emission_table *t, double freq_hz, double *weights);

/* Exact power w_g(freq_hz) of group g (W/Hz). */
double emission_group_power(const emission_table *t, size_t g, double freq_hz);

/* Draws one photon from rng. `scratch` is unused (kept for callers that size it as
 * n_sources doubles); nothing is allocated here. Returns false when the drawn group has
 * no power at the drawn frequency: the photon then has power 0 and nothing else is
 * set. */
bool emission_sample(const emission_table *t, rng_stream *rng, double *scratch,
                     emission_photon *out);

/* A unit direction about unit normal n with cos(theta) = mu and azimuth 2 pi u. */
vec3 emission_direction(vec3 n, double mu, double u);

/* Adapter: rng_uniform as an optics_uniform_fn (ctx is the rng_stream). */
double emission_uniform(void *rng);

#endif
