/* Rendering a sensor's channel images (physics.md "Rendering phase" and "Integrators"),
 * and its truth images.
 *
 * The `path` estimator. With B0(nu) = B_nu(T0) for a reference temperature T0, the
 * radiance leaving a front side obeys (physics.md "Surfaces", Kirchhoff or explicit eps)
 *   L - B0 = [eps B(T) - A B0] + R (L_R - B0) + T (L_T - B0),   A = 1 - R - T(theta),
 * and across a free path of transmittance tau, L_in - B0 = tau (L_far - B0) + (tau - 1) B0;
 * nothing hit, or the back of a one-sided solid, is L - B0 = -B0. A path samples nu from
 * g_c, adds the bracket at every hit (times the product beta of the transmittances so
 * far) and continues by Russian roulette with probabilities R (cosine reflection) and
 * T(theta) (straight: unchanged; diffuse: exit mu ~ T(mu) mu), which makes the BRDF and
 * BTDF weights exactly 1. The estimate is Bbar0 + the sum, Bbar0 the band mean of B0 by
 * the channel quadrature; E[B0(nu)] = Bbar0, so it is unbiased for the band mean of L
 * for any T0 (B0 is an additive control variate, in space and in frequency).
 *
 * Two refinements at the sample's first hit, which all its paths share: the terms of
 * the first free path and the first hit are known functions of nu there, so they enter
 * by their band mean (the channel quadrature, as photon-map's emission), not at the
 * path's nu; and the path splits there (a reflected branch weighted R, a transmitted one
 * weighted T(theta)) instead of playing roulette.
 *
 * In an isothermal enclosure at T0 every bracket is exactly 0, so every path returns
 * Bbar0: N_c = 1 to rounding. T0 is the temperature of the object with the largest
 * area x sides x hemispherical emissivity at the channel centre (the walls of a room). */
#include "sensor/render.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/rng.h"
#include "photon/emission.h"
#include "physics/channel.h"
#include "physics/optics.h"
#include "physics/planck.h"
#include "sensor/camera.h"

/* Scenes with at most this many objects get final-gather's table of band means per pair
 * of objects (render_context.pair_mean). */
#define RENDER_PAIR_OBJECTS 256

/* What every sample of one channel needs, precomputed once: the channel quadrature for
 * the emission term's band mean, and the optics and Planck radiance of every object at
 * every node. Read-only while rendering. */
typedef struct render_context {
    const thz_scene *scene;
    const accel *accel;
    const photon_map *map;
    const thz_channel *channel;
    uint32_t channel_index;
    uint64_t seed;
    size_t k;                /* gather_min_photons */
    size_t k_secondary;      /* final-gather: photons of a secondary hit's k-nearest disk */
    channel_quadrature quad; /* nodes and normalised weights of g_c */
    double *planck;          /* [object * quad.n + node]: B_nu(T_object), W m^-2 sr^-1 Hz^-1 */
    optics_point *optics;    /* [object * quad.n + node] */
    double *alpha_per_m;     /* [node]: atmospheric attenuation, 1/m */
    double *emission_mean;   /* [object]: band mean of eps B when eps does not depend on the
                                angle (solids, explicit eps); NAN for the others */
    bool *scatters;          /* [object]: R > 0 somewhere, or a diffuse shell */
    double *tbar;            /* [object * quad.n + node]: T-bar of diffuse shells, else 0 */
    bool atmosphere;         /* some node has alpha > 0 */
    double t0_k;             /* reference temperature T0, K: path's, or the photon map's */
    double b0_mean;          /* band mean of B(T0) */
    double *b0;              /* [node] B_nu(T0) */
    double *source_mean;     /* [object] band mean of eps B - A B0 for solids; NAN for
                                shells (angle-dependent) */
    bool deviation;          /* photon-map, final-gather: the map holds L - B(T0), T0 > 0,
                                so every source term is eps B - A B0 (escapes, back faces,
                                the air: minus B0) and the sample adds B0 back */
    double *pair_mean;       /* final-gather, [x * n_objects + y]: the band mean of
                                R_x (eps_y B_y - A_y B0) for solid y (else NAN), what a
                                reflected gather ray from x adds at y without shells or
                                air between; NULL beyond RENDER_PAIR_OBJECTS objects */
    bool emitting;           /* emitting atmosphere (docs/atmosphere.md) */
    bool air_terms;          /* render_air contributes: emitting, or deviation */
    double *air_planck;      /* air_terms: [node] B_nu(T_air), 0 for non-emitting air */
    double *bg_planck;       /* air_terms: [node] escape radiance B_nu(T_background), or 0 */
} render_context;

/* The `straight` shells a sample ray has passed through: the path weight at frequency nu
 * is the product of their T(theta) at nu. */
typedef struct render_path {
    size_t n;
    uint32_t object[RENDER_MAX_CROSSINGS];
    double mu[RENDER_MAX_CROSSINGS];
} render_path;

/* Counters and the photon-map variance of one sample. */
typedef struct render_sample {
    double variance;                  /* photon-map: estimated variance of its radiance (Poisson) */
    double batch[PHOTON_MAP_BATCHES]; /* the photon terms of each batch (in the radiance) */
    unsigned escaped, back_face, widened, starved, truncated;
    uint64_t paths;
} render_sample;

/* Where a sample's estimates go: est[j] += weight x (estimate j), j < n_est. */
typedef struct render_target {
    double *est;
    uint32_t n_est;
    double *batch;      /* final-gather with batches: += weight x each batch's photon terms */
    double *disk_var;   /* and += weight^2 x their disks' Poisson variance; else NULL */
    double weight;      /* 1 / n^2 */
    uint64_t rng_index; /* first index of this sample's random streams (x n_est) */
} render_target;

/* An integrator: the estimates of one sample ray. `sample_sr` is the sample's solid
 * angle Omega_S / n^2. */
typedef void (*render_sample_fn)(const render_context *ctx, vec3 origin_m, vec3 dir,
                                 double sample_sr, const render_target *t, render_sample *out);

static void render_add_all(const render_target *t, double v)
{
    for (uint32_t j = 0; j < t->n_est; j++)
        t->est[j] += t->weight * v;
}

static void render_photon_map_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                     double sample_sr, const render_target *t, render_sample *out);
static void render_final_gather_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                       double sample_sr, const render_target *t,
                                       render_sample *out);
static void render_path_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
                               const render_target *t, render_sample *out);

typedef struct render_integrator {
    thz_integrator id;
    const char *name;
    render_sample_fn sample;
    bool needs_photons;
    uint32_t purpose; /* RNG purpose; 0: no random numbers (one pass) */
} render_integrator;

