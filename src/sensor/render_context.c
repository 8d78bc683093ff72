/* The per-channel state of the renderer: see render_context.h. */
#include "sensor/render_context.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/planck.h"
#include "sensor/integrator.h"

static void render_context_fini(render_context *ctx)
{
    channel_quadrature_fini(&ctx->quad);
    free(ctx->planck);
    free(ctx->optics);
    free(ctx->opt_fixed);
    free(ctx->opt_const);
    free(ctx->alpha_per_m);
    free(ctx->emission_mean);
    free(ctx->scatters);
    free(ctx->mirror);
    free(ctx->lookup_q);
    free(ctx->tbar);
    free(ctx->rbar);
    free(ctx->lobes);
    free(ctx->ward_scale);
    free(ctx->ward_comp);
    free(ctx->b0);
    free(ctx->source_mean);
    free(ctx->pair_mean);
    free(ctx->air_planck);
    free(ctx->bg_planck);
    photon_map_directory_destroy(ctx->dir);
    memset(ctx, 0, sizeof *ctx);
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
        /* only a constant-R Lambertian x weights y's terms by R(nu) alone, and only a solid
         * y without an index emits the same at every angle */
        const thz_material *mx = &ctx->scene->materials[ctx->scene->objects[x].material];
        bool plain_x = !mx->index && mx->reflection == REFLECTION_DIFFUSE;
        for (size_t y = 0; y < n_obj; y++) {
            const thz_object *oy = &ctx->scene->objects[y];
            table[x * n_obj + y] = ctx->scatters[x] && plain_x && oy->type == OBJECT_SOLID &&
                                           !ctx->scene->materials[oy->material].index
                                       ? render_emission(ctx, (uint32_t)y, 1.0, &none, 0.0, &s)
                                       : NAN;
        }
    }
    ctx->pair_mean = table;
}

/* The diagonal of the box around every object, sensor and the atmosphere's extent: the
 * longest straight path through the air a sensor can see along (m). */
static double render_scene_span_m(const thz_scene *scene)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t o = 0; o < scene->n_objects; o++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], scene->objects[o].mesh.bbox_min_m[a]);
            hi[a] = fmax(hi[a], scene->objects[o].mesh.bbox_max_m[a]);
        }
    for (size_t s = 0; s < scene->n_sensors; s++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], scene->sensors[s].position_m[a]);
            hi[a] = fmax(hi[a], scene->sensors[s].position_m[a]);
        }
    const thz_atmosphere *atm = &scene->atmosphere;
    for (int a = 0; a < 3 && atm->has_extent; a++) {
        lo[a] = fmin(lo[a], atm->extent_min_m[a]);
        hi[a] = fmax(hi[a], atm->extent_max_m[a]);
    }
    double d2 = 0.0;
    for (int a = 0; a < 3; a++)
        d2 += hi[a] > lo[a] ? (hi[a] - lo[a]) * (hi[a] - lo[a]) : 0.0;
    return sqrt(d2);
}

/* The air's transmittances exp(-alpha d) over the scene's span and a quarter, a
 * sixteenth and a 64th of it: what a band mean through air whose attenuation has lines
 * must resolve between the knots. */
#define RENDER_AIR_PATHS 4
typedef struct render_air_paths {
    const thz_atmosphere *atm;
    double d_m[RENDER_AIR_PATHS];
} render_air_paths;

static void render_air_transmittances(double freq_hz, void *ctx, double *values)
{
    const render_air_paths *air = ctx;
    double alpha = atmosphere_alpha_per_m(air->atm, freq_hz);
    for (int j = 0; j < RENDER_AIR_PATHS; j++)
        values[j] = exp(-alpha * air->d_m[j]);
}

/* Whether the air's attenuation varies with frequency (a constant needs no refinement). */
static bool render_air_spectral(const thz_scene *scene)
{
    atm_model m = scene->atmosphere.model;
    return m == ATM_TABLE || m == ATM_ITU_P676 || m == ATM_LINES;
}

/* The channel's quadrature, its pieces ending at the scene's spectral knots inside the
 * band (the tables' kinks are nodes) and refined where the air's transmittance varies
 * faster than the nodes resolve, so that a narrow line, tabled or in the air, is
 * integrated to ~1e-7 whatever the band (physics.md "Channels": an unbiased quadrature;
 * the fixed rule missed a line sigma/5 wide in the air by 1e-3). */
static thz_status render_context_quadrature(channel_quadrature *q, const thz_scene *scene,
                                            size_t channel, thz_error *err)
{
    const thz_channel *ch = &scene->channels[channel];
    double lo, hi, *knots;
    size_t n_knots;
    channel_support_hz(ch, CHANNEL_QUADRATURE_SIGMAS, &lo, &hi);
    thz_status st = scene_spectral_knots(scene, lo, hi, &knots, &n_knots, err);
    if (st != THZ_OK)
        return st;
    render_air_paths air = {.atm = &scene->atmosphere};
    air.d_m[0] = render_scene_span_m(scene);
    for (int j = 1; j < RENDER_AIR_PATHS; j++)
        air.d_m[j] = 0.25 * air.d_m[j - 1];
    channel_structure s = {RENDER_AIR_PATHS, render_air_transmittances, &air};
    bool refine = render_air_spectral(scene) && air.d_m[0] > 0.0;
    st = channel_quadrature_init_knots(q, ch, CHANNEL_QUADRATURE_NODES, knots, n_knots,
                                       refine ? &s : NULL, err);
    free(knots);
    return st;
}

