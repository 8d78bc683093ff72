/* The `final-gather` integrator (physics.md "Integrators"): at the first non-straight hit,
 * `gather_rays` secondary rays (cosine for reflection, by the BTDF T(theta) cos(theta)
 * for diffuse shells), each adding what render_photon_map_trace finds at its own hit with
 * the k-nearest-photon radius there (k = max(gather_min_photons, RENDER_SECONDARY_K));
 * the first hit's emission enters by its band mean, a gather ray's emission, air and B0
 * terms at its own frequency nu_j (render_scatter.nu; each photon term at the photon's). A
 * band mean over the quadrature per gather ray was 39 % of the instructions on the paper's
 * scene, for no less noise. At a diffuse shell each gather ray splits: a reflected and a
 * transmitted ray, each weighted by its own part (R, T), instead of one of them chosen with
 * probability R : T, whose choice between what the two sides see (a warm object under a
 * cover, the room around it) was most of the noise of the paper's covers; a part lighter
 * than RENDER_GATHER_MIN_PART is traced by roulette (a cover's reflected part, R = 0.05,
 * cost a ray and a lookup for a twentieth of the weight: 8 % of the render's instructions
 * at 0.2 THz, the noise the same). From a deviation
 * map the terms are those of L - B(T0) and the sample adds B(T0). One estimate per gather
 * ray: more passes lower the noise. The j-th gather rays of a pixel's samples are
 * stratified together (render_stratum): their cosine directions meet each polar band
 * once and spread evenly in azimuth, which took the paper's scene's variance per gather ray
 * at 0.2 THz to 0.71 x (docs/integrators.md); estimate j stays independent of the others.
 * Then, from a deviation map, the cosine directions are importance-sampled by the photons
 * that arrived near the hit (guide.h): the stratified point of the unit square warped to the
 * guide's density, which took that variance per gather ray to a further 0.66 x.
 */
#include <math.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "physics/channel.h"
#include "physics/optics.h"
#include "sensor/guide.h"
#include "sensor/integrator.h"

/* A diffuse shell's reflected or transmitted part below this weight (R or T(theta) at
 * the gather ray's frequency) is traced by roulette (render_gather_ray). */
#define RENDER_GATHER_MIN_PART 0.15

/* What a gather ray estimates: the scattered radiance, reflected or diffusely transmitted
 * as it draws with probability R : T (a solid: always reflected), or one of the two
 * parts alone (a diffuse shell's split gather ray, weight 1). */
typedef enum render_gather_part {
    RENDER_GATHER_DRAWN,
    RENDER_GATHER_REFLECTED,
    RENDER_GATHER_TRANSMITTED
} render_gather_part;

/* One gather ray from first vertex `hit` (object obj, seen through `path`, at distance
 * distance_m from the sensor): its estimate of `part` of the scattered radiance towards
 * the sensor. With a stratum (or NULL), a cosine direction takes its polar band and
 * azimuth from it, and a diffusely transmitted one its azimuth. */