static const render_integrator render_integrators[] = {
    {INTEGRATOR_PHOTON_MAP, "photon-map", render_photon_map_sample, true, 0},
    {INTEGRATOR_FINAL_GATHER, "final-gather", render_final_gather_sample, true, RNG_PURPOSE_GATHER},
    {INTEGRATOR_PATH, "path", render_path_sample, false, RNG_PURPOSE_PATH},
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
    return THZ_OK;
}

bool render_integrator_needs_photons(thz_integrator integrator)
{
    const render_integrator *it = render_find_integrator(integrator);
    return it ? it->needs_photons : true;
}

bool render_integrator_has_passes(thz_integrator integrator)
{
    const render_integrator *it = render_find_integrator(integrator);
    return it && it->purpose != 0;
}

uint32_t render_estimates_per_pass(const thz_scene *scene)
{
    switch (scene->render.integrator) {
    case INTEGRATOR_PATH:
        return scene->render.paths_per_sample > 0 ? scene->render.paths_per_sample : 1;
    case INTEGRATOR_FINAL_GATHER:
        return scene->render.gather_rays > 0 ? scene->render.gather_rays : 1;
    default:
        return 1;
    }
}

static void render_context_fini(render_context *ctx)
{
    channel_quadrature_fini(&ctx->quad);
    free(ctx->planck);
    free(ctx->optics);
    free(ctx->alpha_per_m);
    free(ctx->emission_mean);
    free(ctx->scatters);
    free(ctx->tbar);
    free(ctx->b0);
    free(ctx->source_mean);
    free(ctx->pair_mean);
    free(ctx->air_planck);
    free(ctx->bg_planck);
    memset(ctx, 0, sizeof *ctx);
}

double render_reference_temperature_k(const thz_scene *scene, size_t channel)
{
    const thz_channel *ch = &scene->channels[channel];
    double best = -1.0, t0 = 0.0;
    for (size_t o = 0; o < scene->n_objects; o++) {
        const thz_object *obj = &scene->objects[o];
        optics_point op = scene_object_optics(scene, obj, ch->center_hz);
        double sides = obj->type == OBJECT_SHELL || obj->two_sided ? 2.0 : 1.0;
        double w = obj->mesh.total_area_m2 * sides * optics_mean_emissivity(&op);
        if (w > best) {
            best = w;
            t0 = obj->temperature_k;
        }
    }
    return t0;
}

static void render_pair_table(render_context *ctx);

/* T0: the photon map's when map_t0 (photon-map, final-gather), else path_t0_k when it is
 * not NAN, else render_reference_temperature_k (path). */
static thz_status render_context_init(render_context *ctx, const thz_scene *scene, const accel *a,
                                      const photon_map *map, size_t channel, bool map_t0,
                                      double path_t0_k, thz_error *err)
{
    memset(ctx, 0, sizeof *ctx);
    ctx->scene = scene;
    ctx->accel = a;
    ctx->map = map;
    ctx->channel = &scene->channels[channel];
    ctx->channel_index = (uint32_t)channel;
    ctx->seed = scene->photons.seed;
    ctx->k = scene->photons.gather_min_photons;
    ctx->k_secondary = ctx->k > RENDER_SECONDARY_K ? ctx->k : RENDER_SECONDARY_K;
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
    ctx->scatters = thz_malloc_array(n_obj, sizeof *ctx->scatters);
    ctx->b0 = thz_malloc_array(n, sizeof *ctx->b0);
    ctx->source_mean = thz_malloc_array(n_obj, sizeof *ctx->source_mean);
    ctx->tbar = thz_calloc(cells ? cells : 1, sizeof *ctx->tbar);
    if (!ctx->planck || !ctx->optics || !ctx->alpha_per_m || !ctx->emission_mean ||
        !ctx->scatters || !ctx->b0 || !ctx->source_mean || !ctx->tbar) {
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
        const thz_material *mat = &scene->materials[obj->material];
        bool angle_free = obj->type == OBJECT_SOLID || mat->emissivity.n > 0;
        double mean = 0.0;
        for (size_t k = 0; k < n; k++) {
            double nu = ctx->quad.freq_hz[k];
            optics_point *op = &ctx->optics[o * n + k];
            *op = scene_object_optics(scene, obj, nu);
            ctx->planck[o * n + k] = planck_radiance(nu, obj->temperature_k);
            mean += ctx->quad.weight[k] * optics_emissivity(op, 1.0) * ctx->planck[o * n + k];
        }
        ctx->emission_mean[o] = angle_free ? mean : NAN;
        double r_min, r_max;
        spectrum_range(&mat->reflectivity, &r_min, &r_max);
        bool diffuse = obj->type == OBJECT_SHELL && mat->transmission == TRANSMISSION_DIFFUSE;
        ctx->scatters[o] = r_max > 0.0 || diffuse;
        for (size_t k = 0; diffuse && k < n; k++)
            ctx->tbar[o * n + k] = optics_mean_transmission(&ctx->optics[o * n + k]);
    }
    ctx->t0_k = map_t0              ? photon_map_reference_temperature_k(map)
                : !isnan(path_t0_k) ? path_t0_k
                                    : render_reference_temperature_k(scene, channel);
    ctx->deviation = map_t0 && ctx->t0_k > 0.0;
    for (size_t k = 0; k < n; k++) {
        ctx->b0[k] = planck_radiance(ctx->quad.freq_hz[k], ctx->t0_k);
        ctx->b0_mean += ctx->quad.weight[k] * ctx->b0[k];
    }
    for (size_t o = 0; o < n_obj; o++) {
        double sum = 0.0;
        for (size_t k = 0; k < n; k++) {
            const optics_point *op = &ctx->optics[o * n + k];
            sum += ctx->quad.weight[k] * (optics_emissivity(op, 1.0) * ctx->planck[o * n + k] -
                                          optics_absorption(op, 1.0) * ctx->b0[k]);
        }
        ctx->source_mean[o] = scene->objects[o].type == OBJECT_SOLID ? sum : NAN;
    }
    const thz_atmosphere *atm = &scene->atmosphere;
    ctx->emitting = atm->emitting;
    ctx->air_terms = atm->emitting || ctx->deviation;
    if (ctx->air_terms) {
        ctx->air_planck = thz_malloc_array(n ? n : 1, sizeof *ctx->air_planck);
        ctx->bg_planck = thz_malloc_array(n ? n : 1, sizeof *ctx->bg_planck);
        if (!ctx->air_planck || !ctx->bg_planck) {
            render_context_fini(ctx);
            return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory for the band tables");
        }
        /* The same call as b0: air at T0 gives B_air == B0 bit for bit, so the path
         * estimator's air terms (B_air - B0)(1 - tau) vanish exactly in the furnace. */
        for (size_t k = 0; k < n; k++) {
            double nu = ctx->quad.freq_hz[k];
            ctx->air_planck[k] = atm->emitting ? planck_radiance(nu, atm->air.temperature_k) : 0.0;
            ctx->bg_planck[k] =
                atm->emitting ? planck_radiance(nu, atm->background_temperature_k) : 0.0;
        }
    }
    if (map && scene->render.integrator == INTEGRATOR_FINAL_GATHER)
        render_pair_table(ctx);
    return THZ_OK;
}

