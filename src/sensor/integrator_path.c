/* The `path` integrator (physics.md "Integrators"): backward Monte Carlo without a
 * photon map.
 * With B0(nu) = B_nu(T0) for a reference temperature T0, the
 * radiance leaving a front side obeys (physics.md "Surfaces", Kirchhoff or explicit eps)
 *   L - B0 = [eps B(T) - A B0] + R (L_R - B0) + T (L_T - B0),   A = 1 - R - T(theta),
 * and across a free path of transmittance tau, L_in - B0 = tau (L_far - B0) + (tau - 1) B0;
 * nothing hit, or the back of a one-sided solid, is L - B0 = -B0. A path samples nu from
 * g_c, adds the bracket at every hit (times the path's weight beta: the product of the
 * transmittances so far and of what the choices below put in) and goes on reflected
 * (by the material's lobe, brdf.h, whose sample weight multiplies beta; 1 but for Ward)
 * or transmitted (straight: unchanged; diffuse: exit mu ~ T(mu) mu), which makes the BRDF
 * and BTDF weights exactly 1. While beta (R + T(theta)) is at least
 * RENDER_PATH_MIN_WEIGHT it always goes on, beta multiplied by R + T(theta), reflected
 * with probability R / (R + T); below, Russian roulette: on with probability
 * beta (R + T(theta)) / RENDER_PATH_MIN_WEIGHT at weight RENDER_PATH_MIN_WEIGHT,
 * reflected or transmitted in the same proportion. The estimate is Bbar0 + the sum,
 * Bbar0 the band mean of B0 by the channel quadrature; E[B0(nu)] = Bbar0, so it is
 * unbiased for the band mean of L for any T0 (B0 is an additive control variate, in
 * space and in frequency).
 *
 * Two refinements at the sample's first hit, which all its paths share: the terms of
 * the first free path and the first hit are known functions of nu there, so they enter
 * by their band mean (the channel quadrature, as photon-map's emission), not at the
 * path's nu; and the path splits there (a reflected branch weighted R, a transmitted one
 * weighted T(theta)) instead of playing roulette, its branches' directions stratified with
 * those of the same estimate of the pixel's other samples (render_stratum: variance x 0.89
 * on the paper's scene at 0.2 THz, docs/integrators.md).
 *
 * In an isothermal enclosure at T0 every bracket is exactly 0, so every path returns
 * Bbar0: N_c = 1 to rounding. T0 is the temperature of the object with the largest
 * area x sides x hemispherical emissivity at the channel centre (the walls of a room). */
#include <math.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "physics/channel.h"
#include "physics/optics.h"
#include "physics/planck.h"
#include "sensor/integrator.h"

/* A path goes on without roulette, its weight beta multiplied by R + T(theta), while that
 * product is at least this; below, roulette on it, the survivors' weight this. Roulette's
 * choice between going on and stopping was the larger part of the noise where objects of
 * R ~ 0.5 face each other (the paper's cylinders and their covers): on the paper's scene
 * going on while beta (R + T) >= 0.3 took the objects' RMS standard error at 0.2 THz from
 * 0.188 to 0.136 K (16 paths, variance x 0.52) for about 1.2x the render time. Since
 * 2026-12-03 beta includes the first hit's branch weight (R or T(theta),
 * render_path_trace), and the threshold is 0.15: in variance x instructions, 0.05 to 0.2
 * do the same within 1 % (32 paths a sample; 0.1 to 0.2 with 108) and 0.3 is 8 % worse.
 * Below it, roulette kept beta and survived with probability R + T until 2026-12-03: a
 * path leaving a wall (R = 0.1) went on at 10 % with its full weight. Surviving with
 * probability beta (R + T) / 0.15 at weight 0.15 instead gives variance x instructions
 * x 0.91 (108 paths, seeds 1 and 2); with 32 paths 0.15 and 0.2 do the same, 0.1 and
 * 0.3 3-5 % worse. */
#define RENDER_PATH_MIN_WEIGHT 0.15

/* The path's roulette (the top of this file): a weight *w of at least
 * RENDER_PATH_MIN_WEIGHT goes on as it is; a smaller one goes on with probability
 * q = *w / RENDER_PATH_MIN_WEIGHT at weight RENDER_PATH_MIN_WEIGHT (the same
 * expectation). u decides; *u_rest (u, or u / q) is uniform again given that it goes on. */
static bool render_path_roulette(double *w, double u, double *u_rest)
{
    *u_rest = u;
    if (*w >= RENDER_PATH_MIN_WEIGHT)
        return true;
    double q = *w / RENDER_PATH_MIN_WEIGHT;
    if (!(u < q))
        return false;
    *u_rest = u / q;
    *w = RENDER_PATH_MIN_WEIGHT;
    return true;
}

