/* Band values from the scene itself (bands_values.h): the nominal render and the
 * nuisances' renders, their class means and covariance added up. bands_variants.c
 * writes each render's scene text, bands_classes.c turns a render into the classes'
 * statistics (bands_values_internal.h). */
#include "analysis/bands_values.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "analysis/bands_progress.h"
#include "analysis/bands_values_internal.h"
#include "api/api.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/path.h"
#include "scene/scene.h"

void bands_values_fini(bands_values *v)
{
    if (v->class_names)
        for (size_t k = 0; k < v->n_classes; k++)
            free(v->class_names[k]);
    free(v->class_names);
    free(v->class_pixels);
    free(v->mean);
    free(v->cov);
    free(v->pixel_sd);
    free(v->nuisance_sd);
    free(v->mean_mc_var);
    free(v->netd_k);
    memset(v, 0, sizeof *v);
}

/* The temperature of the scene's air, K, or NaN when it has none (no air, or air that
 * neither emits nor has a state): what the nuisances hold or vary. */
static double scene_air_temperature_k(const thz_scene *scene)
{
    const thz_atmosphere *atm = &scene->atmosphere;
    return atm->has_air || atm->emitting ? atm->air.temperature_k : NAN;
}

static thz_status render_variant(thz_context *ctx, const char *text, const bands_setup *s,
                                 const char *base_dir, bands_render *out, thz_error *err)
{
    thz_scene *scene = NULL;
    thz_image *img = NULL;
    thz_status st =
        thz_scene_load_string_within(text, base_dir, s->scene_path, s->root, &scene, err);
    if (st != THZ_OK)
        return st;
    out->air_t_k = scene_air_temperature_k(scene);
    thz_run_settings rs;
    thz_run_settings_init(&rs);
    rs.integrator = "path";
    rs.has_seed = 1;
    rs.seed = s->seed;
    st = thz_render_sensor(ctx, scene, NULL, s->sensor, &rs, &img, err);
    if (st != THZ_OK)
        goto done;
    size_t pixels = (size_t)thz_image_columns(img) * thz_image_rows(img), nb = 0, ne = 0;
    const float *tb = thz_image_plane(img, THZ_PLANE_BRIGHTNESS_TEMPERATURE, &nb);
    const float *se = thz_image_plane(img, THZ_PLANE_RADIANCE_STDERR, &ne);
    const float *ids = thz_image_plane(img, THZ_PLANE_OBJECT_ID, NULL);
    out->pixels = pixels;
    out->tb = thz_malloc_array(pixels * s->n_candidates, sizeof *out->tb);
    out->stderr_l = thz_calloc(pixels * s->n_candidates, sizeof *out->stderr_l);
    out->ids = thz_malloc_array(pixels, sizeof *out->ids);
    if (!out->tb || !out->stderr_l || !out->ids || !tb || nb != s->n_candidates || !ids) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    memcpy(out->tb, tb, pixels * nb * sizeof *tb);
    if (se && ne == nb) {
        memcpy(out->stderr_l, se, pixels * nb * sizeof *se);
        for (size_t i = 0; i < pixels * nb && !out->has_stderr; i++)
            out->has_stderr = se[i] > 0.0f;
    }
    for (size_t p = 0; p < pixels; p++)
        out->ids[p] = (int32_t)ids[p];
done:
    thz_image_destroy(img);
    thz_scene_destroy(scene);
    return st;
}

static void bands_render_fini(bands_render *r)
{
    free(r->tb);
    free(r->stderr_l);
    free(r->ids);
    memset(r, 0, sizeof *r);
}

/* Renders variant `text` and puts its class means in mean (classes from its own truth:
 * a turned sensor sees them elsewhere; `fallback` for a class it no longer sees). cls
 * and count are scratch of the nominal's pixels and the classes. */
static thz_status variant_means(thz_context *ctx, const char *text, const bands_setup *s,
                                const char *base_dir, const int32_t *class_of, size_t n_obj,
                                size_t pixels, int32_t *cls, uint64_t *count, const bands_values *v,
                                const double *fallback, double *mean, double *air_t_k,
                                thz_error *err)
{
    bands_render r = {0};
    thz_status st = render_variant(ctx, text, s, base_dir, &r, err);
    if (st == THZ_OK && r.pixels != pixels) /* a variant never changes the resolution */
        st = thz_error_set(err, THZ_ERR_INTERNAL, "band values: a variant's image differs");
    if (st == THZ_OK) {
        bands_pixel_classes(&r, class_of, n_obj, v->n_classes, cls, count);
        bands_class_means(&r, cls, count, v, fallback, mean);
        *air_t_k = r.air_t_k;
    }
    bands_render_fini(&r);
    return st;
}