/* exp(-alpha d), 1 where alpha = 0 (also for d infinite). */
static double render_tau(double alpha_per_m, double distance_m)
{
    return alpha_per_m > 0.0 ? exp(-alpha_per_m * distance_m) : 1.0;
}

/* Distance from origin_m along dir to where the ray leaves the atmosphere's extent. */
static double render_exit_m(const render_context *ctx, vec3 origin_m, vec3 dir)
{
    const double o[3] = {origin_m.x, origin_m.y, origin_m.z}, d[3] = {dir.x, dir.y, dir.z};
    return atmosphere_extent_exit_m(&ctx->scene->atmosphere, o, d);
}

/* Product of T(theta) of the crossed straight shells at frequency freq_hz. */
static double render_path_weight(const render_context *ctx, const render_path *path, double freq_hz)
{
    double w = 1.0;
    for (size_t i = 0; i < path->n; i++) {
        const thz_object *obj = &ctx->scene->objects[path->object[i]];
        optics_point o = scene_object_optics(ctx->scene, obj, freq_hz);
        w *= optics_transmission(&o, path->mu[i]);
    }
    return w;
}

/* T-bar of diffuse shell `object` at freq_hz: linear interpolation of the table at the
 * (evenly spaced) quadrature nodes inside the band, the exact value outside. T-bar is
 * smooth in frequency, so the interpolation is exact to ~1e-8 over a node spacing of
 * 0.03 sigma; it spares an exponential integral per photon term. */
static double render_tbar(const render_context *ctx, const thz_object *obj, uint32_t object,
                          double freq_hz)
{
    size_t n = ctx->quad.n;
    if (n >= 2) {
        double f0 = ctx->quad.freq_hz[0], step = ctx->quad.freq_hz[1] - f0;
        double x = (freq_hz - f0) / step;
        if (x >= 0.0 && x < (double)(n - 1)) {
            size_t i = (size_t)x;
            double t = x - (double)i;
            const double *tb = &ctx->tbar[(size_t)object * n];
            return tb[i] + t * (tb[i + 1] - tb[i]);
        }
    }
    optics_point o = scene_object_optics(ctx->scene, obj, freq_hz);
    return optics_mean_transmission(&o);
}

/* The scattering at a final-gather vertex x, as a weight on whatever arrives along the
 * gather ray at frequency nu: f_x(nu) cos / pdf / P(branch), with the direction and the
 * branch drawn at the gather ray's frequency nu_j. */
typedef struct render_scatter {
    const thz_material *material;
    const thz_object *object;
    uint32_t object_index;
    bool transmitted;  /* diffuse transmission (else Lambertian reflection) */
    double mu_o;       /* |cos| of the direction towards the sensor at x */
    double mu_i;       /* |cos| of the gather ray at x */
    double pdf_ratio;  /* transmitted: Tbar(nu_j) / T(nu_j, mu_i) */
    double inv_branch; /* 1 / P(branch) */
} render_scatter;

static double render_scatter_weight(const render_context *ctx, const render_scatter *s, double nu)
{
    if (!s)
        return 1.0;
    if (!s->transmitted)
        return spectrum_eval(&s->material->reflectivity, nu) * s->inv_branch;
    /* f_T cos_i / pdf = T(nu,mu_i) T(nu,mu_o) / Tbar(nu) x Tbar(nu_j) / T(nu_j,mu_i) */
    optics_point o = scene_object_optics(ctx->scene, s->object, nu);
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
    for (size_t i = 0; i < path->n && w != 0.0; i++)
        w *= optics_transmission(&ctx->optics[(size_t)path->object[i] * n + k], path->mu[i]);
    return w;
}

/* Band mean of eps(theta) B_nu(T) at a hit (deviation: eps B - A(theta) B0; no cos
 * factor: physics.md "Surfaces") times exp(-alpha d), the straight-shell path weight and
 * the first vertex's scattering s (may be NULL; final-gather's secondary hits), all at
 * each quadrature node: what the sensor sees carries no band noise of B. Without shells
 * or air between, the band means come from the tables (emission_mean or source_mean for
 * the sample's own hit, pair_mean for a reflected gather ray). */
static double render_emission(const render_context *ctx, uint32_t object, double mu,
                              const render_path *path, double distance_m, const render_scatter *s)
{
    if (!(ctx->scene->objects[object].temperature_k > 0.0) && !ctx->deviation)
        return 0.0;
    if (path->n == 0 && !ctx->atmosphere) {
        if (!s) {
            double v = (ctx->deviation ? ctx->source_mean : ctx->emission_mean)[object];
            if (!isnan(v))
                return v;
        } else if (ctx->pair_mean && !s->transmitted) {
            double v = ctx->pair_mean[(size_t)s->object_index * ctx->scene->n_objects + object];
            if (!isnan(v))
                return v * s->inv_branch;
        }
    }
    size_t n = ctx->quad.n;
    const optics_point *op = &ctx->optics[(size_t)object * n];
    const double *planck = &ctx->planck[(size_t)object * n];
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        double v = optics_emissivity(&op[k], mu) * planck[k];
        if (ctx->deviation)
            v -= optics_absorption(&op[k], mu) * ctx->b0[k];
        if (ctx->atmosphere)
            v *= exp(-ctx->alpha_per_m[k] * distance_m);
        if (v != 0.0)
            sum += v * render_node_weight(ctx, path, s, k);
    }
    return s ? sum * s->inv_branch : sum;
}

/* final-gather's table of band means per pair of objects (render_context.pair_mean):
 * render_emission of solid y seen by a reflected gather ray from x, with nothing
 * between; left NULL beyond RENDER_PAIR_OBJECTS objects or without memory (then every
 * ray sums the nodes). */
