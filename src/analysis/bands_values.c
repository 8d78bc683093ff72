/* Band values from the scene itself (bands_values.h). */
#include "analysis/bands_values.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "analysis/bands_progress.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/path.h"
#include "physics/planck.h"
#include "scene/scene.h"
#include "sensor/noise.h"

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

/* The scene's JSON with the nuisance `what` changed: 0 nominal, 1 one target's
 * temperature + range (one variant per target), 2 the other objects' and the air's
 * temperature + range, 3 the humidity x (1 - range), 4 every shell's thickness
 * x (1 + range), 5 the sensor turned by the angle range. Channels and render settings
 * replaced in every variant. */
enum {
    VAR_NOMINAL = 0,
    VAR_TARGETS,
    VAR_AMBIENT,
    VAR_HUMIDITY,
    VAR_THICKNESS,
    VAR_ANGLE,
    VAR_COUNT
};

static const char *const humidity_keys[] = {"relative_humidity", "water_vapour_g_m3", "h2o_vmr"};

static int add_number(json_t *obj, const char *key, double delta, double factor)
{
    json_t *v = json_object_get(obj, key);
    if (!v || !json_is_number(v))
        return 0;
    json_object_set_new(obj, key, json_real(json_number_value(v) * factor + delta));
    return 1;
}

static bool get_vec3(const json_t *obj, const char *key, double v[3])
{
    const json_t *a = json_object_get(obj, key);
    if (!json_is_array(a) || json_array_size(a) != 3)
        return false;
    for (size_t i = 0; i < 3; i++) {
        const json_t *x = json_array_get(a, i);
        if (!json_is_number(x))
            return false;
        v[i] = json_number_value(x);
    }
    return true;
}

static void set_vec3(json_t *obj, const char *key, const double v[3])
{
    json_t *a = json_array();
    for (size_t i = 0; i < 3; i++)
        json_array_append_new(a, json_real(v[i]));
    json_object_set_new(obj, key, a);
}

/* v turned by `deg` about the axis `k` (any length but 0), Rodrigues' formula. */
static void rotate(double v[3], const double k_in[3], double deg)
{
    double len = sqrt(k_in[0] * k_in[0] + k_in[1] * k_in[1] + k_in[2] * k_in[2]);
    double k[3] = {k_in[0] / len, k_in[1] / len, k_in[2] / len};
    double th = deg * M_PI / 180.0, c = cos(th), sn = sin(th);
    double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    double x[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]};
    for (size_t i = 0; i < 3; i++)
        v[i] = v[i] * c + x[i] * sn + k[i] * kv * (1.0 - c);
}

/* The viewing-angle nuisance: the sensor turned by `deg` about its up axis, around its
 * look_at_m point (it keeps looking at it, from another side), or about its own position
 * when it gives a direction instead. Returns 1 when it changed the sensor. */
static int turn_sensor(json_t *sensor, double deg)
{
    double pos[3], at[3], dir[3], up[3] = {0.0, 0.0, 1.0};
    if (!get_vec3(sensor, "position_m", pos))
        return 0;
    get_vec3(sensor, "up", up);
    if (!(up[0] * up[0] + up[1] * up[1] + up[2] * up[2] > 0.0))
        return 0;
    if (get_vec3(sensor, "look_at_m", at)) {
        double r[3] = {pos[0] - at[0], pos[1] - at[1], pos[2] - at[2]};
        rotate(r, up, deg);
        for (size_t i = 0; i < 3; i++)
            pos[i] = at[i] + r[i];
        set_vec3(sensor, "position_m", pos);
        return 1;
    }
    if (!get_vec3(sensor, "direction", dir))
        return 0;
    rotate(dir, up, deg);
    set_vec3(sensor, "direction", dir);
    return 1;
}

/* The nuisances' renders are coarse: one sample per pixel and a quarter of the paths
 * (at least one), against a coarse nominal render with the same seed. A class mean's
 * change is smooth over its pixels and the common seed keeps the Monte Carlo noise out
 * of the difference, so it needs far fewer samples than the pixel statistics do. */
static uint32_t coarse_paths(uint32_t paths)
{
    return paths >= 4 ? paths / 4 : 1;
}