static double render_gather_ray(const render_context *ctx, const accel_hit *hit, vec3 ray_dir,
                                const thz_object *obj, bool diffuse_shell, const render_path *path,
                                double distance_m, render_gather_part part, rng_stream *rng,
                                const sampling_stratum *stratum, render_guide *guide,
                                render_sample *out, render_sample *sec)
{
    const thz_material *mat = &ctx->scene->materials[obj->material];
    /* u2's words first, then u1's: an order fixed here, not left to the order a compiler
     * evaluates a call's arguments in (render_path_sample draws the same way) */
    double u2 = rng_uniform(rng);
    double nu_j = channel_sample_hz(ctx->channel, rng_uniform(rng), u2);
    optics_point o;
    brdf_lobe lobe;
    render_lobe_at(ctx, obj, hit->object, nu_j, &o, &lobe);
    /* a mirror's reflection is traced by the sample (render_mirror), not gathered */
    double r = o.lobe == OPTICS_LOBE_SPECULAR ? 0.0 : optics_reflectance(&o, hit->cos_theta);
    double tr = diffuse_shell ? optics_transmission(&o, hit->cos_theta) : 0.0;
    if (part == RENDER_GATHER_REFLECTED     ? !(r > 0.0)
        : part == RENDER_GATHER_TRANSMITTED ? !(tr > 0.0)
                                            : !(r + tr > 0.0))
        return 0.0;
    /* a split part lighter than RENDER_GATHER_MIN_PART is traced by roulette, with
     * probability q = part / RENDER_GATHER_MIN_PART, weighted 1 / q */
    double q = 1.0;
    if (part != RENDER_GATHER_DRAWN) {
        double w = part == RENDER_GATHER_REFLECTED ? r : tr;
        if (w < RENDER_GATHER_MIN_PART) {
            q = w / RENDER_GATHER_MIN_PART;
            if (!(rng_uniform(rng) < q))
                return 0.0;
        }
    }
    const float *nf = &obj->mesh.normals[3 * (size_t)hit->triangle];
    vec3 n = v3_from_floats(nf);
    vec3 n_seen = hit->side == 0 ? n : v3_scale(n, -1.0);
    render_scatter s = {.material = mat,
                        .object = obj,
                        .object_index = hit->object,
                        .mu_o = hit->cos_theta,
                        .nu = nu_j};
    vec3 dir;
    bool reflected = part == RENDER_GATHER_REFLECTED ||
                     (part == RENDER_GATHER_DRAWN && rng_uniform(rng) * (r + tr) < r);
    if (reflected) {
        s.inv_branch = part == RENDER_GATHER_DRAWN ? (r + tr) / r : 1.0 / q;
        if (o.lobe == OPTICS_LOBE_DIFFUSE && !optics_reflectance_varies(&o)) {
            double u_polar = rng_uniform(rng), u_azimuth = rng_uniform(rng);
            if (stratum) {
                u_polar = stratum->polar_lo + stratum->polar_width * u_polar;
                u_azimuth = stratum->azimuth;
            }
            s.inv_branch *= render_guide_warp(guide, ctx, hit, n_seen, &u_polar, &u_azimuth);
            double mu = sqrt(1.0 - u_polar);
            dir = sampling_direction(n_seen, mu, u_azimuth);
            s.mu_i = mu;
        } else {
            /* the lobe's own sampling at nu_j, weighted f(nu) cos / pdf(nu_j) */
            s.lobe = true;
            s.frame = scene_triangle_frame(obj, hit->triangle, hit->side);
            s.w_view = v3_scale(ray_dir, -1.0);
            double w;
            if (!brdf_sample(&lobe, &s.frame, s.w_view, sampling_uniform, rng, &dir, &w))
                return 0.0;
            s.w_gather = dir;
            s.mu_i = v3_dot(dir, s.frame.n);
            s.pdf = brdf_pdf(&lobe, &s.frame, s.w_view, dir);
            if (!(s.pdf > 0.0) || !(s.mu_i > 0.0))
                return 0.0;
        }
    } else {
        s.transmitted = true;
        s.inv_branch = part == RENDER_GATHER_DRAWN ? (r + tr) / tr : 1.0 / q;
        double mu;
        if (!optics_sample_transmission_mu(&o, sampling_uniform, rng, &mu))
            return 0.0;
        double u_azimuth = rng_uniform(rng);
        dir =
            sampling_direction(v3_scale(n_seen, -1.0), mu, stratum ? stratum->azimuth : u_azimuth);
        s.mu_i = mu;
        s.pdf_ratio = optics_mean_transmission(&o) / optics_transmission(&o, mu);
    }
    s.lookup_u = rng_uniform(rng); /* whether it looks up the photons where it ends */
    vec3 origin = render_leave(ctx, hit, dir);
    double l = render_photon_map_trace(ctx, origin, dir, hit->object, hit->triangle, *path,
                                       distance_m, &s, 0.0, sec);
    out->starved |= sec->starved;
    out->truncated |= sec->truncated;
    return l;
}

/* The sample's terms along a ray from origin_m (past `path`, at distance_m): emission
 * and air on the way, through straight shells and mirrors, and the gather rays at the
 * first hit that scatters otherwise. Recursive where a straight shell is also a mirror. */