static void render_pair_table(render_context *ctx)
{
    size_t n_obj = ctx->scene->n_objects;
    if (n_obj == 0 || n_obj > RENDER_PAIR_OBJECTS)
        return;
    double *table = thz_malloc_array(n_obj * n_obj, sizeof *table);
    if (!table)
        return;
    render_path none = {.n = 0};
    for (size_t x = 0; x < n_obj; x++) {
        render_scatter s = {.object_index = (uint32_t)x, .inv_branch = 1.0};
        for (size_t y = 0; y < n_obj; y++)
            table[x * n_obj + y] = ctx->scatters[x] && ctx->scene->objects[y].type == OBJECT_SOLID
                                       ? render_emission(ctx, (uint32_t)y, 1.0, &none, 0.0, &s)
                                       : NAN;
    }
    ctx->pair_mean = table;
}

/* Deviation: the band mean of B0 exp(-alpha d), seen through path and s: what a back
 * face (radiance 0, deviation -B0) takes away. */
static double render_b0_term(const render_context *ctx, const render_path *path,
                             const render_scatter *s, double distance_m)
{
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
static double render_air(const render_context *ctx, const render_path *path,
                         const render_scatter *s, double d0_m, double d1_m, bool escaped)
{
    if (!ctx->air_terms || (!escaped && !ctx->atmosphere))
        return 0.0; /* without attenuation a free path adds nothing */
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
    double nu = (double)p->freq_hz;
    const thz_scene *scene = g->ctx->scene;
    double f;
    if (!g->transmitted) {
        f = spectrum_eval(&scene->materials[g->obj->material].reflectivity, nu) / M_PI;
    } else {
        /* f_T = T(theta_p) T(theta_o) / (pi T-bar): the reciprocal BTDF */
        optics_point o = scene_object_optics(scene, g->obj, nu);
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
    photon_map_radius(g->ctx->map, object, seen_side, position, g->radius2_m2, render_gather_visit,
                      g);
    if (with_other_side) {
        g->transmitted = true;
        photon_map_radius(g->ctx->map, object, 1 - seen_side, position, g->radius2_m2,
                          render_gather_visit, g);
    }
}

/* The k-nearest search by radius queries: the photons of one object within a radius,
 * with their squared distances, collected in a bounded buffer; the radius is bisected
 * (in r^2, geometrically) until the buffer holds at least k and at most its capacity.
 * The k-th smallest distance in the buffer is then the k-th nearest photon's, and the
 * photons strictly inside it are those of the buffer below it: one or two cheap radius
 * queries instead of a k-nearest traversal and a radius query (about half of
 * final-gather's time). The result is that of photon_map_kth_distance2 exactly, whatever
 * the first guess. */
#define RENDER_KNN_CAP 2048

#define RENDER_KNN_TRIES 48

typedef struct render_knn_entry {
    double d2;
    const photon_record *p;
    int other_side; /* the side not seen (diffuse shells: transmitted photons) */
} render_knn_entry;

typedef struct render_knn_buffer {
    render_knn_entry e[RENDER_KNN_CAP];
    size_t n;     /* entries stored (<= RENDER_KNN_CAP) */
    size_t total; /* photons within the radius, stored or not */
    double radius2_m2;
    int other_side;
} render_knn_buffer;

static void render_knn_visit(void *vb, const photon_record *p, double distance2_m2)
{
    render_knn_buffer *b = vb;
    if (!(distance2_m2 <= b->radius2_m2))
        return;
    if (b->n < RENDER_KNN_CAP)
        b->e[b->n++] = (render_knn_entry){distance2_m2, p, b->other_side};
    b->total++;
}

/* The k-th smallest of n values (k >= 1, n >= k); reorders v. */
static double render_kth_smallest(double *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1, want = k - 1;
    while (lo < hi) {
        double pivot = v[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                double t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (want <= j)
            hi = j;
        else if (want >= i)
            lo = i;
        else
            return v[want];
    }
    return v[want];
}

/* Fills b with the photons of `object` (sides in `mask`, seen side first) within the k-th
 * nearest photon's distance or somewhat beyond, and returns that squared distance; NAN
 * when the search does not settle (the caller falls back to the k-nearest traversal),
 * INFINITY when the object holds fewer than k photons. */
static double render_knn_collect(const render_context *ctx, uint32_t object, int seen_side,
                                 unsigned mask, vec3 position, size_t k, render_knn_buffer *b,
                                 double *scratch)
{
    size_t available = photon_map_object_count(ctx->map, object, mask);
    if (available < k)
        return INFINITY;
    const thz_object *obj = &ctx->scene->objects[object];
    double sides = (mask & 3u) == 3u ? 2.0 : 1.0;
    double area = obj->mesh.total_area_m2 * sides;
    /* first guess: k photons at the object's mean density (right at once for about two
     * thirds of final-gather's secondary hits on the paper's scene, 1.4 queries on
     * average) */
    double r2 = area > 0.0 ? (double)k * area / ((double)available * M_PI) : 1.0;
    double lo = 0.0, hi = INFINITY; /* too few photons within lo, too many within hi */
    for (int tries = 0; tries < RENDER_KNN_TRIES; tries++) {
        b->n = b->total = 0;
        b->radius2_m2 = r2;
        for (int pass = 0; pass < 2; pass++) {
            int side = pass == 0 ? seen_side : 1 - seen_side;
            if (!(mask >> side & 1u))
                continue;
            b->other_side = side != seen_side;
            photon_map_radius(ctx->map, object, side, position, r2, render_knn_visit, b);
        }
        if (b->total < k) {
            lo = r2;
            r2 = isfinite(hi) ? sqrt(lo * hi)
                              : r2 * (b->total ? 2.0 * (double)k / (double)b->total : 16.0);
        } else if (b->total > RENDER_KNN_CAP) {
            hi = r2;
            r2 = lo > 0.0 ? sqrt(lo * hi) : r2 * 0.5 * (double)RENDER_KNN_CAP / (double)b->total;
        } else {
            for (size_t i = 0; i < b->n; i++)
                scratch[i] = b->e[i].d2;
            return render_kth_smallest(scratch, b->n, k);
        }
        if (!(r2 > 0.0) || !isfinite(r2))
            break;
    }
    return NAN;
}

/* L_R (+ L_T for diffuse shells) at the hit by density estimation over the sample's
 * footprint (sample_sr > 0), widened to the k-th nearest photon when it holds fewer than
 * k; sample_sr = 0 asks for the k-th nearest radius directly. Adds the estimate to
 * *radiance and its Poisson variance to out->variance. */
static void render_gather(const render_context *ctx, const accel_hit *hit, const render_path *path,
                          const render_scatter *scatter, double distance_m, double sample_sr,
                          bool diffuse_shell, double *radiance, render_sample *out)
{
    if (!ctx->map)
        return;
    const thz_object *obj = &ctx->scene->objects[hit->object];
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
    };
    size_t k = sample_sr > 0.0 ? ctx->k : ctx->k_secondary;
    render_gather_pass(&g, hit->object, hit->side, diffuse_shell, hit->position_m);
    if (g.count < k) {
        unsigned mask = 1u << hit->side;
        if (diffuse_shell)
            mask |= 1u << (1 - hit->side);
        render_knn_buffer b;
        double scratch[RENDER_KNN_CAP];
        double rk2 =
            render_knn_collect(ctx, hit->object, hit->side, mask, hit->position_m, k, &b, scratch);
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
    double area = M_PI * g.radius2_m2;
    *radiance += g.sum / area;
    out->variance += g.sum2 / (area * area);
    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
        out->batch[b] += g.batch[b] / area;
}

/* The photon-map radiance along a ray (physics.md "Rendering phase"): emission and the
 * photon terms at the first hit, continued through straight shells. `path` and
 * `distance_m` carry what lies between the sensor and `origin_m` (final-gather's
 * secondary rays start with the first vertex's); `scatter` (may be NULL) weights every
 * term by the first vertex's scattering at the term's frequency. */
static double render_photon_map_trace(const render_context *ctx, vec3 origin_m, vec3 dir,
                                      uint32_t ignore_object, uint32_t ignore_triangle,
                                      render_path path, double distance_m,
                                      const render_scatter *scatter, double sample_sr,
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
            if (ctx->deviation)
                radiance -= render_b0_term(ctx, &path, scatter, distance_m);
            return radiance;
        }
        radiance += render_emission(ctx, hit.object, hit.cos_theta, &path, distance_m, scatter);
        bool shell = obj->type == OBJECT_SHELL;
        bool straight =
            shell && ctx->scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        render_gather(ctx, &hit, &path, scatter, distance_m, sample_sr, shell && !straight,
                      &radiance, out);
        if (!straight)
            return radiance;
        if (path.n == RENDER_MAX_CROSSINGS) {
            out->truncated = 1;
            return radiance;
        }
        path.object[path.n] = hit.object;
        path.mu[path.n] = hit.cos_theta;
        path.n++;
        crossings++;
        origin_m = accel_offset_origin(ctx->accel, &hit, dir);
        ignore_object = hit.object;
        ignore_triangle = hit.triangle;
    }
}

/* The origin of a scattered ray leaving `hit` along dir: the hit point moved by 1e-5 of
 * its distance towards the triangle's centroid, then off the surface by the accel's
 * rule. A hit on the edge between two faces (the corners of a room, which camera rays
 * along the image diagonals meet exactly) lies on the neighbouring face's plane, and a
 * ray from there towards that face would slip out of a closed enclosure; the nudge keeps
 * it inside. It moves the point by far less than any gather disk. */
static vec3 render_leave(const render_context *ctx, const accel_hit *hit, vec3 dir)
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

static void render_photon_map_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                     double sample_sr, const render_target *t, render_sample *out)
{
    render_path path = {.n = 0};
    double l = render_photon_map_trace(ctx, origin_m, dir, ACCEL_NO_OBJECT, 0, path, 0.0, NULL,
                                       sample_sr, out);
    if (ctx->deviation)
        l += ctx->b0_mean;
    render_add_all(t, l);
}

