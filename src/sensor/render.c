/* Rendering a sensor's channel images from a photon map (physics.md "Rendering phase"),
 * and its truth images. */
#include "sensor/render.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"
#include "physics/channel.h"
#include "physics/optics.h"
#include "physics/planck.h"
#include "sensor/camera.h"

/* What every sample of one channel needs, precomputed once: the channel quadrature for
 * the emission term's band mean, and the optics and Planck radiance of every object at
 * every node. Read-only while rendering. */
typedef struct render_context {
    const thz_scene *scene;
    const accel *accel;
    const photon_map *map;
    size_t k;                /* gather_min_photons */
    channel_quadrature quad; /* nodes and normalised weights of g_c */
    double *planck;          /* [object * quad.n + node]: B_nu(T_object), W m^-2 sr^-1 Hz^-1 */
    optics_point *optics;    /* [object * quad.n + node] */
    double *alpha_per_m;     /* [node]: atmospheric attenuation, 1/m */
    double *emission_mean;   /* [object]: band mean of eps B when eps does not depend on the
                                angle (solids, explicit eps); NAN for the others */
    bool atmosphere;         /* some node has alpha > 0 */
} render_context;

/* The `straight` shells a sample ray has passed through: the path weight at frequency nu
 * is the product of their T(theta) at nu. */
typedef struct render_path {
    size_t n;
    uint32_t object[RENDER_MAX_CROSSINGS];
    double mu[RENDER_MAX_CROSSINGS];
} render_path;

/* The result of one sample ray. */
typedef struct render_sample {
    double radiance; /* band mean of L exp(-alpha d), W m^-2 sr^-1 Hz^-1 */
    double variance; /* its estimated variance (photon terms, Poisson) */
    unsigned escaped, back_face, widened, starved, truncated;
} render_sample;

/* An integrator: the radiance seen by one sample ray. `sample_sr` is the sample's solid
 * angle Omega_S / n^2; `sample_index` identifies the sample for random streams. */
typedef void (*render_radiance_fn)(const render_context *ctx, vec3 origin_m, vec3 dir,
                                   double sample_sr, uint64_t sample_index, render_sample *out);

static void render_photon_map_radiance(const render_context *ctx, vec3 origin_m, vec3 dir,
                                       double sample_sr, uint64_t sample_index,
                                       render_sample *out);

typedef struct render_integrator {
    thz_integrator id;
    const char *name;
    render_radiance_fn radiance; /* NULL: not implemented yet */
    bool needs_photons;
} render_integrator;

static const render_integrator render_integrators[] = {
    {INTEGRATOR_PHOTON_MAP, "photon-map", render_photon_map_radiance, true},
    {INTEGRATOR_FINAL_GATHER, "final-gather", NULL, true},
    {INTEGRATOR_PATH, "path", NULL, false},
};
#define RENDER_N_INTEGRATORS (sizeof render_integrators / sizeof render_integrators[0])

static const render_integrator *render_find_integrator(thz_integrator id)
{
    for (size_t i = 0; i < RENDER_N_INTEGRATORS; i++)
        if (render_integrators[i].id == id)
            return &render_integrators[i];
    return NULL;
}

const char *render_integrator_name(thz_integrator integrator)
{
    const render_integrator *it = render_find_integrator(integrator);
    return it ? it->name : "unknown";
}

bool render_integrator_parse(const char *name, thz_integrator *out)
{
    for (size_t i = 0; i < RENDER_N_INTEGRATORS; i++)
        if (strcmp(render_integrators[i].name, name) == 0) {
            *out = render_integrators[i].id;
            return true;
        }
    return false;
}

thz_status render_integrator_check(thz_integrator integrator, thz_error *err)
{
    const render_integrator *it = render_find_integrator(integrator);
    if (!it)
        return thz_error_set(err, THZ_ERR_INPUT, "unknown integrator %d", (int)integrator);
    if (!it->radiance)
        return thz_error_set(err, THZ_ERR_INPUT, "integrator '%s' is not implemented yet",
                             it->name);
    return THZ_OK;
}

bool render_integrator_needs_photons(thz_integrator integrator)
{
    const render_integrator *it = render_find_integrator(integrator);
    return it ? it->needs_photons : true;
}