/* The air's temperature in a variant: the nominal scene's air_t_k (NaN: its air has
 * none) raised by the ambient range in VAR_AMBIENT, and held at air_t_k in every other
 * variant, written out where the scene leaves it to the enclosure's temperature (an
 * enclosure that is a target then changes alone). Returns 1 when it changed it. */
static int set_air_temperature(json_t *atm, int what, double air_t_k, double range_k)
{
    if (!atm || !isfinite(air_t_k))
        return 0;
    double t = what == VAR_AMBIENT ? air_t_k + range_k : air_t_k;
    json_object_set_new(atm, "temperature_k", json_real(t));
    return what == VAR_AMBIENT;
}

/* The scene text of a variant (what, and for VAR_TARGETS the one object `target` whose
 * temperature is raised); *changed counts the values it changes. air_t_k: the nominal
 * air's temperature, K (NaN: none). */
static char *variant_text(const json_t *root, const bands_setup *s, const bool *is_class, int what,
                          size_t target, double air_t_k, bool coarse, int *changed)
{
    json_t *doc = json_deep_copy(root);
    if (!doc)
        return NULL;
    json_t *channels = json_array();
    for (size_t c = 0; c < s->n_candidates; c++) {
        json_t *ch = json_object();
        json_object_set_new(ch, "frequency_thz", json_real(s->candidates_thz[c]));
        json_object_set_new(ch, "relative_width", json_real(s->widths[c]));
        json_array_append_new(channels, ch);
    }
    json_object_set_new(doc, "channels", channels);
    json_t *render = json_object();
    json_object_set_new(render, "integrator", json_string("path"));
    json_object_set_new(
        render, "paths_per_sample",
        json_integer(coarse ? coarse_paths(s->paths_per_sample) : s->paths_per_sample));
    json_object_set_new(doc, "render", render);
    /* the sensor's noise with one netd_k per channel cannot follow the candidates: its
     * NETD is interpolated to them instead (api_bands.c), and the renders need none */
    json_t *sensor = json_array_get(json_object_get(doc, "sensors"), s->sensor);
    json_t *noise = json_object_get(sensor, "noise");
    if (noise && json_is_array(json_object_get(noise, "netd_k")))
        json_object_del(sensor, "noise");
    if (coarse && sensor)
        json_object_set_new(sensor, "oversampling", json_integer(1));
    *changed = 0;
    json_t *objects = json_object_get(doc, "objects");
    json_t *atm = json_object_get(doc, "atmosphere");
    if (what != VAR_NOMINAL)
        *changed += set_air_temperature(atm, what, air_t_k, s->ambient_range_k);
    if (what == VAR_TARGETS) {
        /* one target at a time: the targets' temperatures vary independently */
        *changed +=
            add_number(json_array_get(objects, target), "temperature_k", s->target_range_k, 1.0);
    } else if (what == VAR_AMBIENT) {
        for (size_t i = 0; i < json_array_size(objects); i++)
            if (!is_class[i])
                *changed += add_number(json_array_get(objects, i), "temperature_k",
                                       s->ambient_range_k, 1.0);
    } else if (what == VAR_HUMIDITY && atm) {
        /* downwards, which every humidity key accepts */
        for (size_t i = 0; i < 3; i++)
            *changed += add_number(atm, humidity_keys[i], 0.0, 1.0 - s->humidity_range);
    } else if (what == VAR_THICKNESS) {
        for (size_t i = 0; i < json_array_size(objects); i++) {
            json_t *o = json_array_get(objects, i);
            const char *type = json_string_value(json_object_get(o, "type"));
            if (type && strcmp(type, "shell") == 0)
                *changed += add_number(o, "thickness_m", 0.0, 1.0 + s->thickness_range);
        }
    } else if (what == VAR_ANGLE && sensor) {
        *changed += turn_sensor(sensor, s->angle_range_deg);
    }
    char *text = json_dumps(doc, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(doc);
    return text;
}

/* One render of a variant: its Tb cube and radiance standard error (copied), its
 * object_id truth (a turned sensor sees the classes at other pixels), and the air's
 * temperature it used (K, NaN: its air has none). */
typedef struct render_out {
    float *tb, *stderr_l;
    int32_t *ids;
    size_t pixels;
    double air_t_k;
    bool has_stderr; /* false: one sample of one path per pixel estimates none */
} render_out;

/* The temperature of the scene's air, K, or NaN when it has none (no air, or air that
 * neither emits nor has a state): what the nuisances hold or vary. */
static double scene_air_temperature_k(const thz_scene *scene)
{
    const thz_atmosphere *atm = &scene->atmosphere;
    return atm->has_air || atm->emitting ? atm->air.temperature_k : NAN;
}

static thz_status render_variant(thz_context *ctx, const char *text, const bands_setup *s,
                                 const char *base_dir, render_out *out, thz_error *err)
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

static void render_out_fini(render_out *r)
{
    free(r->tb);
    free(r->stderr_l);
    free(r->ids);
    memset(r, 0, sizeof *r);
}

/* The class of each object (class_of, n_obj entries, -1: none) from the nominal
 * render's truth: targets (in order) and "background", or every object seen. */
static thz_status assign_classes(const bands_setup *s, const thz_scene *scene, const int32_t *ids,
                                 size_t pixels, int32_t *class_of, bool *is_class, bands_values *v,
                                 thz_error *err)
{
    size_t n_obj = thz_scene_object_count(scene);
    uint64_t *seen = thz_calloc(n_obj, sizeof *seen);
    thz_status st = THZ_OK;
    if (!seen) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t p = 0; p < pixels; p++)
        if (ids[p] >= 0 && (size_t)ids[p] < n_obj)
            seen[ids[p]]++;
    size_t nc = 0;
    if (s->n_targets) {
        for (size_t o = 0; o < n_obj; o++)
            class_of[o] = -1;
        for (size_t t = 0; t < s->n_targets; t++) {
            if (!seen[s->targets[t]]) {
                thz_object_info oi;
                thz_scene_object(scene, (size_t)s->targets[t], &oi);
                st = thz_error_set(err, THZ_ERR_INPUT, "targets: the sensor sees no pixel of '%s'",
                                   oi.name);
                goto done;
            }
            class_of[s->targets[t]] = (int32_t)nc++;
            is_class[s->targets[t]] = true;
        }
        bool background = false;
        for (size_t o = 0; o < n_obj; o++)
            background = background || (seen[o] && class_of[o] < 0);
        for (size_t o = 0; o < n_obj; o++)
            if (class_of[o] < 0)
                class_of[o] = background ? (int32_t)nc : -1;
        nc += background;
    } else {
        for (size_t o = 0; o < n_obj; o++) {
            class_of[o] = seen[o] ? (int32_t)nc++ : -1;
            is_class[o] = seen[o] > 0;
        }
    }
    v->n_classes = nc;
    v->class_names = thz_calloc(nc, sizeof *v->class_names);
    v->class_pixels = thz_calloc(nc, sizeof *v->class_pixels);
    if (!v->class_names || !v->class_pixels) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t o = 0; o < n_obj; o++) {
        int32_t k = class_of[o];
        if (k < 0 || v->class_names[k])
            continue;
        thz_object_info oi;
        thz_scene_object(scene, o, &oi);
        v->class_names[k] = thz_strdup(is_class[o] ? oi.name : "background");
        if (!v->class_names[k]) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
done:
    free(seen);
    return st;
}