/* One gather ray from first vertex `hit` (object obj, seen through `path`, at distance
 * distance_m from the sensor): its estimate of the scattered radiance towards the sensor. */
static double render_gather_ray(const render_context *ctx, const accel_hit *hit,
                                const thz_object *obj, bool diffuse_shell, const render_path *path,
                                double distance_m, rng_stream *rng, render_sample *out,
                                render_sample *sec)
{
    const thz_material *mat = &ctx->scene->materials[obj->material];
    double nu_j = channel_sample_hz(ctx->channel, rng_uniform(rng), rng_uniform(rng));
    optics_point o = scene_object_optics(ctx->scene, obj, nu_j);
    double r = o.reflectivity;
    double tr = diffuse_shell ? optics_transmission(&o, hit->cos_theta) : 0.0;
    if (!(r + tr > 0.0))
        return 0.0;
    const float *nf = &obj->mesh.normals[3 * (size_t)hit->triangle];
    vec3 n = v3_from_floats(nf);
    vec3 n_seen = hit->side == 0 ? n : v3_scale(n, -1.0);
    render_scatter s = {
        .material = mat, .object = obj, .object_index = hit->object, .mu_o = hit->cos_theta};
    vec3 dir;
    if (rng_uniform(rng) * (r + tr) < r) {
        s.inv_branch = (r + tr) / r;
        double mu = sqrt(1.0 - rng_uniform(rng));
        dir = emission_direction(n_seen, mu, rng_uniform(rng));
        s.mu_i = mu;
    } else {
        s.transmitted = true;
        s.inv_branch = (r + tr) / tr;
        double mu;
        if (!optics_sample_transmission_mu(&o, emission_uniform, rng, &mu))
            return 0.0;
        dir = emission_direction(v3_scale(n_seen, -1.0), mu, rng_uniform(rng));
        s.mu_i = mu;
        s.pdf_ratio = optics_mean_transmission(&o) / optics_transmission(&o, mu);
    }
    vec3 origin = render_leave(ctx, hit, dir);
    double l = render_photon_map_trace(ctx, origin, dir, hit->object, hit->triangle, *path,
                                       distance_m, &s, 0.0, sec);
    out->starved |= sec->starved;
    out->truncated |= sec->truncated;
    return l;
}

static void render_final_gather_sample(const render_context *ctx, vec3 origin_m, vec3 dir,
                                       double sample_sr, const render_target *t, render_sample *out)
{
    (void)sample_sr;
    render_path path = {.n = 0};
    double distance_m = 0.0;
    uint32_t ignore_object = ACCEL_NO_OBJECT, ignore_triangle = 0;
    if (ctx->deviation)
        render_add_all(t, ctx->b0_mean);
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
            if (ctx->deviation)
                render_add_all(t, -render_b0_term(ctx, &path, NULL, distance_m));
            return;
        }
        render_add_all(t, render_emission(ctx, hit.object, hit.cos_theta, &path, distance_m, NULL));
        bool shell = obj->type == OBJECT_SHELL;
        bool straight =
            shell && ctx->scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        if (ctx->scatters[hit.object]) {
            /* streams: the sample's, one per gather ray; crossings of straight shells
             * shift them so that each vertex has its own */
            for (uint32_t j = 0; j < t->n_est; j++) {
                rng_stream rng;
                rng_init(&rng, ctx->seed, ctx->channel_index, RNG_PURPOSE_GATHER,
                         (t->rng_index + j) * (RENDER_MAX_CROSSINGS + 1) + path.n);
                render_sample sec = {.variance = 0.0};
                t->est[j] += t->weight * render_gather_ray(ctx, &hit, obj, shell && !straight,
                                                           &path, distance_m, &rng, out, &sec);
                if (t->batch) {
                    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
                        t->batch[b] += t->weight * sec.batch[b];
                    *t->disk_var += t->weight * t->weight * sec.variance;
                }
            }
            out->paths += t->n_est;
        }
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