static double render_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void render_context_fini(render_context *ctx)
{
    channel_quadrature_fini(&ctx->quad);
    free(ctx->planck);
    free(ctx->optics);
    free(ctx->alpha_per_m);
    free(ctx->emission_mean);
    memset(ctx, 0, sizeof *ctx);
}

static thz_status render_context_init(render_context *ctx, const thz_scene *scene, const accel *a,
                                      const photon_map *map, size_t channel, thz_error *err)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->scene = scene;
    ctx->accel = a;
    ctx->map = map;
    ctx->k = scene->photons.gather_min_photons;
    thz_status st = channel_quadrature_init(&ctx->quad, &scene->channels[channel],
                                            CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK)
        return st;
    size_t n = ctx->quad.n, n_obj = scene->n_objects;
    size_t cells = n_obj * n;
    if (n_obj && cells / n_obj != n)
        return thz_error_set(err, THZ_ERR_LIMIT, "render: too many objects (%zu)", n_obj);
    ctx->planck = thz_malloc_array(cells, sizeof *ctx->planck);
    ctx->optics = thz_malloc_array(cells, sizeof *ctx->optics);
    ctx->alpha_per_m = thz_malloc_array(n, sizeof *ctx->alpha_per_m);
    ctx->emission_mean = thz_malloc_array(n_obj, sizeof *ctx->emission_mean);
    if (!ctx->planck || !ctx->optics || !ctx->alpha_per_m || !ctx->emission_mean) {
        render_context_fini(ctx);
        return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory for the band tables");
    }
    for (size_t k = 0; k < n; k++) {
        ctx->alpha_per_m[k] = atmosphere_alpha_per_m(&scene->atmosphere, ctx->quad.freq_hz[k]);
        if (ctx->alpha_per_m[k] != 0.0)
            ctx->atmosphere = true;
    }
    for (size_t o = 0; o < n_obj; o++) {
        const thz_object *obj = &scene->objects[o];
        bool angle_free = obj->type == OBJECT_SOLID ||
                          scene->materials[obj->material].emissivity.n > 0;
        double mean = 0.0;
        for (size_t k = 0; k < n; k++) {
            double nu = ctx->quad.freq_hz[k];
            optics_point *op = &ctx->optics[o * n + k];
            *op = scene_object_optics(scene, obj, nu);
            ctx->planck[o * n + k] = planck_radiance(nu, obj->temperature_k);
            mean += ctx->quad.weight[k] * optics_emissivity(op, 1.0) * ctx->planck[o * n + k];
        }
        ctx->emission_mean[o] = angle_free ? mean : NAN;
    }
    return THZ_OK;
}

/* Product of T(theta) of the crossed straight shells at frequency freq_hz. */
static double render_path_weight(const render_context *ctx, const render_path *path,
                                 double freq_hz)
{
    double w = 1.0;
    for (size_t i = 0; i < path->n; i++) {
        const thz_object *obj = &ctx->scene->objects[path->object[i]];
        optics_point o = scene_object_optics(ctx->scene, obj, freq_hz);
        w *= optics_transmission(&o, path->mu[i]);
    }
    return w;
}

/* Band mean of eps(theta) B_nu(T) times the path weight and exp(-alpha d) (no cos
 * factor: physics.md "Surfaces"). */
static double render_emission(const render_context *ctx, uint32_t object, double mu,
                              const render_path *path, double distance_m)
{
    if (!(ctx->scene->objects[object].temperature_k > 0.0))
        return 0.0;
    if (path->n == 0 && !ctx->atmosphere && !isnan(ctx->emission_mean[object]))
        return ctx->emission_mean[object];
    size_t n = ctx->quad.n;
    const optics_point *op = &ctx->optics[(size_t)object * n];
    const double *planck = &ctx->planck[(size_t)object * n];
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        double v = ctx->quad.weight[k] * optics_emissivity(&op[k], mu) * planck[k];
        for (size_t i = 0; i < path->n && v != 0.0; i++)
            v *= optics_transmission(&ctx->optics[(size_t)path->object[i] * n + k], path->mu[i]);
        if (ctx->atmosphere)
            v *= exp(-ctx->alpha_per_m[k] * distance_m);
        sum += v;
    }
    return sum;
}