/* The class of each pixel of render r (cls, r->pixels entries, -1: none) and each
 * class's pixel count. */
static void pixel_classes(const render_out *r, const int32_t *class_of, size_t n_obj,
                          size_t n_classes, int32_t *cls, uint64_t *count)
{
    memset(count, 0, n_classes * sizeof *count);
    for (size_t p = 0; p < r->pixels; p++) {
        cls[p] = r->ids[p] >= 0 && (size_t)r->ids[p] < n_obj ? class_of[r->ids[p]] : -1;
        if (cls[p] >= 0)
            count[cls[p]]++;
    }
}

/* Class means of a render's Tb into mean[class * n + c]; a class without pixels (a
 * turned sensor may lose one) takes `fallback`'s mean, i.e. no change. */
static void class_means(const render_out *r, const int32_t *cls, const uint64_t *count,
                        const bands_values *v, const double *fallback, double *mean)
{
    size_t n = v->n_candidates;
    memset(mean, 0, v->n_classes * n * sizeof *mean);
    for (size_t c = 0; c < n; c++)
        for (size_t p = 0; p < r->pixels; p++)
            if (cls[p] >= 0)
                mean[(size_t)cls[p] * n + c] += r->tb[c * r->pixels + p];
    for (size_t k = 0; k < v->n_classes; k++)
        for (size_t c = 0; c < n; c++)
            mean[k * n + c] = count[k] ? mean[k * n + c] / (double)count[k] : fallback[k * n + c];
}