/* Whether a first-hit branch of weight *w is traced: by render_path_roulette, its
 * uniform drawn only where *w is below RENDER_PATH_MIN_WEIGHT. A cover's reflected
 * branch (R = 0.05) cast its rays for 5 % of the path's weight. */
static bool render_path_branch(double *w, rng_stream *rng)
{
    double unused;
    return *w >= RENDER_PATH_MIN_WEIGHT || render_path_roulette(w, rng_uniform32(rng), &unused);
}

/* Philox blocks computed ahead when a sample's paths start, 16 streams at a time
 * (rng_init_many): a path draws its frequency (2 words), then 2 or 3 a bounce. */
#define RENDER_PATH_RNG_BLOCKS 3u

/* A scattered direction at `hit` (arriving along *dir; unit normal n_seen towards the
 * side the ray came from): by the material's lobe on that side (reflection: cosine for
 * a constant-R diffuse surface, else brdf_sample, whose weight multiplies *beta), or
 * leaving the other side with mu ~ T(mu) mu (diffuse transmission). With a stratum (or
 * NULL), a cosine direction takes its polar band and azimuth from it, a transmitted one
 * its azimuth; the stream's words are drawn all the same. False if nothing can be sampled
 * (T = 0 cannot happen after a transmission event; a glossy sample may fall below the
 * surface). */
static bool render_scatter_dir(const thz_scene *scene, const thz_object *obj, const accel_hit *hit,
                               const optics_point *o, vec3 n_seen, bool transmitted,
                               const sampling_stratum *stratum, rng_stream *rng, vec3 *dir,
                               double *beta)
{
    if (!transmitted) {
        if (o->lobe == OPTICS_LOBE_DIFFUSE && !optics_reflectance_varies(o)) {
            if (!stratum) {
                *dir = sampling_cosine32(n_seen, rng);
                return true;
            }
            (void)rng_uniform32(rng); /* the azimuth's word (sampling_cosine32's order) */
            double u_polar = stratum->polar_lo + stratum->polar_width * rng_uniform32(rng);
            *dir = sampling_direction(n_seen, sqrt(1.0 - u_polar), stratum->azimuth);
            return true;
        }
        brdf_frame f = scene_triangle_frame(obj, hit->triangle, hit->side);
        brdf_lobe lobe; /* sampling only (brdf.h): per bounce, R-bar would cost 48 Fresnel terms */
        brdf_lobe_init_sampling(&lobe, o, scene->materials[obj->material].ward_table);
        double w;
        if (!brdf_sample(&lobe, &f, v3_scale(*dir, -1.0), sampling_uniform32, rng, dir, &w))
            return false;
        *beta *= w;
        return true;
    }
    double m;
    if (!optics_sample_transmission_mu(o, sampling_uniform32, rng, &m))
        return false;
    double u_azimuth = rng_uniform32(rng);
    *dir = sampling_direction(v3_scale(n_seen, -1.0), m, stratum ? stratum->azimuth : u_azimuth);
    return true;
}

/* Continues a path leaving `from` along dir with throughput beta at frequency nu (B0 =
 * b0 there; b_air = B_nu(T_air) of an emitting atmosphere, else unused; alpha_per_m the
 * air's attenuation at nu, looked up once per path): the sum of the
 * terms of every later free path and hit (see the top of this file), with Russian
 * roulette on R and T(theta) at each hit. An emitting atmosphere turns a free path's term
 * (tau - 1) B0 into (1 - tau)(B_air - B0) and the escape term -B0 into L_escape - B0. */