/* A scattered direction at `hit` (unit normal n_seen towards the side the ray came from):
 * cosine-distributed on that side (reflection), or leaving the other side with
 * mu ~ T(mu) mu (diffuse transmission). False if T is 0 there (cannot happen after a
 * transmission event). */
static bool render_scatter_dir(const optics_point *o, vec3 n_seen, bool transmitted,
                               rng_stream *rng, vec3 *dir)
{
    if (!transmitted) {
        *dir = emission_direction(n_seen, sqrt(1.0 - rng_uniform(rng)), rng_uniform(rng));
        return true;
    }
    double m;
    if (!optics_sample_transmission_mu(o, emission_uniform, rng, &m))
        return false;
    *dir = emission_direction(v3_scale(n_seen, -1.0), m, rng_uniform(rng));
    return true;
}

/* Continues a path leaving `from` along dir with throughput beta at frequency nu (B0 =
 * b0 there; b_air = B_nu(T_air) of an emitting atmosphere, else unused): the sum of the
 * terms of every later free path and hit (see the top of this file), with Russian
 * roulette on R and T(theta) at each hit. An emitting atmosphere turns a free path's term
 * (tau - 1) B0 into (1 - tau)(B_air - B0) and the escape term -B0 into L_escape - B0. */
static double render_path_continue(const render_context *ctx, const accel_hit *from, vec3 dir,
                                   double nu, double b0, double b_air, double beta, rng_stream *rng,
                                   render_sample *out)
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
                double a = atmosphere_alpha_per_m(&scene->atmosphere, nu);
                double tau = render_tau(a, render_exit_m(ctx, origin, dir));
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
            double tau = atmosphere_transmittance(&scene->atmosphere, nu, d);
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
        optics_point o = scene_object_optics(scene, obj, nu);
        double r = o.reflectivity;
        double tr = optics_transmission(&o, hit.cos_theta);
        double a = 1.0 - r - tr;
        double eps = o.explicit_emissivity ? o.emissivity : a;
        double bt = obj->temperature_k == ctx->t0_k ? b0 : planck_radiance(nu, obj->temperature_k);
        sum += beta * (eps * bt - a * b0);
        double u = rng_uniform(rng);
        if (!(u < r + tr))
            break; /* absorbed */
        bool transmitted = !(u < r);
        if (transmitted && scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT)
            continue; /* straight on, dir unchanged */
        const float *nf = &obj->mesh.normals[3 * (size_t)hit.triangle];
        vec3 n = v3_from_floats(nf);
        vec3 n_seen = hit.side == 0 ? n : v3_scale(n, -1.0);
        if (!render_scatter_dir(&o, n_seen, transmitted, rng, &dir))
            break;
    }
    return sum;
}

/* One path from the sample's first hit `first` (ray along dir0 from the sensor): the
 * random part of its estimate, beyond the deterministic first terms. At the first hit
 * the path splits instead of playing roulette: a reflected branch weighted R and, for
 * shells, a transmitted branch weighted T(theta), each continued by roulette. (Every path
 * of a sample shares the first hit; roulette there would add the variance of choosing
 * between what the reflection and the transmission see, the main noise of a wall that
 * reflects a warmer object.) */
static double render_path_trace(const render_context *ctx, const accel_hit *first, vec3 dir0,
                                rng_stream *rng, render_sample *out)
{
    const thz_scene *scene = ctx->scene;
    double nu = channel_sample_hz(ctx->channel, rng_uniform(rng), rng_uniform(rng));
    double b0 = planck_radiance(nu, ctx->t0_k);
    double t_air = scene->atmosphere.air.temperature_k;
    double b_air = !ctx->emitting ? 0.0 : t_air == ctx->t0_k ? b0 : planck_radiance(nu, t_air);
    double beta =
        ctx->atmosphere ? atmosphere_transmittance(&scene->atmosphere, nu, first->distance_m) : 1.0;
    const thz_object *obj = &scene->objects[first->object];
    optics_point o = scene_object_optics(scene, obj, nu);
    double r = o.reflectivity;
    double tr = optics_transmission(&o, first->cos_theta);
    const float *nf = &obj->mesh.normals[3 * (size_t)first->triangle];
    vec3 n = v3_from_floats(nf);
    vec3 n_seen = first->side == 0 ? n : v3_scale(n, -1.0);
    double sum = 0.0;
    vec3 dir;
    if (r > 0.0 && render_scatter_dir(&o, n_seen, false, rng, &dir))
        sum += r * render_path_continue(ctx, first, dir, nu, b0, b_air, beta, rng, out);
    if (tr > 0.0) {
        bool straight = scene->materials[obj->material].transmission == TRANSMISSION_STRAIGHT;
        dir = dir0;
        if (straight || render_scatter_dir(&o, n_seen, true, rng, &dir))
            sum += tr * render_path_continue(ctx, first, dir, nu, b0, b_air, beta, rng, out);
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
        double a = optics_absorption(&op[k], hit->cos_theta);
        double eps = optics_emissivity(&op[k], hit->cos_theta);
        double free_path = ctx->emitting ? (1.0 - tau) * (ctx->air_planck[k] - ctx->b0[k])
                                         : (tau - 1.0) * ctx->b0[k];
        sum += ctx->quad.weight[k] * (free_path + tau * (eps * planck[k] - a * ctx->b0[k]));
    }
    return sum;
}