/* Accumulator of one gather over one side of the hit object. */
typedef struct render_gather_state {
    const render_context *ctx;
    const thz_object *obj;
    vec3 normal_seen;    /* unit normal of the triangle hit, towards the sensor's side */
    double mu_o;         /* |cos theta| of the view ray */
    const render_path *path;
    double distance_m;   /* from the sensor */
    double radius2_m2;
    bool strict;         /* only photons strictly inside (widened disk) */
    bool transmitted;    /* photons of the other side of a diffuse shell: BTDF, not BRDF */
    size_t count;
    double sum, sum2;    /* sum of photon terms f Phi w exp(-alpha d), and of their squares */
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
    double nu = (double)p->freq_hz;
    const thz_scene *scene = g->ctx->scene;
    double f;
    if (!g->transmitted) {
        f = spectrum_eval(&scene->materials[g->obj->material].reflectivity, nu) / M_PI;
    } else {
        /* f_T = T(theta_p) T(theta_o) / (pi T-bar): the reciprocal BTDF */
        optics_point o = scene_object_optics(scene, g->obj, nu);
        double mu_p = fmax(fabs(along), 1e-12);
        double tbar = optics_mean_transmission(&o);
        f = tbar > 0.0
                ? optics_transmission(&o, mu_p) * optics_transmission(&o, g->mu_o) / (M_PI * tbar)
                : 0.0;
    }
    if (f == 0.0)
        return;
    double c = f * (double)p->power_w_per_hz * render_path_weight(g->ctx, g->path, nu) *
               atmosphere_transmittance(&scene->atmosphere, nu, g->distance_m);
    g->sum += c;
    g->sum2 += c * c;
}

static void render_gather_pass(render_gather_state *g, uint32_t object, int seen_side,
                               bool with_other_side, vec3 position)
{
    g->count = 0;
    g->sum = g->sum2 = 0.0;
    g->transmitted = false;
    photon_map_radius(g->ctx->map, object, seen_side, position, g->radius2_m2,
                      render_gather_visit, g);
    if (with_other_side) {
        g->transmitted = true;
        photon_map_radius(g->ctx->map, object, 1 - seen_side, position, g->radius2_m2,
                          render_gather_visit, g);
    }
}

/* L_R (+ L_T for diffuse shells) at the hit by density estimation over the sample's
 * footprint, widened to the k-th nearest photon when it holds fewer than k. */
static void render_gather(const render_context *ctx, const accel_hit *hit,
                          const render_path *path, double distance_m, double sample_sr,
                          bool diffuse_shell, render_sample *out)
{
    if (!ctx->map)
        return;
    const thz_object *obj = &ctx->scene->objects[hit->object];
    const float *nf = &obj->mesh.normals[3 * (size_t)hit->triangle];
    vec3 normal = v3_from_floats(nf);
    render_gather_state g = {
        .ctx = ctx,
        .obj = obj,
        .normal_seen = hit->side == 0 ? normal : v3_scale(normal, -1.0),
        .mu_o = hit->cos_theta,
        .path = path,
        .distance_m = distance_m,
        .radius2_m2 = sample_sr * distance_m * distance_m / (M_PI * hit->cos_theta),
    };
    render_gather_pass(&g, hit->object, hit->side, diffuse_shell, hit->position_m);
    if (g.count < ctx->k) {
        unsigned mask = 1u << hit->side;
        if (diffuse_shell)
            mask |= 1u << (1 - hit->side);
        double rk2 = photon_map_kth_distance2(ctx->map, hit->object, mask, hit->position_m,
                                              ctx->k);
        if (!isfinite(rk2) || !(rk2 > 0.0)) {
            out->starved = 1;
            return;
        }
        out->widened = 1;
        g.radius2_m2 = rk2;
        g.strict = true; /* the k-th photon lies on the boundary: k - 1 inside */
        render_gather_pass(&g, hit->object, hit->side, diffuse_shell, hit->position_m);
    }
    double area = M_PI * g.radius2_m2;
    out->radiance += g.sum / area;
    out->variance += g.sum2 / (area * area);
}