static double render_path_continue(const render_context *ctx, const accel_hit *from, vec3 dir,
                                   double nu, double b0, double b_air, double alpha_per_m,
                                   double beta, rng_stream *rng, render_sample *out)
{
    const thz_scene *scene = ctx->scene;
    double sum = 0.0;
    accel_hit hit = *from;
    for (uint32_t bounce = 1;; bounce++) {
        vec3 surface = hit.position_m;
        vec3 origin = render_leave(ctx, &hit, dir);
        uint32_t from_object = hit.object, from_triangle = hit.triangle;
        if (!accel_intersect(ctx->accel, origin, dir, INFINITY, from_object, from_triangle, &hit)) {
            if (ctx->emitting) {
                double tau = render_tau(alpha_per_m, render_exit_m(ctx, origin, dir));
                double b_bg = planck_radiance(nu, scene->atmosphere.background_temperature_k);
                sum += beta * (b_bg * tau + b_air * (1.0 - tau) - b0);
            } else {
                sum -= beta * b0;
            }
            break;
        }
        if (bounce >= RENDER_MAX_BOUNCES) {
            out->truncated = 1;
            break;
        }
        if (ctx->atmosphere) {
            /* from the surface point, not the offset origin (as the photon phase) */
            const float *hn = &scene->objects[hit.object].mesh.normals[3 * (size_t)hit.triangle];
            vec3 to_hit = v3_sub(hit.position_m, surface);
            double d = hit.cos_theta > 1e-6
                           ? fabs(v3_dot(to_hit, v3_from_floats(hn))) / hit.cos_theta
                           : v3_length(to_hit);
            double tau = render_tau(alpha_per_m, d); /* atmosphere_transmittance */
            if (ctx->emitting)
                sum += beta * (1.0 - tau) * (b_air - b0);
            else
                sum += beta * (tau - 1.0) * b0;
            beta *= tau;
        }
        const thz_object *obj = &scene->objects[hit.object];
        if (!scene_object_side_is_front(obj, hit.side)) {
            sum -= beta * b0;
            break;
        }
        optics_point o = render_optics_at(ctx, hit.object, nu);
        double r = optics_reflectance(&o, hit.cos_theta);
        double tr = optics_transmission(&o, hit.cos_theta);
        double a = 1.0 - r - tr;
        double eps = o.explicit_emissivity ? o.emissivity : a;
        double bt = obj->temperature_k == ctx->t0_k ? b0 : planck_radiance(nu, obj->temperature_k);
        sum += beta * (eps * bt - a * b0);
        /* on with weight beta (R + T), or by roulette below the threshold; reflected or
         * transmitted in proportion R : T */
        double u = rng_uniform32(rng), keep = r + tr, w = beta * keep;
        if (!render_path_roulette(&w, u, &u))
            break; /* absorbed */
        beta = w;
        bool transmitted = !(u * keep < r);
        if (transmitted && scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT)
            continue; /* straight on, dir unchanged */
        const float *nf = &obj->mesh.normals[3 * (size_t)hit.triangle];
        vec3 n = v3_from_floats(nf);
        vec3 n_seen = hit.side == 0 ? n : v3_scale(n, -1.0);
        if (!render_scatter_dir(scene, obj, &hit, &o, n_seen, transmitted, NULL, rng, &dir, &beta))
            break;
    }
    return sum;
}

/* One path from the sample's first hit `first` (ray along dir0 from the sensor) at
 * frequency nu (drawn from its stream rng's first two words by render_path_sample): the
 * random part of its estimate, beyond the deterministic first terms. At the first hit
 * the path splits instead of playing roulette: a reflected branch weighted R and, for
 * shells, a transmitted branch weighted T(theta), each continued by roulette. (Every path
 * of a sample shares the first hit; roulette there would add the variance of choosing
 * between what the reflection and the transmission see, the main noise of a wall that
 * reflects a warmer object.) A branch's weight is part of its beta, so that roulette
 * weighs it by what it carries: a cover's reflected branch (R = 0.05) went on without
 * roulette as far as its transmitted one (T = 0.93) when the weight multiplied the
 * branch's sum instead (variance x instructions x 0.92 on the paper's scene at 0.2 THz).
 * A branch lighter than RENDER_PATH_MIN_WEIGHT is itself traced by roulette
 * (render_path_branch): variance x instructions x 0.90 more (108 paths, seeds 1 and 2).
 * The branches' directions come from `stratum` where it is not NULL (render_stratum). */
static double render_path_trace(const render_context *ctx, const accel_hit *first, vec3 dir0,
                                double nu, const sampling_stratum *stratum, rng_stream *rng,
                                render_sample *out)
{
    const thz_scene *scene = ctx->scene;
    double b0 = planck_radiance(nu, ctx->t0_k);
    double t_air = scene->atmosphere.air.temperature_k;
    double b_air = !ctx->emitting ? 0.0 : t_air == ctx->t0_k ? b0 : planck_radiance(nu, t_air);
    /* alpha(nu) is fixed along the path: render_tau(alpha, d) is
     * atmosphere_transmittance(nu, d) bit for bit (alpha >= 0) */
    double alpha = atmosphere_alpha_per_m(&scene->atmosphere, nu);
    double beta = ctx->atmosphere ? render_tau(alpha, first->distance_m) : 1.0;
    const thz_object *obj = &scene->objects[first->object];
    optics_point o = render_optics_at(ctx, first->object, nu);
    double r = optics_reflectance(&o, first->cos_theta);
    double tr = optics_transmission(&o, first->cos_theta);
    const float *nf = &obj->mesh.normals[3 * (size_t)first->triangle];
    vec3 n = v3_from_floats(nf);
    vec3 n_seen = first->side == 0 ? n : v3_scale(n, -1.0);
    double sum = 0.0;
    vec3 dir = dir0;
    double w_r = r * beta;
    if (r > 0.0 && render_path_branch(&w_r, rng) &&
        render_scatter_dir(scene, obj, first, &o, n_seen, false, stratum, rng, &dir, &w_r))
        sum += render_path_continue(ctx, first, dir, nu, b0, b_air, alpha, w_r, rng, out);
    double w_t = tr * beta;
    if (tr > 0.0 && render_path_branch(&w_t, rng)) {
        bool straight = scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        dir = dir0;
        if (straight ||
            render_scatter_dir(scene, obj, first, &o, n_seen, true, stratum, rng, &dir, &w_t))
            sum += render_path_continue(ctx, first, dir, nu, b0, b_air, alpha, w_t, rng, out);
    }
    out->paths++;
    return sum;
}