/* T0: the photon map's when map_t0 (photon-map, final-gather), else path_t0_k when it is
 * not NAN, else scene_reference_temperature_k (path). */
static thz_status render_context_init(render_context *ctx, const thz_scene *scene, const accel *a,
                                      const photon_map *map, size_t channel, bool map_t0,
                                      double path_t0_k, int threads, thz_error *err)
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
    thz_status st = render_context_quadrature(&ctx->quad, scene, channel, err);
    if (st != THZ_OK)
        return st;
    size_t n = ctx->quad.n, n_obj = scene->n_objects;
    size_t cells = n_obj * n;
    if (n_obj && cells / n_obj != n)
        return thz_error_set(err, THZ_ERR_LIMIT, "render: too many objects (%zu)", n_obj);
    ctx->planck = thz_malloc_array(cells, sizeof *ctx->planck);
    ctx->optics = thz_malloc_array(cells, sizeof *ctx->optics);
    ctx->opt_fixed = thz_calloc(n_obj ? n_obj : 1, sizeof *ctx->opt_fixed);
    ctx->opt_const = thz_calloc(n_obj ? n_obj : 1, sizeof *ctx->opt_const);
    ctx->alpha_per_m = thz_malloc_array(n, sizeof *ctx->alpha_per_m);
    ctx->emission_mean = thz_malloc_array(n_obj, sizeof *ctx->emission_mean);
    ctx->scatters = thz_malloc_array(n_obj, sizeof *ctx->scatters);
    ctx->mirror = thz_malloc_array(n_obj, sizeof *ctx->mirror);
    ctx->lookup_q = thz_malloc_array(n_obj, sizeof *ctx->lookup_q);
    ctx->b0 = thz_malloc_array(n, sizeof *ctx->b0);
    ctx->source_mean = thz_malloc_array(n_obj, sizeof *ctx->source_mean);
    ctx->tbar = thz_calloc(cells ? cells : 1, sizeof *ctx->tbar);
    ctx->rbar = thz_calloc(cells ? cells : 1, sizeof *ctx->rbar);
    ctx->lobes = thz_calloc(cells ? cells : 1, sizeof *ctx->lobes);
    ctx->ward_scale = thz_calloc(cells ? cells : 1, sizeof *ctx->ward_scale);
    ctx->ward_comp = thz_calloc(cells ? cells : 1, sizeof *ctx->ward_comp);
    if (!ctx->planck || !ctx->optics || !ctx->opt_fixed || !ctx->opt_const || !ctx->alpha_per_m ||
        !ctx->emission_mean || !ctx->scatters || !ctx->mirror || !ctx->lookup_q || !ctx->b0 ||
        !ctx->source_mean || !ctx->tbar || !ctx->rbar || !ctx->lobes || !ctx->ward_scale ||
        !ctx->ward_comp) {
        render_context_fini(ctx);
        return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory for the band tables");
    }
    for (size_t k = 0; k < n; k++) {
        ctx->alpha_per_m[k] = atmosphere_alpha_per_m(&scene->atmosphere, ctx->quad.freq_hz[k]);
        if (ctx->alpha_per_m[k] != 0.0)
            ctx->atmosphere = true;
    }
    ctx->t0_k = map_t0              ? photon_map_reference_temperature_k(map)
                : !isnan(path_t0_k) ? path_t0_k
                                    : scene_reference_temperature_k(scene, channel);
    ctx->deviation = map_t0 && ctx->t0_k > 0.0;
    for (size_t o = 0; o < n_obj; o++) {
        const thz_object *obj = &scene->objects[o];
        const thz_material *mat = &scene->materials[obj->material];
        bool angle_free = (obj->type == OBJECT_SOLID && !mat->index) || mat->emissivity.n > 0;
        ctx->opt_const[o] = scene_object_optics_constant(scene, obj);
        if (ctx->opt_const[o])
            ctx->opt_fixed[o] = scene_object_optics(scene, obj, 0.0);
        double mean = 0.0;
        for (size_t k = 0; k < n; k++) {
            double nu = ctx->quad.freq_hz[k];
            optics_point *op = &ctx->optics[o * n + k];
            *op = scene_object_optics(scene, obj, nu);
            optics_prepare(op);
            ctx->rbar[o * n + k] = optics_mean_reflectance(op);
            scene_object_lobe(scene, obj, op, &ctx->lobes[o * n + k]);
            ctx->ward_scale[o * n + k] = ctx->lobes[o * n + k].scale;
            ctx->ward_comp[o * n + k] = ctx->lobes[o * n + k].comp_norm;
            ctx->planck[o * n + k] = planck_radiance(nu, obj->temperature_k);
            mean += ctx->quad.weight[k] * optics_emissivity(op, 1.0) * ctx->planck[o * n + k];
        }
        ctx->emission_mean[o] = angle_free ? mean : NAN;
        double r_min, r_max;
        spectrum_range(&mat->reflectivity, &r_min, &r_max);
        bool diffuse = obj->type == OBJECT_SHELL && mat->transmission == TRANSMISSION_DIFFUSE;
        ctx->scatters[o] = r_max > 0.0 || diffuse || mat->index;
        ctx->mirror[o] = mat->reflection == REFLECTION_SPECULAR && (r_max > 0.0 || mat->index);
        for (size_t k = 0; (diffuse || mat->index) && k < n; k++)
            ctx->tbar[o * n + k] = optics_mean_transmission(&ctx->optics[o * n + k]);
        /* by roulette on R + T from a deviation map only (RENDER_GATHER_LOOKUP_FULL) */
        double scattered = r_max;
        for (size_t k = 0; k < n; k++)
            scattered = fmax(scattered, ctx->rbar[o * n + k] + ctx->tbar[o * n + k]);
        ctx->lookup_q[o] = !ctx->scatters[o] || !(scattered > 0.0) ? 0.0
                           : ctx->deviation ? fmin(1.0, scattered / RENDER_GATHER_LOOKUP_FULL)
                                            : 1.0;
    }
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
        const thz_object *obj = &scene->objects[o];
        ctx->source_mean[o] =
            obj->type == OBJECT_SOLID && !scene->materials[obj->material].index ? sum : NAN;
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
    if (map) {
        st = photon_map_directory_create(map, threads, &ctx->dir, err);
        if (st != THZ_OK) {
            render_context_fini(ctx);
            return st;
        }
    }
    if (map && scene->render.integrator == INTEGRATOR_FINAL_GATHER)
        render_pair_table(ctx);
    return THZ_OK;
}