static void render_photon_map_radiance(const render_context *ctx, vec3 origin_m, vec3 dir,
                                       double sample_sr, uint64_t sample_index,
                                       render_sample *out)
{
    (void)sample_index; /* deterministic: no random numbers */
    render_path path = {.n = 0};
    double distance_m = 0.0;
    uint32_t ignore_object = ACCEL_NO_OBJECT, ignore_triangle = 0;
    for (;;) {
        accel_hit hit;
        if (!accel_intersect(ctx->accel, origin_m, dir, INFINITY, ignore_object, ignore_triangle,
                             &hit)) {
            if (path.n == 0)
                out->escaped = 1;
            return;
        }
        distance_m += hit.distance_m;
        const thz_object *obj = &ctx->scene->objects[hit.object];
        if (!scene_object_side_is_front(obj, hit.side)) {
            out->back_face = 1;
            return;
        }
        out->radiance += render_emission(ctx, hit.object, hit.cos_theta, &path, distance_m);
        bool shell = obj->type == OBJECT_SHELL;
        bool straight =
            shell && ctx->scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        render_gather(ctx, &hit, &path, distance_m, sample_sr, shell && !straight, out);
        if (!straight)
            return;
        if (path.n == RENDER_MAX_CROSSINGS) {
            out->truncated = 1;
            return;
        }
        path.object[path.n] = hit.object;
        path.mu[path.n] = hit.cos_theta;
        path.n++;
        origin_m = accel_offset_origin(ctx->accel, &hit, dir);
        ignore_object = hit.object;
        ignore_triangle = hit.triangle;
    }
}

static int render_threads(const render_options *opt)
{
    int n = opt && opt->threads > 0 ? opt->threads : omp_get_max_threads();
    return n > 0 ? n : 1;
}

/* Calls the progress callback (from the calling thread); true if it asks to stop. */
static bool render_report(const render_options *opt, const thz_scene *scene, size_t channel,
                          uint64_t done, uint64_t total)
{
    if (!opt || !opt->progress)
        return false;
    thz_progress p = {.stage = "render",
                      .channel = channel,
                      .n_channels = scene->n_channels,
                      .done = done,
                      .total = total};
    return opt->progress(opt->progress_user, &p) != 0;
}