/* The nuisances' renders of bands_values_compute: what each needs, the coarse nominal
 * class means their changes are taken against, and how many change the scene. */
typedef struct nuisance_run {
    thz_context *ctx;
    const bands_setup *s;
    const json_t *root;      /* the scene file's document */
    const char *base_dir;    /* its directory */
    const double *ranges;    /* per VAR_*: the nuisance's range (0: not varied) */
    const bool *is_class;    /* per object: a class of its own */
    const int32_t *class_of; /* per object: its class (-1: none) */
    size_t n_obj, pixels;    /* the scene's objects; the nominal render's pixels */
    int32_t *cls;            /* scratch: each pixel's class */
    uint64_t *count;         /* scratch: each class's pixels */
    double air_t_k;          /* the nominal air's temperature, K (NaN: none) */
    double *coarse_mean;     /* the coarse nominal's class means; NULL until rendered */
    double *dmean;           /* scratch: a variant's class means, then their change */
    size_t varied;           /* the variants that change the scene (counted first) */
    bands_values *v;
} nuisance_run;

/* Renders the coarse nominal variant, the one the changes are taken against, into
 * r->coarse_mean (a class it does not see keeps the nominal mean). */
static thz_status nuisance_coarse_nominal(nuisance_run *r, thz_error *err)
{
    bands_values *v = r->v;
    int changed = 0;
    char *nominal_text =
        bands_variant_text(r->root, r->s, r->is_class, VAR_NOMINAL, 0, r->air_t_k, true, &changed);
    r->coarse_mean = thz_calloc(v->n_classes * v->n_candidates, sizeof *r->coarse_mean);
    if (!nominal_text || !r->coarse_mean) {
        free(nominal_text);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    double unused;
    thz_status st =
        variant_means(r->ctx, nominal_text, r->s, r->base_dir, r->class_of, r->n_obj, r->pixels,
                      r->cls, r->count, v, v->mean, r->coarse_mean, &unused, err);
    free(nominal_text);
    if (st == THZ_OK)
        v->renders++;
    return st;
}

/* Adds a variant's change d of each class's mean (dmean holds its means; d is left there)
 * to the class's covariance, d d^T, and d^2 to its nuisances' variance: d is the change
 * over sqrt(3), a uniform variation within +-range having variance range^2 / 3. */
static void nuisance_add(bands_values *v, const double *coarse_mean, double *dmean)
{
    size_t n = v->n_candidates;
    for (size_t k = 0; k < v->n_classes; k++) {
        double *d = dmean + k * n, *cov = v->cov + k * n * n;
        for (size_t c = 0; c < n; c++)
            d[c] = (d[c] - coarse_mean[k * n + c]) / sqrt(3.0);
        for (size_t a = 0; a < n; a++) {
            for (size_t b = 0; b < n; b++)
                cov[a * n + b] += d[a] * d[b];
            v->nuisance_sd[k * n + a] += d[a] * d[a];
        }
    }
}

/* The variant of nuisance `what` (of object o for VAR_TARGETS): counting, only whether
 * it changes the scene (r->varied); else, when it does, its render against the coarse
 * nominal one (rendered first, once), added to the classes' covariance. */
static thz_status nuisance_variant(nuisance_run *r, int what, size_t o, bool counting,
                                   thz_error *err)
{
    bands_values *v = r->v;
    int changed = 0;
    char *text =
        bands_variant_text(r->root, r->s, r->is_class, what, o, r->air_t_k, true, &changed);
    if (!text)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    if (counting)
        r->varied += changed != 0;
    if (counting || !changed) {
        free(text);
        return THZ_OK;
    }
    thz_status st = r->coarse_mean ? THZ_OK : nuisance_coarse_nominal(r, err);
    double air_used = r->air_t_k;
    if (st == THZ_OK)
        st = variant_means(r->ctx, text, r->s, r->base_dir, r->class_of, r->n_obj, r->pixels,
                           r->cls, r->count, v, r->coarse_mean, r->dmean, &air_used, err);
    free(text);
    if (st != THZ_OK)
        return st;
    v->renders++;
    v->humidity_varied = v->humidity_varied || what == VAR_HUMIDITY;
    /* whatever moved it: the air that follows an enclosure's temperature too */
    v->air_temperature_varied =
        v->air_temperature_varied || (isfinite(air_used) && air_used != r->air_t_k);
    v->thickness_varied = v->thickness_varied || what == VAR_THICKNESS;
    v->angle_varied = v->angle_varied || what == VAR_ANGLE;
    nuisance_add(v, r->coarse_mean, r->dmean);
    return THZ_OK;
}

/* Every nuisance whose range is not 0, in VAR_* order, through nuisance_variant: counting
 * the renders, or making them. */
static thz_status nuisance_each(nuisance_run *r, bool counting, thz_error *err)
{
    for (int what = VAR_TARGETS; what < VAR_COUNT; what++) {
        if (!(r->ranges[what] > 0.0))
            continue;
        /* each target's temperature is its own nuisance: one render per target */
        size_t n_variants = what == VAR_TARGETS ? r->n_obj : 1;
        for (size_t o = 0; o < n_variants; o++) {
            if (what == VAR_TARGETS && !r->is_class[o])
                continue;
            thz_status st = nuisance_variant(r, what, o, counting, err);
            if (st != THZ_OK)
                return st;
        }
    }
    return THZ_OK;
}

thz_status bands_values_compute(thz_context *ctx, const bands_setup *s, bands_values *v,
                                thz_error *err)
{
    memset(v, 0, sizeof *v);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const double ranges[VAR_COUNT] = {0,
                                      s->target_range_k,
                                      s->ambient_range_k,
                                      s->humidity_range,
                                      s->thickness_range,
                                      s->angle_range_deg};
    bool any_range = false; /* else one render, the nominal one */
    for (int what = VAR_TARGETS; what < VAR_COUNT; what++)
        any_range = any_range || ranges[what] > 0.0;
    size_t n = s->n_candidates;
    v->n_candidates = n;
    v->coarse_paths = bands_coarse_paths(s->paths_per_sample);
    json_error_t jerr;
    json_t *root = json_load_file(s->scene_path, JSON_REJECT_DUPLICATES, &jerr);
    if (!root)
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%d:%d: %s", s->scene_path, jerr.line,
                             jerr.column, jerr.text);
    bands_progress progress;
    bands_progress_begin(&progress, ctx, any_range ? 0 : 1);
    char base_dir[THZ_PATH_MAX];
    snprintf(base_dir, sizeof base_dir, "%s", s->scene_path);
    char *slash = strrchr(base_dir, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(base_dir, sizeof base_dir, ".");
    thz_status st = THZ_OK;
    thz_scene *scene = NULL;
    bands_render nominal = {0};
    int32_t *cls = NULL, *class_of = NULL;
    uint64_t *count = NULL;
    bool *is_class = NULL;
    double *x = NULL, *dmean = NULL, *coarse_mean = NULL;
    char *text = NULL;
    int changed = 0;
    size_t n_obj = json_array_size(json_object_get(root, "objects"));
    is_class = thz_calloc(n_obj ? n_obj : 1, sizeof *is_class);
    class_of = thz_calloc(n_obj ? n_obj : 1, sizeof *class_of);
    if (!is_class || !class_of)
        goto nomem;
    text = bands_variant_text(root, s, is_class, VAR_NOMINAL, 0, NAN, false, &changed);
    if (!text)
        goto nomem;
    st = thz_scene_load_string_within(text, base_dir, s->scene_path, s->root, &scene, err);
    /* The scene's warnings, as simulate and render give them: those of the scene with the
     * candidates as its channels (a candidate's band beyond a material table, a sensor
     * outside its enclosure, ...), which the run warnings refer to; the nuisances'
     * variants repeat them and are not said again. */
    if (st == THZ_OK && ctx && ctx->warning)
        for (size_t i = 0; i < thz_scene_warning_count(scene); i++)
            ctx->warning(ctx->warning_user, thz_scene_warning(scene, i));
    if (st == THZ_OK)
        st = render_variant(ctx, text, s, base_dir, &nominal, err);
    free(text);
    text = NULL;
    if (st != THZ_OK)
        goto done;
    v->renders = 1;
    for (size_t c = 0; c < n && s->netd_from_sensor; c++) {
        thz_sensor_channel_info sc;
        st = thz_scene_sensor_channel(scene, s->sensor, c, &sc);
        if (st != THZ_OK) {
            thz_error_set(err, st, "sensor %zu, channel %zu: no noise figures", s->sensor, c);
            goto done;
        }
        s->netd_k[c] = sc.netd_k; /* at the channel's reference temperature (reported) */
    }
    cls = thz_calloc(nominal.pixels, sizeof *cls);
    if (!cls)
        goto nomem;
    st = bands_assign_classes(s, scene, nominal.ids, nominal.pixels, class_of, is_class, v, err);
    if (st != THZ_OK)
        goto done;
    if (v->n_classes < 2) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: the sensor sees %zu class(es); band selection needs two or more",
                           s->scene_path, v->n_classes);
        goto done;
    }
    size_t nc = v->n_classes;
    bands_pixel_classes(&nominal, class_of, n_obj, nc, cls, v->class_pixels);
    v->mean = thz_calloc(nc * n, sizeof *v->mean);
    v->cov = thz_calloc(nc * n * n, sizeof *v->cov);
    v->pixel_sd = thz_calloc(nc * n, sizeof *v->pixel_sd);
    v->nuisance_sd = thz_calloc(nc * n, sizeof *v->nuisance_sd);
    v->mean_mc_var = thz_calloc(nc * n, sizeof *v->mean_mc_var);
    v->netd_k = thz_calloc(nc * n, sizeof *v->netd_k);
    x = thz_calloc(n, sizeof *x);
    dmean = thz_calloc(nc * n, sizeof *dmean);
    count = thz_calloc(nc, sizeof *count);
    if (!v->mean || !v->cov || !v->pixel_sd || !v->nuisance_sd || !v->mean_mc_var || !v->netd_k ||
        !x || !dmean || !count)
        goto nomem;
    bands_class_means(&nominal, cls, v->class_pixels, v, v->mean, v->mean);
    bands_class_netd(scene, s, v);
    bands_pixel_covariance(&nominal, cls, s, v, x);
    v->spread_is_noise = !nominal.has_stderr;

    /* Nuisances: a uniform variation within +-range has variance range^2 / 3; the
     * render at +range (humidity: x (1 - range)) gives the change d of each class's
     * mean, which adds d d^T / 3 to its covariance (the same seed in every render keeps
     * the Monte Carlo noise out of d). These renders and the nominal one d is taken
     * against are coarse (coarse_paths). Each render's own truth gives its classes'
     * pixels: a turned sensor sees them elsewhere in the image. */
    nuisance_run nr = {.ctx = ctx,
                       .s = s,
                       .root = root,
                       .base_dir = base_dir,
                       .ranges = ranges,
                       .is_class = is_class,
                       .class_of = class_of,
                       .n_obj = n_obj,
                       .pixels = nominal.pixels,
                       .cls = cls,
                       .count = count,
                       .air_t_k = scene_air_temperature_k(scene),
                       .dmean = dmean,
                       .v = v};
    /* the renders counted first, now that the classes say which ranges change any */
    st = nuisance_each(&nr, true, err);
    if (st == THZ_OK) {
        bands_progress_renders(&progress, 1 + (nr.varied ? nr.varied + 1 : 0));
        st = nuisance_each(&nr, false, err);
    }
    coarse_mean = nr.coarse_mean;
    if (st != THZ_OK)
        goto done;
    for (size_t i = 0; i < nc * n; i++)
        v->nuisance_sd[i] = sqrt(v->nuisance_sd[i]);
    goto done;
nomem:
    st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
done:
    bands_progress_end(&progress);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    v->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    free(text);
    free(x);
    free(dmean);
    free(coarse_mean);
    free(count);
    free(cls);
    free(class_of);
    free(is_class);
    bands_render_fini(&nominal);
    thz_scene_destroy(scene);
    json_decref(root);
    if (st != THZ_OK)
        bands_values_fini(v);
    return st;
}