static void render_path_sample(const render_context *ctx, vec3 origin_m, vec3 dir, double sample_sr,
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
        if (ctx->emitting)
            render_add_all(t, render_air(ctx, &none, NULL, 0.0, first.distance_m, false));
        return;
    }
    double fixed = ctx->b0_mean + render_path_first(ctx, &first);
    for (uint32_t j = 0; j < t->n_est; j++) {
        rng_stream rng;
        rng_init(&rng, ctx->seed, ctx->channel_index, RNG_PURPOSE_PATH, t->rng_index + j);
        t->est[j] += t->weight * (fixed + render_path_trace(ctx, &first, dir, &rng, out));
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

thz_status render_accum_init(render_accum *acc, size_t pixels, thz_error *err)
{
    memset(acc, 0, sizeof *acc);
    acc->pixels = pixels;
    acc->mean = thz_calloc(pixels ? pixels : 1, sizeof *acc->mean);
    acc->m2 = thz_calloc(pixels ? pixels : 1, sizeof *acc->m2);
    if (!acc->mean || !acc->m2) {
        render_accum_fini(acc);
        return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory for %zu pixel statistics",
                             pixels);
    }
    return THZ_OK;
}

void render_accum_fini(render_accum *acc)
{
    free(acc->mean);
    free(acc->m2);
    free(acc->batch);
    free(acc->disk_var);
    memset(acc, 0, sizeof *acc);
}

double render_accum_stderr(const render_accum *acc, size_t p)
{
    if (acc->poisson)
        return sqrt(acc->m2[p]);
    if (acc->n < 2)
        return 0.0;
    double n = (double)acc->n;
    double var = acc->m2[p] / ((n - 1.0) * n);
    if (acc->batch) {
        const double *s = &acc->batch[p * PHOTON_MAP_BATCHES];
        double nb = (double)PHOTON_MAP_BATCHES, mean = 0.0, ss = 0.0;
        for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
            mean += s[b];
        mean /= nb;
        for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
            ss += (s[b] - mean) * (s[b] - mean);
        /* Z_b = B s_b / N estimates the photon part alone; var of their mean */
        double map_var = ss * nb * nb / (n * n) / (nb - 1.0) / nb;
        double diag = acc->disk_var[p] / (n * n);
        if (map_var > diag)
            var += map_var - diag;
    }
    return sqrt(var);
}

/* The random-stream index of estimate 0 of sample `sample` (of `samples` per pass) of
 * sensor `sensor` in pass `pass`, with J estimates per sample: the fold of the four
 * indices (unique below 2^64 estimates in all). */
static uint64_t render_rng_index(const thz_scene *scene, size_t sensor, uint32_t pass,
                                 uint64_t samples, uint64_t sample, uint32_t j_count)
{
    uint64_t unit = (uint64_t)pass * scene->n_sensors + sensor;
    return (unit * samples + sample) * j_count;
}

thz_status render_sensor_channel_pass(const thz_scene *scene, const accel *a, const photon_map *map,
                                      size_t channel, size_t sensor, uint32_t pass,
                                      render_accum *acc, const render_options *opt,
                                      render_stats *stats, thz_error *err)
{
    double t0 = thz_now_s();
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (channel >= scene->n_channels || sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "render: channel %zu or sensor %zu out of range", channel, sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (acc->pixels != (size_t)sn->columns * sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: statistics do not match sensor '%s'",
                             sn->name);
    thz_status st = render_integrator_check(scene->render.integrator, err);
    if (st != THZ_OK)
        return st;
    const render_integrator *integ = render_find_integrator(scene->render.integrator);
    if (integ->needs_photons && !map)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: integrator '%s' needs a photon map",
                             integ->name);
    if (integ->purpose == 0 && pass > 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "render: integrator '%s' is deterministic given its photon map; "
                             "more passes cannot lower its noise (more photons do)",
                             integ->name);
    if (pass != acc->passes)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: pass %u out of order (expected %u)",
                             pass, acc->passes);
    camera cam;
    st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    uint32_t n_est = integ->purpose ? render_estimates_per_pass(scene) : 1;
    int threads = render_threads(opt);
    render_context ctx;
    double path_t0_k = opt && opt->path_t0_set ? opt->path_t0_k : NAN;
    if (!(path_t0_k >= 0.0) && !isnan(path_t0_k))
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: path T0 %g K is negative", path_t0_k);
    st = render_context_init(&ctx, scene, a, map, channel, integ->needs_photons, path_t0_k, err);
    if (st != THZ_OK)
        return st;
    if (opt && opt->use_seed)
        ctx.seed = opt->seed;
    /* final-gather with a batched map: the map's own noise per pixel (render_accum) */
    bool batched = scene->render.integrator == INTEGRATOR_FINAL_GATHER &&
                   photon_map_batches(map) == PHOTON_MAP_BATCHES;
    if (batched && pass == 0 && !acc->batch) {
        acc->batch = thz_calloc(acc->pixels * PHOTON_MAP_BATCHES, sizeof *acc->batch);
        acc->disk_var = thz_calloc(acc->pixels ? acc->pixels : 1, sizeof *acc->disk_var);
        if (!acc->batch || !acc->disk_var) {
            render_context_fini(&ctx);
            return thz_error_set(err, THZ_ERR_NOMEM,
                                 "render: out of memory for %zu pixels' photon batches",
                                 acc->pixels);
        }
    }
    batched = batched && acc->batch;
    /* per thread: the current pixel's n_est estimates, then its batch sums and Poisson
     * variance */
    size_t per_thread = n_est + PHOTON_MAP_BATCHES + 1;
    double *scratch = thz_malloc_array((size_t)threads * per_thread, sizeof *scratch);
    if (!scratch) {
        render_context_fini(&ctx);
        return thz_error_set(err, THZ_ERR_NOMEM,
                             "render: out of memory for %u estimates x %d "
                             "threads",
                             n_est, threads);
    }

    uint32_t n = cam.oversampling, cols = cam.columns, rows = cam.rows;
    double n2 = (double)n * (double)n;
    uint64_t samples_per_pass = (uint64_t)cols * rows * n * n;
    /* Rows per block: about 64k sample estimates between progress calls (fewer parallel
     * regions: less waiting at their ends). */
    uint64_t work_per_row = (uint64_t)cols * n * n * n_est;
    uint32_t block = (uint32_t)(65536 / (work_per_row ? work_per_row : 1));
    if (block < 1)
        block = 1;
    uint64_t n_samples = 0, n_escaped = 0, n_back = 0, n_widened = 0, n_starved = 0,
             n_truncated = 0, n_paths = 0;
    double n_b = (double)n_est, n_a = (double)acc->n, n_ab = n_a + n_b;

    if (render_report(opt, scene, channel, 0, rows)) {
        st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
        goto cleanup;
    }
    for (uint32_t r0 = 0; r0 < rows; r0 += block) {
        uint32_t r1 = r0 + block < rows ? r0 + block : rows;
        int64_t first = (int64_t)r0 * cols, last = (int64_t)r1 * cols;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) \
    reduction(+ : n_samples, n_escaped, n_back, n_widened, n_starved, n_truncated, n_paths)
        for (int64_t px = first; px < last; px++) {
            double *est = &scratch[(size_t)omp_get_thread_num() * per_thread];
            for (size_t j = 0; j < per_thread; j++)
                est[j] = 0.0;
            double *pixel_batch = batched ? est + n_est : NULL;
            double *pixel_disk_var = batched ? est + n_est + PHOTON_MAP_BATCHES : NULL;
            uint32_t row = (uint32_t)(px / cols), col = (uint32_t)(px % cols);
            double omega_sr = camera_pixel_solid_angle(&cam, col, row);
            double sample_sr = omega_sr / n2;
            double var_sum = 0.0;
            for (uint32_t j = 0; j < n; j++)
                for (uint32_t i = 0; i < n; i++) {
                    render_sample s = {.variance = 0.0};
                    vec3 dir = camera_sample_dir(&cam, col, row, i, j);
                    uint64_t sample = (uint64_t)px * n * n + (uint64_t)j * n + i;
                    render_target t = {
                        .est = est,
                        .n_est = n_est,
                        .batch = pixel_batch,
                        .disk_var = pixel_disk_var,
                        .weight = 1.0 / n2,
                        .rng_index =
                            render_rng_index(scene, sensor, pass, samples_per_pass, sample, n_est),
                    };
                    integ->sample(&ctx, cam.position_m, dir, sample_sr, &t, &s);
                    var_sum += s.variance;
                    n_samples++;
                    n_escaped += s.escaped;
                    n_back += s.back_face;
                    n_widened += s.widened;
                    n_starved += s.starved;
                    n_truncated += s.truncated;
                    n_paths += s.paths;
                }
            size_t p = (size_t)px;
            if (!integ->purpose) {
                acc->mean[p] = est[0];
                acc->m2[p] = var_sum / (n2 * n2);
                continue;
            }
            /* this pass's mean and squared deviations (two-pass), merged with the earlier
             * passes' (Chan et al.) */
            double shift = 0.0, m2_b = 0.0; /* about est[0]: equal estimates give 0 */
            for (uint32_t k = 1; k < n_est; k++)
                shift += est[k] - est[0];
            double mean_b = est[0] + shift / n_b;
            for (uint32_t k = 0; k < n_est; k++)
                m2_b += (est[k] - mean_b) * (est[k] - mean_b);
            double delta = mean_b - acc->mean[p];
            acc->mean[p] += delta * n_b / n_ab;
            acc->m2[p] += m2_b + delta * delta * n_a * n_b / n_ab;
            if (batched) {
                for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
                    acc->batch[p * PHOTON_MAP_BATCHES + b] += pixel_batch[b];
                acc->disk_var[p] += *pixel_disk_var;
            }
        }
        if (render_report(opt, scene, channel, r1, rows)) {
            st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
            goto cleanup;
        }
    }
    acc->n += n_est;
    acc->passes++;
    acc->poisson = integ->purpose == 0;

