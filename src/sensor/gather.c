/* The photon-map density estimate at a hit (physics.md "Rendering phase"): the photons of
 * the object hit, on the side seen (and the other side for `diffuse` shells), within the
 * sample's footprint disk or the k-th nearest photon's (photon/knn.h), whose incoming
 * direction agrees with that side of the triangle hit. */
#include <math.h>
#include <string.h>

#include "photon/knn.h"
#include "physics/optics.h"
#include "sensor/integrator.h"

/* Accumulator of one gather over one side of the hit object. */
typedef struct render_gather_state {
    const render_context *ctx;
    const thz_object *obj;
    uint32_t object_index;
    vec3 normal_seen; /* unit normal of the triangle hit, towards the sensor's side */
    double mu_o;      /* |cos theta| of the view ray */
    const render_path *path;
    const render_scatter *scatter; /* final-gather: the first vertex's weight, or NULL */
    double distance_m;             /* from the sensor */
    double radius2_m2;
    bool strict;      /* only photons strictly inside (widened disk) */
    bool plain;       /* constant-R Lambertian reflection: f = R(nu)/pi */
    bool skip_seen;   /* a mirror: its reflection is traced, not estimated */
    brdf_frame frame; /* the frame on the seen side and the direction towards the sensor */
    vec3 w_view;
    bool transmitted; /* photons of the other side of a diffuse shell: BTDF, not BRDF */
    size_t count;
    double sum, sum2; /* sum of photon terms f Phi w exp(-alpha d), and of their squares */
    double batch[PHOTON_MAP_BATCHES]; /* sum per photon batch */
} render_gather_state;

static void render_gather_visit(void *vstate, const photon_record *p, double distance2_m2)
{
    render_gather_state *g = vstate;
    if (g->strict ? !(distance2_m2 < g->radius2_m2) : !(distance2_m2 <= g->radius2_m2))
        return;
    /* Only photons that arrived on the surface seen: travelling against the seen side's
     * normal (or along it, for the transmitted ones). Rejects photons of the opposite
     * face of a thin solid, which lie within a wide disk but light the other side. */
    vec3 dir = photon_decode_direction(p->dir_oct);
    double along = v3_dot(dir, g->normal_seen);
    if (g->transmitted ? !(along > 0.0) : !(along < 0.0))
        return;
    g->count++;
    if (!g->transmitted && g->skip_seen)
        return;
    double nu = (double)p->freq_hz;
    const thz_scene *scene = g->ctx->scene;
    double f;
    if (!g->transmitted && g->plain) {
        f = spectrum_eval(&scene->materials[g->obj->material].reflectivity, nu) / M_PI;
    } else if (!g->transmitted) {
        optics_point o;
        brdf_lobe l;
        render_lobe_at(g->ctx, g->obj, g->object_index, nu, &o, &l);
        f = brdf_eval(&l, &g->frame, v3_scale(dir, -1.0), g->w_view);
    } else {
        /* f_T = T(theta_p) T(theta_o) / (pi T-bar): the reciprocal BTDF */
        optics_point o = render_optics_at(g->ctx, g->object_index, nu);
        double mu_p = fmax(fabs(along), 1e-12);
        double tbar = render_tbar(g->ctx, g->obj, g->object_index, nu);
        f = tbar > 0.0
                ? optics_transmission(&o, mu_p) * optics_transmission(&o, g->mu_o) / (M_PI * tbar)
                : 0.0;
    }
    if (f == 0.0)
        return;
    double c = f * (double)p->power_w_per_hz * render_path_weight(g->ctx, g->path, nu) *
               atmosphere_transmittance(&scene->atmosphere, nu, g->distance_m) *
               render_scatter_weight(g->ctx, g->scatter, nu);
    g->sum += c;
    g->sum2 += c * c;
    g->batch[photon_batch(p)] += c;
}

static void render_gather_pass(render_gather_state *g, uint32_t object, int seen_side,
                               bool with_other_side, vec3 position)
{
    g->count = 0;
    g->sum = g->sum2 = 0.0;
    memset(g->batch, 0, sizeof g->batch);
    g->transmitted = false;
    if (!(g->radius2_m2 > 0.0))
        return;
    photon_map_radius_in(g->ctx->map, g->ctx->dir, object, seen_side, position, g->radius2_m2,
                         render_gather_visit, g);
    if (with_other_side) {
        g->transmitted = true;
        photon_map_radius_in(g->ctx->map, g->ctx->dir, object, 1 - seen_side, position,
                             g->radius2_m2, render_gather_visit, g);
    }
}

