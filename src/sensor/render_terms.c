/* The band terms of the renderer: see render_terms.h. */
#include "sensor/render_terms.h"

#include <math.h>

#include "physics/channel.h"
#include "physics/optics.h"
#include "physics/planck.h"
#include "physics/spectrum.h"

/* Distance from origin_m along dir to where the ray leaves the atmosphere's extent. */
double render_exit_m(const render_context *ctx, vec3 origin_m, vec3 dir)
{
    const double o[3] = {origin_m.x, origin_m.y, origin_m.z}, d[3] = {dir.x, dir.y, dir.z};
    return atmosphere_extent_exit_m(&ctx->scene->atmosphere, o, d);
}

/* Product of T(theta) of the crossed straight shells at frequency freq_hz. */
double render_path_weight(const render_context *ctx, const render_path *path, double freq_hz)
{
    double w = 1.0;
    for (size_t i = 0; i < path->n; i++) {
        optics_point o = render_optics_at(ctx, path->object[i], freq_hz);
        w *= path->reflected[i] ? optics_reflectance(&o, path->mu[i])
                                : optics_transmission(&o, path->mu[i]);
    }
    return w;
}

/* Linear interpolation of table[object * n + node] at freq_hz between the quadrature
 * nodes inside the band; NAN outside. The tabled quantities are smooth in frequency
 * between the scene's spectral knots, which are nodes, so the interpolation is exact
 * to ~1e-8 over a node spacing of 0.03 sigma; it spares a quadrature per photon term.
 * The Gaussian's nodes without knots are evenly spaced (the node is found by division);
 * otherwise each piece has its own Simpson spacing (a measured response's pieces where
 * g = 0 have none), so the node is found by bisection. */
static double render_interp(const render_context *ctx, const double *table, uint32_t object,
                            double freq_hz)
{
    size_t n = ctx->quad.n;
    if (n < 2)
        return NAN;
    const double *f = ctx->quad.freq_hz;
    size_t i;
    double t;
    if (ctx->quad.even) {
        double step = f[1] - f[0];
        double x = (freq_hz - f[0]) / step;
        if (!(x >= 0.0 && x < (double)(n - 1)))
            return NAN;
        i = (size_t)x;
        t = x - (double)i;
    } else {
        if (!(freq_hz >= f[0] && freq_hz < f[n - 1]))
            return NAN;
        i = spectrum_interval(f, n, freq_hz);
        t = (freq_hz - f[i]) / (f[i + 1] - f[i]);
    }
    const double *tb = &table[(size_t)object * n];
    return tb[i] + t * (tb[i + 1] - tb[i]);
}

/* T-bar of diffuse shell `object` at freq_hz: the table's interpolation inside the band,
 * the exact value outside. */
double render_tbar(const render_context *ctx, const thz_object *obj, uint32_t object,
                   double freq_hz)
{
    double v = render_interp(ctx, ctx->tbar, object, freq_hz);
    if (!isnan(v))
        return v;
    optics_point o = scene_object_optics(ctx->scene, obj, freq_hz);
    return optics_mean_transmission(&o);
}

void render_lobe_at(const render_context *ctx, const thz_object *obj, uint32_t object,
                    double freq_hz, optics_point *o, brdf_lobe *l)
{
    *o = render_optics_at(ctx, object, freq_hz);
    double rbar = render_interp(ctx, ctx->rbar, object, freq_hz);
    if (o->has_index) {
        if (isnan(rbar)) {
            optics_prepare(o);
        } else {
            o->mean_r = rbar;
            o->mean_t = render_interp(ctx, ctx->tbar, object, freq_hz);
            o->means_ready = true;
        }
    }
    double scale = render_interp(ctx, ctx->ward_scale, object, freq_hz);
    if (o->lobe != OPTICS_LOBE_WARD || isnan(scale)) {
        scene_object_lobe(ctx->scene, obj, o, l);
        return;
    }
    l->o = o;
    l->ward = ctx->scene->materials[obj->material].ward_table;
    l->scale = scale;
    l->comp_norm = render_interp(ctx, ctx->ward_comp, object, freq_hz);
}

double render_scatter_weight(const render_context *ctx, const render_scatter *s, double nu)
{
    if (!s)
        return 1.0;
    if (s->lobe) {
        optics_point o;
        brdf_lobe l;
        render_lobe_at(ctx, s->object, s->object_index, nu, &o, &l);
        return brdf_eval(&l, &s->frame, s->w_gather, s->w_view) * s->mu_i / s->pdf * s->inv_branch;
    }
    if (!s->transmitted)
        return spectrum_eval(&s->material->reflectivity, nu) * s->inv_branch;
    /* f_T cos_i / pdf = T(nu,mu_i) T(nu,mu_o) / Tbar(nu) x Tbar(nu_j) / T(nu_j,mu_i) */
    optics_point o = render_optics_at(ctx, s->object_index, nu);
    double tbar = render_tbar(ctx, s->object, s->object_index, nu);
    if (!(tbar > 0.0))
        return 0.0;
    return optics_transmission(&o, s->mu_i) * optics_transmission(&o, s->mu_o) / tbar *
           s->pdf_ratio * s->inv_branch;
}

