/* Surface optics at one frequency (physics.md "Surfaces"): transmission T(theta),
 * absorption A(theta), emissivity eps(theta), their hemispherical means, and sampling
 * of directions proportional to T(theta) cos(theta) or eps(theta) cos(theta).
 *
 * theta is the angle between a direction and the surface normal; functions take
 * mu = |cos theta| in (0, 1].
 */
#ifndef THZ_PHYSICS_OPTICS_H
#define THZ_PHYSICS_OPTICS_H

#include <stdbool.h>

typedef struct optics_point {
    double reflectivity;      /* R, 0..1 */
    double attenuation_per_m; /* alpha_M, >= 0 */
    double thickness_m;       /* t; 0 for solids (no transmission) */
    double emissivity;        /* explicit eps when explicit_emissivity */
    bool explicit_emissivity;
} optics_point;

/* T(theta) = min(exp(-alpha_M t / mu), 1 - R) for shells (thickness > 0), 0 for solids. */
double optics_transmission(const optics_point *o, double mu);

/* A(theta) = 1 - R - T(theta). */
double optics_absorption(const optics_point *o, double mu);

/* eps(theta): the explicit emissivity, or Kirchhoff's A(theta). */
double optics_emissivity(const optics_point *o, double mu);

/* Hemispherical means 2 int_0^1 X(mu) mu dmu of T and eps (T-bar, eps-bar). */
double optics_mean_transmission(const optics_point *o);
double optics_mean_emissivity(const optics_point *o);

/* Samples mu in (0,1] with density proportional to T(mu) mu (the diffuse BTDF's exit
 * distribution, physics.md) or eps(mu) mu (emission), using uniforms from `next`
 * (called as many times as needed, e.g. by rejection). Returns false if the
 * distribution is identically zero. */
typedef double (*optics_uniform_fn)(void *ctx);
bool optics_sample_transmission_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                                   double *mu);
bool optics_sample_emission_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                               double *mu);

/* Largest |eps(theta) - A(theta)| over angles (0 for Kirchhoff materials): validate
 * warns when it exceeds 0.01. */
double optics_kirchhoff_violation(const optics_point *o);

#endif
