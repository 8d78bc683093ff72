/* The `photon-map` integrator, the paper's (physics.md "Rendering phase", eq. 11-13): at
 * the first hit (through straight shells) the band mean of the emission plus the density
 * estimate of the photons there over the sample's footprint (gather.c); deterministic
 * given the photon map, so one pass. From a deviation map (photon_map.h) the terms are
 * those of L - B(T0) and the sample adds the band mean of B(T0).
 */
#include <math.h>

#include "sensor/integrator.h"

bool render_mirror(const render_context *ctx, const accel_hit *hit, render_path *path, vec3 *dir,
                   vec3 *origin_m, render_sample *out)
{
    const thz_object *obj = &ctx->scene->objects[hit->object];
    if (!ctx->mirror[hit->object])
        return false;
    if (path->n == RENDER_MAX_CROSSINGS) {
        out->truncated = 1;
        return false;
    }
    vec3 n = v3_from_floats(&obj->mesh.normals[3 * (size_t)hit->triangle]);
    *dir = v3_normalize(v3_sub(*dir, v3_scale(n, 2.0 * v3_dot(*dir, n))));
    path->object[path->n] = hit->object;
    path->mu[path->n] = hit->cos_theta;
    path->reflected[path->n] = true;
    path->n++;
    *origin_m = accel_offset_origin(ctx->accel, hit, *dir);
    return true;
}

/* The photon-map radiance along a ray (physics.md "Rendering phase"): emission and the
 * photon terms at the first hit, continued through straight shells. `path` and
 * `distance_m` carry what lies between the sensor and `origin_m` (final-gather's
 * secondary rays start with the first vertex's); `scatter` (may be NULL) weights every
 * term by the first vertex's scattering at the term's frequency. */
double render_photon_map_trace(const render_context *ctx, vec3 origin_m, vec3 dir,
                               uint32_t ignore_object, uint32_t ignore_triangle, render_path path,
                               double distance_m, const render_scatter *scatter, double sample_sr,
                               render_sample *out)
{
    double radiance = 0.0;
    size_t crossings = 0;
    for (;;) {
        accel_hit hit;
        if (!accel_intersect(ctx->accel, origin_m, dir, INFINITY, ignore_object, ignore_triangle,
                             &hit)) {
            if (crossings == 0)
                out->escaped = 1;
            if (ctx->air_terms)
                radiance += render_air(ctx, &path, scatter, distance_m,
                                       distance_m + render_exit_m(ctx, origin_m, dir), true);
            return radiance;
        }
        double d0_m = distance_m;
        distance_m += hit.distance_m;
        radiance += render_air(ctx, &path, scatter, d0_m, distance_m, false);
        const thz_object *obj = &ctx->scene->objects[hit.object];
        if (!scene_object_side_is_front(obj, hit.side)) {
            out->back_face = 1;
            out->back_object = hit.object;
            if (ctx->deviation)
                radiance -= render_b0_term(ctx, &path, scatter, distance_m);
            return radiance;
        }
        radiance += render_emission(ctx, hit.object, hit.cos_theta, &path, distance_m, scatter);
        bool shell = obj->type == OBJECT_SHELL;
        bool straight =
            shell && ctx->scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        render_gather(ctx, &hit, dir, &path, scatter, distance_m, sample_sr, shell && !straight,
                      &radiance, out);
        vec3 in_dir = dir;
        if (render_mirror(ctx, &hit, &path, &dir, &origin_m, out)) {
            if (!straight) {
                ignore_object = hit.object;
                ignore_triangle = hit.triangle;
                crossings++;
                continue;
            }
            /* a mirror that also lets light straight through: the mirror branch here,
             * then on straight (path holds the bounce only in the branch) */
            render_path branch = path;
            path.n--;
            if (path.n < RENDER_MIRROR_BRANCHES)
                radiance += render_photon_map_trace(ctx, origin_m, dir, hit.object, hit.triangle,
                                                    branch, distance_m, scatter, sample_sr, out);
            else
                out->truncated = 1;
            dir = in_dir;
        }
        if (!straight)
            return radiance;
        if (path.n == RENDER_MAX_CROSSINGS) {
            out->truncated = 1;
            return radiance;
        }
        path.object[path.n] = hit.object;
        path.mu[path.n] = hit.cos_theta;
        path.reflected[path.n] = false;
        path.n++;
        crossings++;
        origin_m = accel_offset_origin(ctx->accel, &hit, dir);
        ignore_object = hit.object;
        ignore_triangle = hit.triangle;
    }
}

void render_photon_map_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
                              const render_target *t, render_sample *out)
{
    render_path path = {.n = 0};
    double l = render_photon_map_trace(ctx, origin_m, dir, ACCEL_NO_OBJECT, 0, path, 0.0, NULL,
                                       sample_sr, out);
    if (ctx->deviation)
        l += ctx->b0_mean;
    render_add_all(t, l);
}