/* The first vertex's scattering weight at quadrature node k, without 1 / P(branch). */
static double render_scatter_node(const render_context *ctx, const render_scatter *s, size_t k)
{
    size_t n = ctx->quad.n;
    const optics_point *ox = &ctx->optics[(size_t)s->object_index * n + k];
    if (s->lobe)
        return brdf_eval(&ctx->lobes[(size_t)s->object_index * n + k], &s->frame, s->w_gather,
                         s->w_view) *
               s->mu_i / s->pdf;
    if (!s->transmitted)
        return ox->reflectivity;
    double tbar = ctx->tbar[(size_t)s->object_index * n + k];
    return tbar > 0.0 ? optics_transmission(ox, s->mu_i) * optics_transmission(ox, s->mu_o) / tbar *
                            s->pdf_ratio
                      : 0.0;
}

/* The weight of quadrature node k in a band mean seen through `path` and the first
 * vertex's scattering s (may be NULL; without 1 / P(branch)): the node's quadrature
 * weight times s's scattering weight and the straight shells' T(theta) at that node. */
static double render_node_weight(const render_context *ctx, const render_path *path,
                                 const render_scatter *s, size_t k)
{
    size_t n = ctx->quad.n;
    double w = ctx->quad.weight[k];
    if (s)
        w *= render_scatter_node(ctx, s, k);
    for (size_t i = 0; i < path->n && w != 0.0; i++) {
        const optics_point *o = &ctx->optics[(size_t)path->object[i] * n + k];
        w *= path->reflected[i] ? optics_reflectance(o, path->mu[i])
                                : optics_transmission(o, path->mu[i]);
    }
    return w;
}

/* The weight of a term at the gather ray's own frequency s->nu: its scattering at the
 * first vertex (with 1 / P(branch)), the straight shells' T(theta) and exp(-alpha d). */
static double render_weight_at(const render_context *ctx, const render_path *path,
                               const render_scatter *s, double distance_m)
{
    double w = render_scatter_weight(ctx, s, s->nu) * render_path_weight(ctx, path, s->nu);
    if (ctx->atmosphere && w != 0.0)
        w *= render_tau(atmosphere_alpha_per_m(&ctx->scene->atmosphere, s->nu), distance_m);
    return w;
}

/* B0 = B_nu(T0) at the gather ray's frequency (0 without a deviation map). */
static double render_b0_at(const render_context *ctx, const render_scatter *s)
{
    return ctx->deviation ? planck_radiance(s->nu, ctx->t0_k) : 0.0;
}

/* Band mean of eps(theta) B_nu(T) at a hit (deviation: eps B - A(theta) B0; no cos
 * factor: physics.md "Surfaces") times exp(-alpha d), the straight-shell path weight and
 * the first vertex's scattering s (may be NULL; final-gather's secondary hits), all at
 * each quadrature node: what the sensor sees carries no band noise of B. Without shells
 * or air between, the band means come from the tables (emission_mean or source_mean for
 * the sample's own hit, pair_mean for a reflected gather ray). Else a gather ray's
 * (s->nu > 0) at its own frequency: the band's variation of its emission is small beside
 * what the gather rays see, and the 401 nodes were 39 % of final-gather's work. */
double render_emission(const render_context *ctx, uint32_t object, double mu,
                       const render_path *path, double distance_m, const render_scatter *s)
{
    if (!(ctx->scene->objects[object].temperature_k > 0.0) && !ctx->deviation)
        return 0.0;
    if (path->n == 0 && !ctx->atmosphere) {
        if (!s) {
            double v = (ctx->deviation ? ctx->source_mean : ctx->emission_mean)[object];
            if (!isnan(v))
                return v;
        } else if (ctx->pair_mean && !s->transmitted && !s->lobe) {
            double v = ctx->pair_mean[(size_t)s->object_index * ctx->scene->n_objects + object];
            if (!isnan(v))
                return v * s->inv_branch;
        }
    }
    if (s && s->nu > 0.0) { /* a gather ray's secondary hit: at its own frequency */
        const thz_object *obj = &ctx->scene->objects[object];
        optics_point o = render_optics_at(ctx, object, s->nu);
        double a, eps;
        optics_absorption_emissivity(&o, mu, &a, &eps);
        double bt = obj->temperature_k > 0.0 ? planck_radiance(s->nu, obj->temperature_k) : 0.0;
        double v = eps * bt - a * render_b0_at(ctx, s);
        return v != 0.0 ? v * render_weight_at(ctx, path, s, distance_m) : 0.0;
    }
    size_t n = ctx->quad.n;
    const optics_point *op = &ctx->optics[(size_t)object * n];
    const double *planck = &ctx->planck[(size_t)object * n];
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        double v;
        if (ctx->deviation) {
            double a, eps;
            optics_absorption_emissivity(&op[k], mu, &a, &eps);
            v = eps * planck[k] - a * ctx->b0[k];
        } else {
            v = optics_emissivity(&op[k], mu) * planck[k];
        }
        if (ctx->atmosphere)
            v *= exp(-ctx->alpha_per_m[k] * distance_m);
        if (v != 0.0)
            sum += v * render_node_weight(ctx, path, s, k);
    }
    return s ? sum * s->inv_branch : sum;
}

