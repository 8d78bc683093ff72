/* Emission sampling of the photon phase (physics.md "Photon phase", eq. 5-6).
 *
 * Sources. With reference temperature T0 = 0 (the paper's map of L) each object emits
 * eps(mu) B_nu(T) per unit projected area, mu ~ eps(mu) mu. With T0 > 0 the table fires
 * the map of the deviation L - B0, B0 = B_nu(T0) (photon_map.h "Reference temperature"):
 * since R + T(mu) + A(mu) = 1 at every surface, L - B0 obeys the same transport with
 * the signed sources eps(mu) B(T) - A(mu) B0. By kind of source (emission_kind):
 * - Kirchhoff materials (eps = A): A(mu) (B(T) - B0), the emission above with B(T)
 *   replaced by B(T) - B0 and the same angular law; identically 0 (no source) at T = T0;
 *   an object at 0 K emits -A B0;
 * - explicit-emissivity solids: eps and A = 1 - R do not depend on angle, so one cosine
 *   source of power pi A_area sides (eps B(T) - (1 - R) B0), whose sign may change with
 *   frequency;
 * - explicit-emissivity shells: eps B(T) (cosine) and -A(mu) B0 (mu ~ A(mu) mu) have
 *   different angular laws: two sources, each in its own group;
 * - back faces of one-sided solids: they leave radiance 0 (the renderer adds -B0 where a
 *   ray meets one), i.e. the deviation -B0: a Lambertian source of power -pi A B0 on the
 *   back side (EMISSION_BACK, all in one group). Most back faces face into a closed
 *   solid or out of a closed room, where their photons would store nothing, so each is
 *   drawn in proportion to its reach share r, the share of EMISSION_REACH_RAYS cosine
 *   rays from random back-side points (fixed streams, RNG_PURPOSE_BACK_FACE) whose
 *   first hit is a front face, and its photons carry 1 / r more power: the power fired
 *   is exactly -pi A B0 in expectation. A back face with r = 0 gets no source: an
 *   opening that fewer than about 1 in EMISSION_REACH_RAYS rays find counts as closed
 *   (as for the boundary, air_emission.h).
 * With T0 = 0 only the B(T) parts exist and the tables, photons and random streams are
 * exactly those of the paper's scheme.
 *
 * Scheme (unbiased for the band mean, as physics.md allows): a photon's frequency nu is
 * drawn from the channel response g_c alone. At that nu the sources are grouped (see
 * emission_group) and each group g has the exact signed power w_g(nu) (for a Kirchhoff
 * group pi eps-bar_g(nu) A_g (B_nu(T_g) - B0), times its sides). Evaluating every w_g at
 * every photon's frequency costs an optics evaluation per group (an exponential
 * integral for shells) and was most of the photon phase's time, so the group is drawn
 * instead from a tabulation q_g(nu) of the magnitudes |w_g| (linear interpolation on a
 * fine grid over the band, floored so that q_g > 0 wherever w_g may be nonzero), and the
 * photon carries the signed power
 *     Phi = w_g(nu) Q(nu) / (q_g(nu) K),   Q = sum_g q_g,
 * with w_g evaluated exactly, at the photon's own frequency, for the drawn group only.
 * Then E[Phi | nu] = sum_g w_g(nu) / K = P_A(nu) / K exactly (P_A the deviation sources'
 * power when T0 > 0): the tabulation changes only how evenly the power is spread over
 * photons (|w| / q differs from 1 by the interpolation error, ~1e-7 for smooth optics),
 * never the mean; narrow material lines are still integrated, since w_g is exact. Within
 * the group a source is drawn by its frequency-independent share, one of its emitting
 * sides uniformly, a triangle by an area CDF (searched from a guide table), a point
 * uniformly on the triangle, and a direction by the source's angular law about the
 * emitting side's normal and uniform azimuth.
 *
 * Emitting sides: both sides of shells and two-sided solids, the front side of one-sided
 * solids (and with T0 > 0 their back side's -B0). Objects without area emit nothing;
 * with T0 = 0 neither do objects at 0 K.
 */
#ifndef THZ_PHOTON_EMISSION_H
#define THZ_PHOTON_EMISSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/rng.h"
#include "accel/accel.h"
#include "core/vec3.h"
#include "scene/scene.h"

/* Rays per one-sided solid for the reach share of its back side's source (T0 > 0;
 * emission_reach.h). */
#define EMISSION_REACH_RAYS 16384

/* Kind of a source: how its power and direction depend on B(T), B0 and the optics.
 * Powers per frequency, with W = pi A_area sides: */
typedef enum emission_kind {
    EMISSION_KIRCHHOFF = 0, /* W eps-bar (B(T) - B0), mu ~ A(mu) mu (eps = A) */
    EMISSION_EPS,           /* W eps B(T), cosine: explicit eps (shells; solids when T0 = 0) */
    EMISSION_EPS_ABSORB,    /* W (eps B(T) - (1 - R) B0), cosine: explicit-eps solids, T0 > 0 */
    EMISSION_ABSORB,        /* -W A-bar B0, mu ~ A(mu) mu: explicit-eps shells and solids with an
                             * index, T0 > 0 */
    EMISSION_BACK           /* -pi A B0, cosine, from side 1: one-sided solids, T0 > 0 */
} emission_kind;

/* One source of an emitting object. With T0 > 0 an object can be up to three: an
 * explicit-emissivity shell, or solid with a complex index, is two (eps B(T) and
 * -A(mu) B0), and a one-sided solid whose back side reaches a front face adds that. */
