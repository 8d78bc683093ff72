/* Surface optics at one frequency (physics.md "Surfaces"): reflectance R(theta),
 * transmission T(theta), absorption A(theta), emissivity eps(theta), their hemispherical
 * means, and sampling of directions proportional to R(theta) cos(theta),
 * T(theta) cos(theta) or eps(theta) cos(theta).
 *
 * theta is the angle between a direction and the surface normal; functions take
 * mu = |cos theta| in (0, 1].
 *
 * Without a complex index, R is a constant and T(theta) = min(exp(-alpha_M t/mu), 1 - R)
 * (the paper's model, closed forms). With an index n + ik (has_index), R(theta) is the
 * Fresnel reflectance of a half-space (solids) or of a slab of thickness t with
 * incoherent multiple reflections (shells; fresnel.h), T(theta) the slab's; a
 * `reflectivity` or `attenuation_per_m` given beside the index replaces R by the constant
 * (T by min(T_slab, 1 - R)) or the slab's internal attenuation 4 pi k nu / c by alpha_M.
 * Hemispherical means are then Gauss-Legendre sums (48 nodes; R and T are analytic in mu,
 * so they converge to ~1e-13), and sampling is by rejection from the cosine law.
 */
#ifndef THZ_PHYSICS_OPTICS_H
#define THZ_PHYSICS_OPTICS_H

#include <stdbool.h>

/* The reflection lobe (the material's `reflection` key): Lambertian with the reciprocal
 * BRDF R(mu_i) R(mu_o) / (pi R-bar) (R/pi when R is constant), a mirror of reflectance
 * R(theta), or Ward's anisotropic lobe with its diffuse complement (brdf.h). */
typedef enum optics_lobe {
    OPTICS_LOBE_DIFFUSE = 0,
    OPTICS_LOBE_SPECULAR,
    OPTICS_LOBE_WARD
} optics_lobe;

typedef struct optics_point {
    double reflectivity;      /* R, 0..1 (the constant R: no index, or reflectivity_given) */
    double attenuation_per_m; /* alpha_M, >= 0 (no index, or attenuation_given) */
    double thickness_m;       /* t; 0 for solids (no transmission) */
    double emissivity;        /* explicit eps when explicit_emissivity */
    bool explicit_emissivity;
    bool has_index;          /* R(theta), T(theta) from the complex index n + ik */
    bool reflectivity_given; /* with an index: R is the constant `reflectivity` */
    bool attenuation_given;  /* with an index: a slab's inside attenuates by alpha_M */
    double n, k;             /* the index at freq_hz (has_index) */
    double freq_hz;          /* the frequency the point describes, Hz */
    optics_lobe lobe;
    double ward_alpha[2]; /* Ward's alpha_x, alpha_y (OPTICS_LOBE_WARD) */
    bool means_ready;     /* optics_prepare has cached mean_r and mean_t */
    double mean_r, mean_t;
} optics_point;

/* Whether R depends on the angle (an index without an explicit `reflectivity`). When
 * false every function below gives bit for bit what the paper's model gives. */
bool optics_reflectance_varies(const optics_point *o);

/* Caches the hemispherical means of R and T in o (a no-op without an index): call it
 * once where the same point serves many evaluations of the means. */
void optics_prepare(optics_point *o);

/* R(theta): the constant R, or the Fresnel reflectance of the half-space or slab. */
double optics_reflectance(const optics_point *o, double mu);

/* R-bar = 2 int_0^1 R(mu) mu dmu. */
double optics_mean_reflectance(const optics_point *o);

/* T(theta) = min(exp(-alpha_M t / mu), 1 - R) for shells (thickness > 0) without an
 * index, the slab's T(theta) with one; 0 for solids. */
double optics_transmission(const optics_point *o, double mu);

/* A(theta) = 1 - R(theta) - T(theta). */
double optics_absorption(const optics_point *o, double mu);

/* eps(theta): the explicit emissivity, or Kirchhoff's A(theta). */
double optics_emissivity(const optics_point *o, double mu);

/* A(theta) and eps(theta) together, as optics_absorption and optics_emissivity give
 * them, the absorption computed once (band sums over hundreds of nodes). */
void optics_absorption_emissivity(const optics_point *o, double mu, double *a, double *eps);

/* Hemispherical means 2 int_0^1 X(mu) mu dmu of T and eps (T-bar, eps-bar). */
double optics_mean_transmission(const optics_point *o);
double optics_mean_emissivity(const optics_point *o);

/* Samples mu in (0,1] with density proportional to T(mu) mu (the diffuse BTDF's exit
 * distribution, physics.md), eps(mu) mu (emission) or R(mu) mu (the diffuse BRDF's, the
 * cosine law when R is constant), using uniforms from `next` (called as many times as
 * needed, e.g. by rejection). Returns false if the distribution is identically zero (or,
 * with an index, where its hemispherical mean is below OPTICS_MIN_MEAN, or after
 * OPTICS_MAX_TRIES rejected proposals). */
#define OPTICS_MAX_TRIES 1000000
/* After this many rejections the sampler asks the distribution's hemispherical mean and
 * gives up at once below OPTICS_MIN_MEAN (optics.c). */
#define OPTICS_QUICK_TRIES 64
#define OPTICS_MIN_MEAN 1e-5
typedef double (*optics_uniform_fn)(void *ctx);
bool optics_sample_transmission_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                                   double *mu);
bool optics_sample_emission_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                               double *mu);

/* Whether optics_sample_emission_mu draws the cosine law, mu = sqrt(1 - u) from one
 * uniform u (eps does not depend on angle and is > 0): callers that sample many photons
 * from the same optics may draw it themselves, with the same numbers. */
bool optics_emission_is_cosine(const optics_point *o);
bool optics_sample_reflection_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                                 double *mu);

/* Largest |eps(theta) - A(theta)| over angles (0 for Kirchhoff materials): validate
 * warns when it exceeds 0.01. */
double optics_kirchhoff_violation(const optics_point *o);

#endif