/* Deviation: the band mean of B0 exp(-alpha d), seen through path and s: what a back
 * face (radiance 0, deviation -B0) takes away. */
double render_b0_term(const render_context *ctx, const render_path *path, const render_scatter *s,
                      double distance_m)
{
    if (s && s->nu > 0.0)
        return render_b0_at(ctx, s) * render_weight_at(ctx, path, s, distance_m);
    double sum = 0.0;
    for (size_t k = 0; k < ctx->quad.n; k++)
        sum += ctx->b0[k] * render_tau(ctx->alpha_per_m[k], distance_m) *
               render_node_weight(ctx, path, s, k);
    return s ? sum * s->inv_branch : sum;
}

/* The emitting air along one free segment of a sample or gather ray, from distance d0_m
 * to d1_m from the sensor: the band mean, by the channel quadrature, of
 * B_nu(T_air) (exp(-alpha d0) - exp(-alpha d1)), i.e. the segment's path radiance
 * B(1 - exp(-alpha (d1 - d0))) weighted by the transmittance before it, times the
 * straight-shell path weight and the first vertex's scattering weight (s may be NULL).
 * `escaped`: the ray hits nothing and d1_m is where it leaves the extent (may be
 * infinite); the background B_nu(T_bg) exp(-alpha d1) is added. 0 when the air does
 * not emit. Deviation (photon map of L - B0): B_air - B0 and B_bg - B0 instead (B_air,
 * B_bg = 0 for air that does not emit): the free path's (tau - 1) B0 and an escape's
 * -B0. */
double render_air(const render_context *ctx, const render_path *path, const render_scatter *s,
                  double d0_m, double d1_m, bool escaped)
{
    if (!ctx->air_terms || (!escaped && !ctx->atmosphere))
        return 0.0; /* without attenuation a free path adds nothing */
    if (s && s->nu > 0.0) {
        const thz_atmosphere *atm = &ctx->scene->atmosphere;
        double a = atmosphere_alpha_per_m(atm, s->nu), b0 = render_b0_at(ctx, s);
        double t1 = render_tau(a, d1_m);
        double air = 0.0, bg = 0.0; /* air that does not emit: B_air = B_bg = 0 */
        if (atm->emitting) {
            air = planck_radiance(s->nu, atm->air.temperature_k);
            bg = escaped ? planck_radiance(s->nu, atm->background_temperature_k) : 0.0;
        }
        double v = (air - b0) * (render_tau(a, d0_m) - t1);
        if (escaped)
            v += (bg - b0) * t1;
        /* the attenuation is in the terms: the weight without it */
        return v != 0.0
                   ? v * render_scatter_weight(ctx, s, s->nu) * render_path_weight(ctx, path, s->nu)
                   : 0.0;
    }
    double sum = 0.0;
    for (size_t k = 0; k < ctx->quad.n; k++) {
        double a = ctx->alpha_per_m[k];
        double t1 = render_tau(a, d1_m);
        double b0 = ctx->deviation ? ctx->b0[k] : 0.0;
        double v = (ctx->air_planck[k] - b0) * (render_tau(a, d0_m) - t1);
        if (escaped)
            v += (ctx->bg_planck[k] - b0) * t1;
        if (v != 0.0)
            sum += v * render_node_weight(ctx, path, s, k);
    }
    return s ? sum * s->inv_branch : sum;
}

/* The origin of a scattered ray leaving `hit` along dir: the hit point moved by 1e-5 of
 * its distance towards the triangle's centroid, then off the surface by the accel's
 * rule. A hit on the edge between two faces (the corners of a room, which camera rays
 * along the image diagonals meet exactly) lies on the neighbouring face's plane, and a
 * ray from there towards that face would slip out of a closed enclosure; the nudge keeps
 * it inside. It moves the point by far less than any gather disk. */
vec3 render_leave(const render_context *ctx, const accel_hit *hit, vec3 dir)
{
    const thz_mesh *m = &ctx->scene->objects[hit->object].mesh;
    const uint32_t *ix = &m->indices[3 * (size_t)hit->triangle];
    vec3 c = v3(0.0, 0.0, 0.0);
    for (int k = 0; k < 3; k++)
        c = v3_add(c, v3_from_floats(&m->positions[3 * (size_t)ix[k]]));
    accel_hit moved = *hit;
    moved.position_m =
        v3_madd(hit->position_m, 1e-5, v3_sub(v3_scale(c, 1.0 / 3.0), hit->position_m));
    return accel_offset_origin(ctx->accel, &moved, dir);
}