/* L_R (+ L_T for diffuse shells) at the hit by density estimation over the sample's
 * footprint (sample_sr > 0), widened to the k-th nearest photon when it holds fewer than
 * k; sample_sr = 0 asks for the k-th nearest radius directly. Adds the estimate to
 * *radiance and its Poisson variance to out->variance. With `scatter` (final-gather's
 * secondary hit) only with probability render_context.lookup_q, weighted by its inverse. */
void render_gather(const render_context *ctx, const accel_hit *hit, vec3 ray_dir,
                   const render_path *path, const render_scatter *scatter, double distance_m,
                   double sample_sr, bool diffuse_shell, double *radiance, render_sample *out)
{
    if (!ctx->map)
        return;
    const thz_object *obj = &ctx->scene->objects[hit->object];
    const thz_material *mat = &ctx->scene->materials[obj->material];
    if (mat->reflection == REFLECTION_SPECULAR && !diffuse_shell)
        return; /* a mirror's reflection is traced by the integrator */

    /* final-gather: the lookup only with probability q, weighted 1/q */
    double inv_q = 1.0;
    if (scatter) {
        double q = ctx->lookup_q[hit->object];
        if (!(scatter->lookup_u < q))
            return;
        inv_q = 1.0 / q;
    }
    const float *nf = &obj->mesh.normals[3 * (size_t)hit->triangle];
    vec3 normal = v3_from_floats(nf);
    render_gather_state g = {
        .ctx = ctx,
        .obj = obj,
        .object_index = hit->object,
        .normal_seen = hit->side == 0 ? normal : v3_scale(normal, -1.0),
        .mu_o = hit->cos_theta,
        .path = path,
        .scatter = scatter,
        .distance_m = distance_m,
        .radius2_m2 = sample_sr * distance_m * distance_m / (M_PI * hit->cos_theta),
        .plain = !mat->index && mat->reflection == REFLECTION_DIFFUSE,
        .skip_seen = mat->reflection == REFLECTION_SPECULAR,
        .frame = scene_triangle_frame(obj, hit->triangle, hit->side),
        .w_view = v3_scale(ray_dir, -1.0),
    };
    size_t k = sample_sr > 0.0 ? ctx->k : ctx->k_secondary;
    render_gather_pass(&g, hit->object, hit->side, diffuse_shell, hit->position_m);
    if (g.count < k) {
        unsigned mask = 1u << hit->side;
        if (diffuse_shell)
            mask |= 1u << (1 - hit->side);
        knn_buffer b;
        double scratch[KNN_CAP];
        double rk2 = knn_collect(ctx->map, ctx->dir, hit->object, obj->mesh.total_area_m2,
                                 hit->side, mask, hit->position_m, k, &b, scratch);
        bool collected = !isnan(rk2);
        if (!collected)
            rk2 = photon_map_kth_distance2(ctx->map, hit->object, mask, hit->position_m, k);
        if (!isfinite(rk2) || !(rk2 > 0.0)) {
            /* A deviation map holds no photons where no deviation arrives (an object at
             * T0 lit only by objects at T0): its estimate 0 is right, not starved. */
            if (!ctx->deviation || photon_map_object_count(ctx->map, hit->object, mask) > 0)
                out->starved = 1;
            return;
        }
        if (sample_sr > 0.0)
            out->widened = 1;
        g.radius2_m2 = rk2;
        g.strict = true; /* the k-th photon lies on the boundary: k - 1 inside */
        if (collected) {
            /* the buffer holds every photon within rk2, seen side first, in the order a
             * radius query visits them */
            g.count = 0;
            g.sum = g.sum2 = 0.0;
            memset(g.batch, 0, sizeof g.batch);
            for (size_t i = 0; i < b.n; i++) {
                g.transmitted = b.e[i].other_side;
                render_gather_visit(&g, b.e[i].p, b.e[i].d2);
            }
        } else {
            render_gather_pass(&g, hit->object, hit->side, diffuse_shell, hit->position_m);
        }
    }
    double area = M_PI * g.radius2_m2 / inv_q; /* the weight 1/q folded in */
    *radiance += g.sum / area;
    out->variance += g.sum2 / (area * area);
    double sd = sqrt(g.sum2) / area;
    out->covariance_bound += 2.0 * out->sd_sum * sd;
    out->sd_sum += sd;
    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
        out->batch[b] += g.batch[b] / area;
}