static void render_final_gather_trace(const render_context *ctx, vec3 origin_m, vec3 dir,
                                      uint32_t ignore_object, uint32_t ignore_triangle,
                                      render_path path, double distance_m, const render_target *t,
                                      render_sample *out)
{
    for (;;) {
        accel_hit hit;
        if (!accel_intersect(ctx->accel, origin_m, dir, INFINITY, ignore_object, ignore_triangle,
                             &hit)) {
            if (path.n == 0)
                out->escaped = 1;
            if (ctx->air_terms)
                render_add_all(t, render_air(ctx, &path, NULL, distance_m,
                                             distance_m + render_exit_m(ctx, origin_m, dir), true));
            return;
        }
        double d0_m = distance_m;
        distance_m += hit.distance_m;
        if (ctx->air_terms)
            render_add_all(t, render_air(ctx, &path, NULL, d0_m, distance_m, false));
        const thz_object *obj = &ctx->scene->objects[hit.object];
        if (!scene_object_side_is_front(obj, hit.side)) {
            out->back_face = 1;
            out->back_object = hit.object;
            if (ctx->deviation)
                render_add_all(t, -render_b0_term(ctx, &path, NULL, distance_m));
            return;
        }
        render_add_all(t, render_emission(ctx, hit.object, hit.cos_theta, &path, distance_m, NULL));
        bool shell = obj->type == OBJECT_SHELL;
        bool straight =
            shell && ctx->scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        bool mirror = ctx->scene->materials[obj->material].reflection == REFLECTION_SPECULAR;
        if (ctx->scatters[hit.object] && (!mirror || (shell && !straight))) {
            /* streams: the sample's, one per gather ray (a split ray's reflected part
             * draws first, then its transmitted part); crossings of straight shells shift
             * them so that each vertex has its own */
            bool split = shell && !straight;
            render_guide guide = {.state = 0}; /* drawn by the first gather ray to use it */
            for (uint32_t j = 0; j < t->n_est; j++) {
                rng_stream rng;
                rng_init(&rng, ctx->seed, ctx->channel_index, RNG_PURPOSE_GATHER,
                         (t->rng_index + j) * (RENDER_MAX_CROSSINGS + 1) + path.n);
                sampling_stratum stratum;
                bool stratified = render_stratum(ctx, t, j, path.n, &stratum);
                for (int k = 0; k < (split ? 2 : 1); k++) {
                    render_gather_part part = !split   ? RENDER_GATHER_DRAWN
                                              : k == 0 ? RENDER_GATHER_REFLECTED
                                                       : RENDER_GATHER_TRANSMITTED;
                    render_sample sec = {.variance = 0.0};
                    t->est[j] +=
                        t->weight * render_gather_ray(ctx, &hit, dir, obj, split, &path, distance_m,
                                                      part, &rng, stratified ? &stratum : NULL,
                                                      &guide, out, &sec);
                    if (t->batch) {
                        for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
                            t->batch[b] += t->weight * sec.batch[b];
                        *t->disk_var += t->weight * t->weight * sec.variance;
                    }
                }
            }
            out->paths += split ? 2 * t->n_est : t->n_est;
        }
        vec3 in_dir = dir;
        if (render_mirror(ctx, &hit, &path, &dir, &origin_m, out)) {
            ignore_object = hit.object;
            ignore_triangle = hit.triangle;
            if (!straight)
                continue;
            render_path branch = path;
            path.n--;
            if (path.n < RENDER_MIRROR_BRANCHES)
                render_final_gather_trace(ctx, origin_m, dir, hit.object, hit.triangle, branch,
                                          distance_m, t, out);
            else
                out->truncated = 1;
            dir = in_dir;
        }
        if (!straight)
            return;
        if (path.n == RENDER_MAX_CROSSINGS) {
            out->truncated = 1;
            return;
        }
        path.object[path.n] = hit.object;
        path.mu[path.n] = hit.cos_theta;
        path.reflected[path.n] = false;
        path.n++;
        origin_m = accel_offset_origin(ctx->accel, &hit, dir);
        ignore_object = hit.object;
        ignore_triangle = hit.triangle;
    }
}

void render_final_gather_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                double sample_sr, const render_target *t, render_sample *out)
{
    (void)sample_sr;
    render_path path = {.n = 0};
    if (ctx->deviation)
        render_add_all(t, ctx->b0_mean);
    render_final_gather_trace(ctx, origin_m, dir, ACCEL_NO_OBJECT, 0, path, 0.0, t, out);
}