thz_status render_context_create(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, const render_options *opt, render_context **out,
                                 thz_error *err)
{
    *out = NULL;
    if (channel >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: channel %zu out of range", channel);
    thz_status st = render_integrator_check(scene->render.integrator, err);
    if (st != THZ_OK)
        return st;
    const render_integrator *integ = render_integrator_find(scene->render.integrator);
    if (integ->needs_photons && !map)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: integrator '%s' needs a photon map",
                             render_integrator_name(integ->id));
    double path_t0_k = opt && opt->path_t0_set ? opt->path_t0_k : NAN;
    if (!(path_t0_k >= 0.0) && !isnan(path_t0_k))
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: path T0 %g K is negative", path_t0_k);
    render_context *ctx = thz_calloc(1, sizeof *ctx);
    if (!ctx)
        return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory");
    st = render_context_init(ctx, scene, a, map, channel, integ->needs_photons, path_t0_k,
                             opt ? opt->threads : 0, err);
    if (st != THZ_OK) {
        render_context_destroy(ctx); /* fini is safe on what init left */
        return st;
    }
    if (opt && opt->use_seed)
        ctx->seed = opt->seed;
    ctx->guided = !(opt && opt->unguided);
    ctx->integrator = integ;
    *out = ctx;
    return THZ_OK;
}

uint64_t render_context_bytes(const thz_scene *scene)
{
    /* as render_context_init allocates: planck, optics, tbar, rbar, lobes, ward_scale and
     * ward_comp per cell; the per-object arrays; the pair table */
    uint64_t nodes = CHANNEL_QUADRATURE_NODES;
    for (size_t c = 0; c < scene->n_channels; c++) {
        /* the channel's own rule (a few thousand table lookups), else a bound */
        channel_quadrature q;
        thz_error err;
        size_t n;
        if (render_context_quadrature(&q, scene, c, &err) == THZ_OK) {
            n = q.n;
            channel_quadrature_fini(&q);
        } else {
            const thz_channel *ch = &scene->channels[c];
            double lo, hi;
            channel_support_hz(ch, CHANNEL_QUADRATURE_SIGMAS, &lo, &hi);
            size_t k = scene_spectral_knots_bound(scene, lo, hi);
            n = channel_quadrature_max_nodes(ch, CHANNEL_QUADRATURE_NODES, k,
                                             render_air_spectral(scene));
        }
        nodes = n > nodes ? n : nodes;
    }
    uint64_t n_obj = scene->n_objects, cells = n_obj * nodes;
    uint64_t per_cell = 5u * sizeof(double) + sizeof(optics_point) + sizeof(brdf_lobe);
    uint64_t per_object = sizeof(optics_point) + 3u * sizeof(bool) + 3u * sizeof(double);
    uint64_t bytes = cells * per_cell + n_obj * per_object + sizeof(render_context);
    if (n_obj <= RENDER_PAIR_OBJECTS)
        bytes += n_obj * n_obj * sizeof(double);
    return bytes;
}

void render_context_destroy(render_context *ctx)
{
    if (!ctx)
        return;
    render_context_fini(ctx);
    free(ctx);
}