/* The band mean of the first segment's and first hit's terms, (tau - 1) B0 +
 * tau (eps B(T) - A B0), by the channel quadrature: deterministic per sample, so that the
 * band noise of what the sensor sees directly (the emission of the surface hit, its
 * attenuation) does not enter the paths. */
static double render_path_first(const render_context *ctx, const accel_hit *hit)
{
    if (!ctx->atmosphere && !isnan(ctx->source_mean[hit->object]))
        return ctx->source_mean[hit->object];
    size_t n = ctx->quad.n;
    const optics_point *op = &ctx->optics[(size_t)hit->object * n];
    const double *planck = &ctx->planck[(size_t)hit->object * n];
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        double tau = ctx->atmosphere ? exp(-ctx->alpha_per_m[k] * hit->distance_m) : 1.0;
        double a, eps;
        optics_absorption_emissivity(&op[k], hit->cos_theta, &a, &eps);
        double free_path = ctx->emitting ? (1.0 - tau) * (ctx->air_planck[k] - ctx->b0[k])
                                         : (tau - 1.0) * ctx->b0[k];
        sum += ctx->quad.weight[k] * (free_path + tau * (eps * planck[k] - a * ctx->b0[k]));
    }
    return sum;
}

void render_path_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
                        const render_target *t, render_sample *out)
{
    (void)sample_sr;
    accel_hit first;
    render_path none = {.n = 0};
    if (!accel_intersect(ctx->accel, origin_m, dir, INFINITY, ACCEL_NO_OBJECT, 0, &first)) {
        out->escaped = 1;
        /* radiance 0 for every path, or what the air and the background give */
        if (ctx->emitting)
            render_add_all(
                t, render_air(ctx, &none, NULL, 0.0, render_exit_m(ctx, origin_m, dir), true));
        return;
    }
    if (!scene_object_side_is_front(&ctx->scene->objects[first.object], first.side)) {
        out->back_face = 1;
        out->back_object = first.object;
        if (ctx->emitting)
            render_add_all(t, render_air(ctx, &none, NULL, 0.0, first.distance_m, false));
        return;
    }
    double fixed = ctx->b0_mean + render_path_first(ctx, &first);
    /* 16 paths at a time: their streams started together (rng_init_many), their
     * frequencies drawn together (channel_sample_many_hz, u2's word first), then each
     * path traced; the same numbers as one path at a time (rng_init, channel_sample_hz) */
    for (uint32_t j0 = 0; j0 < t->n_est; j0 += RNG_MANY) {
        size_t n = t->n_est - j0 < RNG_MANY ? t->n_est - j0 : RNG_MANY;
        rng_stream rng[RNG_MANY];
        rng_init_many(rng, n, ctx->seed, ctx->channel_index, RNG_PURPOSE_PATH, t->rng_index + j0,
                      RENDER_PATH_RNG_BLOCKS);
        double u1[RNG_MANY], u2[RNG_MANY], nu[RNG_MANY];
        for (size_t k = 0; k < n; k++) {
            u2[k] = rng_uniform32(&rng[k]);
            u1[k] = rng_uniform32(&rng[k]);
        }
        channel_sample_many_hz(ctx->channel, u1, u2, n, nu);
        for (size_t k = 0; k < n; k++) {
            sampling_stratum stratum;
            bool stratified = render_stratum(ctx, t, (uint32_t)(j0 + k), 0, &stratum);
            t->est[j0 + k] +=
                t->weight * (fixed + render_path_trace(ctx, &first, dir, nu[k],
                                                       stratified ? &stratum : NULL, &rng[k], out));
        }
    }
}