thz_status render_sensor_channel(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, size_t sensor, sensor_images *images,
                                 const render_options *opt, render_stats *stats, thz_error *err)
{
    double t0 = render_now_s();
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (channel >= scene->n_channels || sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: channel %zu or sensor %zu out of range",
                             channel, sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows ||
        images->n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    thz_status st = render_integrator_check(scene->render.integrator, err);
    if (st != THZ_OK)
        return st;
    const render_integrator *integ = render_find_integrator(scene->render.integrator);
    if (integ->needs_photons && !map)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: integrator '%s' needs a photon map",
                             integ->name);
    camera cam;
    st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    render_context ctx;
    st = render_context_init(&ctx, scene, a, map, channel, err);
    if (st != THZ_OK)
        return st;

    const thz_channel *ch = &scene->channels[channel];
    double bandwidth_hz = channel_bandwidth_hz(ch);
    double b_ref = 0.0; /* band mean of B_nu(T_ref) */
    for (size_t k = 0; k < ctx.quad.n; k++)
        b_ref += ctx.quad.weight[k] * planck_radiance(ctx.quad.freq_hz[k], sn->normalize_to_k);

    uint32_t n = cam.oversampling, cols = cam.columns, rows = cam.rows;
    double n2 = (double)n * (double)n;
    size_t plane = (size_t)channel * rows * cols;
    /* Rows per block: about 16k samples between progress calls (cancellation latency). */
    uint64_t samples_per_row = (uint64_t)cols * n * n;
    uint32_t block = (uint32_t)(16384 / (samples_per_row ? samples_per_row : 1));
    if (block < 1)
        block = 1;
    int threads = render_threads(opt);
    uint64_t n_samples = 0, n_escaped = 0, n_back = 0, n_widened = 0, n_starved = 0,
             n_truncated = 0;

    if (render_report(opt, scene, channel, 0, rows)) {
        st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
        goto cleanup;
    }
    for (uint32_t r0 = 0; r0 < rows; r0 += block) {
        uint32_t r1 = r0 + block < rows ? r0 + block : rows;
        int64_t first = (int64_t)r0 * cols, last = (int64_t)r1 * cols;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) \
    reduction(+ : n_samples, n_escaped, n_back, n_widened, n_starved, n_truncated)
        for (int64_t px = first; px < last; px++) {
            uint32_t row = (uint32_t)(px / cols), col = (uint32_t)(px % cols);
            double omega_sr = camera_pixel_solid_angle(&cam, col, row);
            double sample_sr = omega_sr / n2;
            double l_sum = 0.0, var_sum = 0.0;
            for (uint32_t j = 0; j < n; j++)
                for (uint32_t i = 0; i < n; i++) {
                    render_sample s = {.radiance = 0.0};
                    vec3 dir = camera_sample_dir(&cam, col, row, i, j);
                    uint64_t index = (uint64_t)px * n * n + (uint64_t)j * n + i;
                    integ->radiance(&ctx, cam.position_m, dir, sample_sr, index, &s);
                    l_sum += s.radiance;
                    var_sum += s.variance;
                    n_samples++;
                    n_escaped += s.escaped;
                    n_back += s.back_face;
                    n_widened += s.widened;
                    n_starved += s.starved;
                    n_truncated += s.truncated;
                }
            double l = l_sum / n2; /* L_c, W m^-2 sr^-1 Hz^-1 */
            size_t at = plane + (size_t)px;
            images->radiance[at] = (float)l;
            if (images->radiance_stderr)
                images->radiance_stderr[at] = (float)(sqrt(var_sum) / n2);
            images->power[at] = (float)(l * omega_sr * sn->aperture_m2 * bandwidth_hz);
            images->brightness_temperature[at] =
                l > 0.0 ? (float)planck_brightness_temperature(ch->center_hz, l) : 0.0f;
            images->normalized[at] = b_ref > 0.0 ? (float)(l / b_ref) : 0.0f;
        }
        if (render_report(opt, scene, channel, r1, rows)) {
            st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
            goto cleanup;
        }
    }

cleanup:
    if (stats) {
        stats->samples = n_samples;
        stats->escaped_samples = n_escaped;
        stats->back_face_samples = n_back;
        stats->widened_gathers = n_widened;
        stats->starved_gathers = n_starved;
        stats->truncated_paths = n_truncated;
        stats->seconds = render_now_s() - t0;
    }
    render_context_fini(&ctx);
    return st;
}

thz_status render_sensor_truth(const thz_scene *scene, const accel *a, size_t sensor,
                               sensor_images *images, const render_options *opt, thz_error *err)
{
    if (sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: sensor %zu out of range", sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    int64_t n_px = (int64_t)cam.columns * cam.rows;
    int threads = render_threads(opt);
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
    for (int64_t px = 0; px < n_px; px++) {
        uint32_t row = (uint32_t)(px / cam.columns), col = (uint32_t)(px % cam.columns);
        vec3 dir = camera_pixel_center_dir(&cam, col, row);
        accel_hit hit;
        float *rgb = &images->visual_rgb[3 * (size_t)px];
        if (!accel_intersect(a, cam.position_m, dir, INFINITY, ACCEL_NO_OBJECT, 0, &hit)) {
            images->temperature_k[px] = 0.0f;
            images->distance_m[px] = 0.0f;
            images->object_id[px] = -1;
            rgb[0] = rgb[1] = rgb[2] = 0.0f;
            continue;
        }
        const thz_object *obj = &scene->objects[hit.object];
        const double *color = scene->materials[obj->material].color;
        double shade = 0.25 + 0.75 * fabs(hit.cos_theta);
        images->temperature_k[px] = (float)obj->temperature_k;
        images->distance_m[px] = (float)hit.distance_m;
        images->object_id[px] = (int32_t)hit.object;
        for (int c = 0; c < 3; c++)
            rgb[c] = (float)(color[c] * shade);
    }
    return THZ_OK;
}