typedef struct emission_source {
    uint32_t object; /* index into scene->objects */
    emission_kind kind;
    int sides;            /* 1 or 2 emitting sides (EMISSION_BACK: 1, side 1) */
    double area_m2;       /* total area of one side */
    bool constant_optics; /* R, alpha_M and eps do not depend on frequency */
    double weight;        /* constant optics: the coefficient of B_nu(T) in the power
                             (pi eps-bar A sides), 0 for EMISSION_ABSORB and _BACK */
    double weight0;       /* constant optics: the coefficient of -B0 (pi A-bar A sides;
                             0 with T0 = 0 and for EMISSION_EPS; pi A r for _BACK) */
    double share;         /* weight within its group: weight + weight0 (constant optics,
                             a fixed multiple of |power| within a group) or A sides
                             (variable optics, the optics shared by the group) */
    double reach_share;   /* EMISSION_BACK: r in (0, 1], the photons carry 1 / r; else 1 */
    optics_point optics;  /* constant optics: the optics at every frequency */
    bool cosine_law;      /* constant optics drawn by the cosine law (optics.h
                             optics_emission_is_cosine): mu = sqrt(1 - u) directly */
    double *triangle_cdf; /* n_triangles cumulative areas, last = total, then their guide
                             table (cdf.h: n_triangles uint32_t) in the same block; shared
                             by an object's sources, owned by the first (owns_cdf) */
    bool owns_cdf;
} emission_source;

/* Sources whose power differs only by a frequency-independent factor form one group, so
 * that a photon needs the exact power of one group only: the same temperature and kind,
 * and either constant optics (for EMISSION_EPS_ABSORB also the same eps and R, which fix
 * the ratio of the two terms; with T0 = 0 constant-optics sources of any kind share a
 * group per temperature, as their powers are all B(T) times a constant), or
 * frequency-dependent optics with the same material, type, thickness and sidedness (so
 * eps-bar(nu) and A-bar(nu) are the same). The source within the group is drawn by its
 * share (CDF over the group's sources). */
typedef struct emission_group {
    double temperature_k;
    emission_kind kind;  /* of its sources (with T0 = 0 and constant optics: of the first) */
    size_t first, count; /* range of emission_table.order */
    bool constant_optics;
    double weight;  /* constant: sum of weights; variable: pi sum of A sides */
    double weight0; /* constant: sum of weight0s; variable: unused */
    double *cdf;    /* count cumulative shares (count > 1) */
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
    double t0_k;        /* reference temperature T0 (0: the paper's map of L) */
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
    double power_w_per_hz; /* signed: E[Phi | nu] = P_A(nu) / K; 0 when nothing emits */
    vec3 position_m;       /* on the triangle */
    vec3 dir;              /* unit, into the emitting side's hemisphere */
    uint32_t object;
    uint32_t triangle;
    int side;       /* 0 front, 1 back */
    uint32_t batch; /* photon_map.h: set by the phase (photon index mod batches) */
} emission_photon;

struct emission_reach; /* photon/emission_reach.h */

/* Prepares channel `channel`'s sources for K = n_photons photons of the map of
 * L - B_nu(t0_k) (t0_k = 0: the paper's map of L; t0_k must be >= 0). With t0_k > 0 the
 * one-sided solids' back sides take their reach shares from reach, computed for this
 * scene (emission_reach_compute); reach NULL or not done: computed here, on all threads.
 * acc (borrowed, the scene's) may be NULL only with t0_k = 0. */
thz_status emission_table_init(emission_table *t, const thz_scene *scene, const accel *acc,
                               size_t channel, uint64_t n_photons, double t0_k,
                               const struct emission_reach *reach, thz_error *err);
void emission_table_fini(emission_table *t);

/* Exact signed power w_g(freq_hz) of group g (W/Hz). */
double emission_group_power(const emission_table *t, size_t g, double freq_hz);

/* Band mean (channel response) of sum_g |w_g(nu)|, W/Hz: the surfaces' share of the
 * photons beside the air and boundary sources when T0 > 0 (air_emission.h). */
double emission_band_magnitude_w_per_hz(const emission_table *t);

/* Draws one photon from rng; allocates nothing. Returns false when the drawn group has
 * no power at the drawn frequency: the photon then has power 0 and nothing else is
 * set. The power is signed (negative where the source's eps B(T) < A B0). */
bool emission_sample(const emission_table *t, rng_stream *rng, emission_photon *out);
/* emission_sample after its first two draws, which gave the frequency nu (for a caller
 * that draws the frequencies of many photons at once: channel_sample_many_hz). */
bool emission_sample_at(const emission_table *t, rng_stream *rng, double nu, emission_photon *out);
/* emission_sample_at but for the direction, left to the caller (sampling_direction_many,
 * for many photons at once): out->dir is sampling_direction(normal, mu, u). */
typedef struct emission_aim {
    vec3 normal; /* of the emitting side */
    double mu;   /* cos(theta) drawn by the source's angular law */
    double u;    /* the azimuth's draw */
} emission_aim;
bool emission_sample_aim(const emission_table *t, rng_stream *rng, double nu, emission_photon *out,
                         emission_aim *aim);

/* Internal to src/photon/: an object's triangle CDF (n_triangles cumulative areas, then
 * their guide table, cdf.h: n_triangles uint32_t, in one malloc'd block; NULL when out of
 * memory or beyond 2^32 triangles), and a point uniform on mesh m by it (*tri its
 * triangle), from three draws of rng. */
double *emission_triangle_cdf(const thz_mesh *m);
vec3 emission_point(const thz_mesh *m, const double *triangle_cdf, double area_m2, rng_stream *rng,
                    size_t *tri);

#endif
