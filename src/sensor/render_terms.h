/* The band terms of the renderer, shared by the integrators: what a ray gains from
 * emission, the air and back faces as band means by the channel quadrature (seen through
 * straight shells and a first scattering vertex), the weights of those, and where a
 * scattered ray starts. physics.md "Rendering phase" and "Integrators".
 */
#ifndef THZ_SENSOR_RENDER_TERMS_H
#define THZ_SENSOR_RENDER_TERMS_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "sensor/render_context.h"

/* The `straight` shells a sample ray has passed through and the mirrors (`specular`
 * reflection) it has bounced off: the path weight at frequency nu is the product of
 * their T(theta) and R(theta) at nu. */
typedef struct render_path {
    size_t n;
    uint32_t object[RENDER_MAX_CROSSINGS];
    double mu[RENDER_MAX_CROSSINGS];
    bool reflected[RENDER_MAX_CROSSINGS]; /* a mirror bounce (R), else a crossing (T) */
} render_path;

/* The scattering at a final-gather vertex x, as a weight on whatever arrives along the
 * gather ray at frequency nu: f_x(nu) cos / pdf / P(branch), with the direction and the
 * branch drawn at the gather ray's frequency nu_j. */
typedef struct render_scatter {
    const thz_material *material;
    const thz_object *object;
    uint32_t object_index;
    bool transmitted;  /* diffuse transmission (else reflection) */
    bool lobe;         /* reflection by an angle-dependent or glossy lobe: the weight is
                          f(nu; w_gather, w_view) mu_i / pdf (else a constant-R
                          Lambertian one: R(nu)) */
    double mu_o;       /* |cos| of the direction towards the sensor at x */
    double mu_i;       /* |cos| of the gather ray at x */
    double pdf_ratio;  /* transmitted: Tbar(nu_j) / T(nu_j, mu_i) */
    double inv_branch; /* 1 / P(branch) */
    brdf_frame frame;  /* lobe: the frame at x, and the directions away from x */
    vec3 w_gather, w_view;
    double pdf;      /* lobe: the density of w_gather per solid angle at nu_j */
    double lookup_u; /* a uniform: the photons at the gather ray's end are looked up when
                        it is below render_context.lookup_q there (render_gather) */
    double nu;       /* > 0: the gather ray's frequency nu_j, at which its emission, air and
                        B0 terms are then taken (one sample of the band, as its photon terms
                        are); 0: their band means by the channel quadrature */
} render_scatter;

/* The optics of `object` (obj) at freq_hz with its means cached from the band's tables
 * (interpolated as render_tbar), and its lobe (brdf.h; Ward's scale and complement
 * interpolated likewise). o must outlive l. */
void render_lobe_at(const render_context *ctx, const thz_object *obj, uint32_t object,
                    double freq_hz, optics_point *o, brdf_lobe *l);

/* scene_object_optics of `object` at freq_hz, from the context's table where it does not
 * depend on frequency (the same point, its freq_hz aside, which only an index reads). */
static inline optics_point render_optics_at(const render_context *ctx, uint32_t object,
                                            double freq_hz)
{
    return ctx->opt_const[object]
               ? ctx->opt_fixed[object]
               : scene_object_optics(ctx->scene, &ctx->scene->objects[object], freq_hz);
}

/* exp(-alpha d), 1 where alpha = 0 (also for d infinite). */
static inline double render_tau(double alpha_per_m, double distance_m)
{
    return alpha_per_m > 0.0 ? exp(-alpha_per_m * distance_m) : 1.0;
}

/* Distance from origin_m along dir to where the ray leaves the atmosphere's extent. */
double render_exit_m(const render_context *ctx, vec3 origin_m, vec3 dir);

/* Product of T(theta) of the crossed straight shells at frequency freq_hz. */
double render_path_weight(const render_context *ctx, const render_path *path, double freq_hz);

/* T-bar of diffuse shell `object` (obj) at freq_hz, interpolated in the band's table. */
double render_tbar(const render_context *ctx, const thz_object *obj, uint32_t object,
                   double freq_hz);

/* The weight f_x(nu) cos / pdf / P(branch) of final-gather vertex s at frequency nu
 * (1 for s NULL). */
double render_scatter_weight(const render_context *ctx, const render_scatter *s, double nu);

/* Band mean of the emission at a hit of `object` seen at |cos| mu through path, at
 * distance_m, weighted by s (may be NULL); deviation: eps B - A B0. With s->nu > 0 (a
 * gather ray), this and the two below are taken at s->nu alone: one unbiased sample of
 * the band mean. */
double render_emission(const render_context *ctx, uint32_t object, double mu,
                       const render_path *path, double distance_m, const render_scatter *s);

/* Deviation: the band mean of B0 exp(-alpha d) seen through path and s (a back face). */
double render_b0_term(const render_context *ctx, const render_path *path, const render_scatter *s,
                      double distance_m);

/* The emitting air (and, escaped, the background) along a free segment d0_m..d1_m. */
double render_air(const render_context *ctx, const render_path *path, const render_scatter *s,
                  double d0_m, double d1_m, bool escaped);

/* The origin of a scattered ray leaving `hit` along dir. */
vec3 render_leave(const render_context *ctx, const accel_hit *hit, vec3 dir);

#endif