cleanup:
    if (stats) {
        stats->samples = n_samples;
        stats->escaped_samples = n_escaped;
        stats->back_face_samples = n_back;
        stats->widened_gathers = n_widened;
        stats->starved_gathers = n_starved;
        stats->truncated_paths = n_truncated;
        stats->paths = n_paths;
        stats->seconds = thz_now_s() - t0;
    }
    free(scratch);
    render_context_fini(&ctx);
    return st;
}

thz_status render_accum_write(const thz_scene *scene, size_t channel, size_t sensor,
                              const render_accum *acc, sensor_images *images, thz_error *err)
{
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows ||
        images->n_channels != scene->n_channels || acc->pixels != (size_t)sn->columns * sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    const thz_channel *ch = &scene->channels[channel];
    channel_quadrature q;
    st = channel_quadrature_init(&q, ch, CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK)
        return st;
    double b_ref = 0.0; /* band mean of B_nu(T_ref) */
    for (size_t k = 0; k < q.n; k++)
        b_ref += q.weight[k] * planck_radiance(q.freq_hz[k], sn->normalize_to_k);
    channel_quadrature_fini(&q);
    double bandwidth_hz = channel_bandwidth_hz(ch);
    size_t plane = channel * acc->pixels;
    for (size_t p = 0; p < acc->pixels; p++) {
        uint32_t row = (uint32_t)(p / sn->columns), col = (uint32_t)(p % sn->columns);
        double omega_sr = camera_pixel_solid_angle(&cam, col, row);
        double l = acc->mean[p]; /* L_c, W m^-2 sr^-1 Hz^-1 */
        size_t at = plane + p;
        images->radiance[at] = (float)l;
        if (images->radiance_stderr)
            images->radiance_stderr[at] = (float)render_accum_stderr(acc, p);
        images->power[at] = (float)(l * omega_sr * sn->aperture_m2 * bandwidth_hz);
        images->brightness_temperature[at] =
            l > 0.0 ? (float)planck_brightness_temperature(ch->center_hz, l) : 0.0f;
        images->normalized[at] = b_ref > 0.0 ? (float)(l / b_ref) : 0.0f;
    }
    return THZ_OK;
}

thz_status render_sensor_channel(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, size_t sensor, sensor_images *images,
                                 const render_options *opt, render_stats *stats, thz_error *err)
{
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (channel >= scene->n_channels || sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "render: channel %zu or sensor %zu out of range", channel, sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows ||
        images->n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    render_accum acc;
    thz_status st = render_accum_init(&acc, (size_t)sn->columns * sn->rows, err);
    if (st != THZ_OK)
        return st;
    st = render_sensor_channel_pass(scene, a, map, channel, sensor, 0, &acc, opt, stats, err);
    if (st == THZ_OK)
        st = render_accum_write(scene, channel, sensor, &acc, images, err);
    render_accum_fini(&acc);
    return st;
}

double render_stderr_k(double freq_hz, double tb_k, double stderr_l)
{
    if (!(tb_k > 0.0))
        return 0.0;
    double x = THZ_PLANCK_H * freq_hz / (THZ_BOLTZMANN_K * tb_k);
    double em1 = expm1(x);
    double dbdt = planck_radiance(freq_hz, tb_k) * x * (em1 + 1.0) / (em1 * tb_k);
    return stderr_l / dbdt;
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
            images->temperature_k[px] = SENSOR_NOTHING_HIT;
            images->distance_m[px] = SENSOR_NOTHING_HIT;
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