/* The pixel covariance of each class about its mean, less the Monte Carlo variance of
 * its pixels on the diagonal (floored at 0), plus its NETD^2 on the diagonal. */
static void pixel_covariance(const render_out *r, const int32_t *cls, const bands_setup *s,
                             bands_values *v, double *x)
{
    size_t n = v->n_candidates, pixels = r->pixels;
    for (size_t p = 0; p < pixels; p++) {
        if (cls[p] < 0)
            continue;
        size_t k = (size_t)cls[p];
        for (size_t c = 0; c < n; c++)
            x[c] = r->tb[c * pixels + p] - v->mean[k * n + c];
        double *cov = v->cov + k * n * n;
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b <= a; b++)
                cov[a * n + b] += x[a] * x[b];
    }
    for (size_t k = 0; k < v->n_classes; k++) {
        double *cov = v->cov + k * n * n;
        double d = v->class_pixels[k] > 1 ? (double)(v->class_pixels[k] - 1) : 1.0;
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b <= a; b++) {
                cov[a * n + b] /= d;
                cov[b * n + a] = cov[a * n + b];
            }
    }
    /* Removing the Monte Carlo variance mc_c from the diagonal alone could leave a
     * matrix that is not positive semi-definite; scaling row and column c by
     * sqrt(1 - mc_c / var_c) instead (D C D, D >= 0 diagonal) keeps it so and keeps the
     * correlations. */
    for (size_t k = 0; k < v->n_classes; k++) {
        double *cov = v->cov + k * n * n;
        for (size_t c = 0; c < n; c++) {
            /* the radiance's standard error in K through dB/dT at the channel's centre
             * (the bands are narrow) */
            double nu = s->candidates_thz[c] * 1e12, mc = 0.0;
            for (size_t p = 0; p < pixels; p++)
                if (cls[p] == (int32_t)k) {
                    double t = r->tb[c * pixels + p];
                    double sd = t > 0.0 ? r->stderr_l[c * pixels + p] / planck_dbdt(nu, t) : 0.0;
                    mc += sd * sd;
                }
            mc /= (double)v->class_pixels[k];
            double var = cov[c * n + c];
            /* the pixels' errors are independent: the mean's variance is their mean / pixels;
             * a render without standard errors has the pixels' variance stand in (a bound) */
            v->mean_mc_var[k * n + c] = (r->has_stderr ? mc : var) / (double)v->class_pixels[k];
            x[c] = var > mc ? sqrt(1.0 - mc / var) : 0.0;
        }
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b < n; b++)
                cov[a * n + b] *= x[a] * x[b];
        for (size_t c = 0; c < n; c++) {
            v->pixel_sd[k * n + c] = sqrt(cov[c * n + c]);
            cov[c * n + c] += v->netd_k[k * n + c] * v->netd_k[k * n + c];
        }
    }
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
    render_out r = {0};
    thz_status st = render_variant(ctx, text, s, base_dir, &r, err);
    if (st == THZ_OK && r.pixels != pixels) /* a variant never changes the resolution */
        st = thz_error_set(err, THZ_ERR_INTERNAL, "band values: a variant's image differs");
    if (st == THZ_OK) {
        pixel_classes(&r, class_of, n_obj, v->n_classes, cls, count);
        class_means(&r, cls, count, v, fallback, mean);
        *air_t_k = r.air_t_k;
    }
    render_out_fini(&r);
    return st;
}

/* The NETD of each class and candidate: the radiometer's at the class's mean Tb (its
 * noise grows with the Tb it measures, scene-format.md "noise"), else the candidate's. */
static void class_netd(const thz_scene *scene, const bands_setup *s, bands_values *v)
{
    size_t n = v->n_candidates;
    for (size_t k = 0; k < v->n_classes; k++)
        for (size_t c = 0; c < n; c++)
            v->netd_k[k * n + c] = s->netd_from_sensor
                                       ? noise_netd_k(&scene->sensors[s->sensor].noise,
                                                      &scene->channels[c], c, v->mean[k * n + c])
                                       : s->netd_k[c];
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
    v->coarse_paths = coarse_paths(s->paths_per_sample);
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
    render_out nominal = {0};
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
    text = variant_text(root, s, is_class, VAR_NOMINAL, 0, NAN, false, &changed);
    if (!text)
        goto nomem;
    st = thz_scene_load_string_within(text, base_dir, s->scene_path, s->root, &scene, err);
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
    st = assign_classes(s, scene, nominal.ids, nominal.pixels, class_of, is_class, v, err);
    if (st != THZ_OK)
        goto done;
    if (v->n_classes < 2) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: the sensor sees %zu class(es); band selection needs two or more",
                           s->scene_path, v->n_classes);
        goto done;
    }
    size_t nc = v->n_classes;
    pixel_classes(&nominal, class_of, n_obj, nc, cls, v->class_pixels);
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
    class_means(&nominal, cls, v->class_pixels, v, v->mean, v->mean);
    class_netd(scene, s, v);
    pixel_covariance(&nominal, cls, s, v, x);

    /* Nuisances: a uniform variation within +-range has variance range^2 / 3; the
     * render at +range (humidity: x (1 - range)) gives the change d of each class's
     * mean, which adds d d^T / 3 to its covariance (the same seed in every render keeps
     * the Monte Carlo noise out of d). These renders and the nominal one d is taken
     * against are coarse (coarse_paths). Each render's own truth gives its classes'
     * pixels: a turned sensor sees them elsewhere in the image. */
    double air_t_k = scene_air_temperature_k(scene);
    size_t varied = 0; /* the renders, now that the classes say which ranges change any */
    for (int pass = 0; pass < 2; pass++) { /* 0 counts the renders, 1 makes them */
        if (pass == 1)
            bands_progress_renders(&progress, 1 + (varied ? varied + 1 : 0));
        for (int what = VAR_TARGETS; what < VAR_COUNT; what++) {
            if (!(ranges[what] > 0.0))
                continue;
            /* each target's temperature is its own nuisance: one render per target */
            for (size_t o = 0; o < (what == VAR_TARGETS ? n_obj : 1); o++) {
                if (what == VAR_TARGETS && !is_class[o])
                    continue;
                text = variant_text(root, s, is_class, what, o, air_t_k, true, &changed);
                if (!text)
                    goto nomem;
                if (!changed || pass == 0) {
                    varied += changed != 0;
                    free(text);
                    text = NULL;
                    continue;
                }
                if (!coarse_mean) { /* the coarse nominal render the changes are taken against */
                    char *nominal_text =
                        variant_text(root, s, is_class, VAR_NOMINAL, 0, air_t_k, true, &changed);
                    coarse_mean = thz_calloc(nc * n, sizeof *coarse_mean);
                    if (!nominal_text || !coarse_mean) {
                        free(nominal_text);
                        goto nomem;
                    }
                    double unused;
                    st = variant_means(ctx, nominal_text, s, base_dir, class_of, n_obj,
                                       nominal.pixels, cls, count, v, v->mean, coarse_mean, &unused,
                                       err);
                    free(nominal_text);
                    if (st != THZ_OK)
                        goto done;
                    v->renders++;
                }
                double air_used = air_t_k;
                st = variant_means(ctx, text, s, base_dir, class_of, n_obj, nominal.pixels, cls,
                                   count, v, coarse_mean, dmean, &air_used, err);
                free(text);
                text = NULL;
                if (st != THZ_OK)
                    goto done;
                v->renders++;
                v->humidity_varied = v->humidity_varied || what == VAR_HUMIDITY;
                /* whatever moved it: the air that follows an enclosure's temperature too */
                v->air_temperature_varied =
                    v->air_temperature_varied || (isfinite(air_used) && air_used != air_t_k);
                v->thickness_varied = v->thickness_varied || what == VAR_THICKNESS;
                v->angle_varied = v->angle_varied || what == VAR_ANGLE;
                for (size_t k = 0; k < nc; k++) {
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
        }
    }
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
    render_out_fini(&nominal);
    thz_scene_destroy(scene);
    json_decref(root);
    if (st != THZ_OK)
        bands_values_fini(v);
    return st;
}
