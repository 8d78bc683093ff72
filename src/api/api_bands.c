/* The public API of band selection (thzmap/analysis.h): options, the search over a
 * scene's candidate channels, and its files (analysis/bands_*.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/bands_output.h"
#include "analysis/bands_search.h"
#include "analysis/bands_values.h"
#include "api/api.h"
#include "core/alloc.h"
#include "io/output.h"

/* Most candidates: a scene has at most this many channels (scene-format.md). */
enum { BANDS_MAX_CANDIDATES = 4096 };

struct thz_bands {
    char *scene_path, *scene_name, *sensor;
    char *root; /* thz_bands_options.root, copied; NULL: not confined */
    double from_thz, to_thz, step_ghz;
    double *candidates_thz; /* per candidate: its centre (c = centre * n_widths + width) */
    double *widths;         /* per candidate: its relative width */
    size_t *group;          /* per candidate: its centre's index */
    double *width_list;     /* the n_widths widths searched, ascending */
    size_t n_widths, n_centres;
    double *netd_k; /* per candidate */
    const char *netd_source;
    long *targets;
    bands_setup setup;
    bands_values values;
    bands_search_result search;
    double *air_db_per_km; /* or NULL */
    double noise_b;        /* the worst pair's B from the render's Monte Carlo noise alone */
    char *warning;         /* NULL, or: the worst pair cannot be told apart */
    char *json;
};

void thz_bands_options_init(thz_bands_options *opt)
{
    if (!opt)
        return;
    memset(opt, 0, sizeof *opt);
    opt->from_thz = 0.1;
    opt->to_thz = 1.5;
    opt->step_ghz = 10.0;
    opt->netd_k = 0.5; /* used when has_netd, or when the sensor has no noise */
    opt->target_temperature_range_k = 2.0;
    opt->ambient_temperature_range_k = 2.0;
    opt->humidity_range = 0.2;
    opt->paths_per_sample = 16;
    opt->exhaustive_limit = 2000000;
}

void thz_bands_destroy(thz_bands *b)
{
    if (!b)
        return;
    free(b->scene_path);
    free(b->root);
    free(b->scene_name);
    free(b->sensor);
    free(b->candidates_thz);
    free(b->widths);
    free(b->group);
    free(b->width_list);
    free(b->netd_k);
    free(b->targets);
    bands_values_fini(&b->values);
    bands_search_result_fini(&b->search);
    free(b->air_db_per_km);
    free(b->warning);
    free(b->json);
    free(b);
}

double thz_bands_candidate_centres(const thz_bands_options *o)
{
    if (!o || !(o->from_thz > 0.0) || !(o->to_thz >= o->from_thz) || !(o->step_ghz > 0.0) ||
        !isfinite(o->to_thz) || !isfinite(o->step_ghz))
        return 0.0;
    return floor((o->to_thz - o->from_thz) * 1e3 / o->step_ghz + 1e-9) + 1.0;
}

static thz_status check_options(const thz_bands_options *o, size_t *n_candidates, thz_error *err)
{
    if (o->count < 1 || o->count > BANDS_MAX_COUNT)
        return thz_error_set(err, THZ_ERR_INPUT, "count %zu: expected 1 to %d", o->count,
                             BANDS_MAX_COUNT);
    if (!(o->from_thz > 0.0) || !(o->to_thz >= o->from_thz) || !(o->step_ghz > 0.0) ||
        !isfinite(o->to_thz))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "candidates %g to %g THz by %g GHz: expected 0 < from <= to and a "
                             "step > 0",
                             o->from_thz, o->to_thz, o->step_ghz);
    double n = thz_bands_candidate_centres(o);
    if (n > BANDS_MAX_CANDIDATES)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%.0f candidates from %g to %g THz by %g GHz: at most %d (raise "
                             "the step)",
                             n, o->from_thz, o->to_thz, o->step_ghz, BANDS_MAX_CANDIDATES);
    if ((size_t)n < o->count)
        return thz_error_set(err, THZ_ERR_INPUT, "count %zu: only %.0f candidate centres", o->count,
                             n);
    if (!(o->relative_width >= 0.0 && o->relative_width <= 0.5))
        return thz_error_set(err, THZ_ERR_INPUT, "relative_width %g: expected 0 < w <= 0.5",
                             o->relative_width);
    if (o->n_widths && !o->relative_widths)
        return thz_error_set(err, THZ_ERR_INPUT, "widths: %zu given but no list", o->n_widths);
    if (o->n_widths && o->relative_width > 0.0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "relative_width %g and widths: give one (the candidates' one "
                             "width, or the widths searched)",
                             o->relative_width);
    for (size_t i = 0; i < o->n_widths; i++) {
        if (!(o->relative_widths[i] > 0.0 && o->relative_widths[i] <= 0.5))
            return thz_error_set(err, THZ_ERR_INPUT, "widths: %g: expected 0 < w <= 0.5",
                                 o->relative_widths[i]);
        for (size_t j = 0; j < i; j++)
            if (o->relative_widths[j] == o->relative_widths[i])
                return thz_error_set(err, THZ_ERR_INPUT, "widths: %g given twice",
                                     o->relative_widths[i]);
    }
    if (n * (double)(o->n_widths ? o->n_widths : 1) > BANDS_MAX_CANDIDATES)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%.0f centres x %zu widths: at most %d candidates (raise "
                             "the step or give fewer widths)",
                             n, o->n_widths, BANDS_MAX_CANDIDATES);
    if (!(o->thickness_range >= 0.0 && o->thickness_range < 1.0))
        return thz_error_set(err, THZ_ERR_INPUT, "thickness range %g: expected 0 <= F < 1",
                             o->thickness_range);
    if (!(o->angle_range_deg >= 0.0 && o->angle_range_deg <= 90.0))
        return thz_error_set(err, THZ_ERR_INPUT, "angle range %g degrees: expected 0 to 90",
                             o->angle_range_deg);
    if (o->has_netd && !(o->netd_k > 0.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "NETD %g K: expected > 0 K (a sensor without noise leaves a class "
                             "of identical pixels with no spread to separate by)",
                             o->netd_k);
    if (!(o->netd_k >= 0.0) || !(o->target_temperature_range_k >= 0.0) ||
        !(o->ambient_temperature_range_k >= 0.0) ||
        !(o->humidity_range >= 0.0 && o->humidity_range < 1.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "NETD and ranges must be >= 0 (and the humidity range below 1)");
    if (o->n_targets && !o->targets)
        return thz_error_set(err, THZ_ERR_INPUT, "targets: %zu given but no list", o->n_targets);
    for (size_t t = 0; t < o->n_targets; t++)
        if (!o->targets[t] || !o->targets[t][0])
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "targets[%zu]: expected an object's name, got %s", t,
                                 o->targets[t] ? "\"\"" : "NULL");
    if (o->paths_per_sample < 1)
        return thz_error_set(err, THZ_ERR_INPUT, "paths per sample: expected at least 1");
    if (o->has_seed && o->seed > (uint64_t)INT64_MAX) /* bands.json records it exactly */
        return thz_error_set(err, THZ_ERR_INPUT, "seed %llu: expected 0 to %lld, as photons.seed",
                             (unsigned long long)o->seed, (long long)INT64_MAX);
    *n_candidates = (size_t)n;
    return THZ_OK;
}

/* The NETD per candidate: --netd-k; or the sensor's given netd_k, interpolated linearly
 * in frequency between its channels (held beyond the ends); or, for a radiometer,
 * bands_values reads each candidate's NETD from the scene with the candidates as its
 * channels (it depends on their bandwidth); or netd_k when the sensor has no noise. */
static thz_status resolve_netd(thz_bands *b, const thz_bands_options *o, const thz_scene *scene,
                               size_t sensor, thz_error *err)
{
    b->netd_source = "--netd-k";
    if (o->has_netd)
        return THZ_OK;
    size_t nch = thz_scene_channel_count(scene), n = b->setup.n_candidates;
    thz_sensor_channel_info sc;
    thz_status st = thz_scene_sensor_channel(scene, sensor, 0, &sc);
    if (st != THZ_OK)
        return thz_error_set(err, st, "sensor %zu: no noise figures", sensor);
    if (strcmp(sc.noise, "none") == 0) {
        b->netd_source = "default (the sensor has no noise)";
        return THZ_OK;
    }
    if (strcmp(sc.noise, "netd") != 0) {
        b->netd_source = strcmp(sc.noise, "dicke") == 0 ? "the sensor's radiometer (dicke)"
                                                        : "the sensor's radiometer (total-power)";
        b->setup.netd_from_sensor = true;
        return THZ_OK;
    }
    b->netd_source = "the sensor's netd_k, interpolated to the candidates";
    for (size_t c = 0; c < n; c++) {
        double f = b->candidates_thz[c], lo = -1.0, hi = -1.0, lo_f = 0.0, hi_f = 0.0;
        for (size_t i = 0; i < nch; i++) {
            thz_channel_info ci;
            st = thz_scene_channel(scene, i, &ci);
            if (st == THZ_OK)
                st = thz_scene_sensor_channel(scene, sensor, i, &sc);
            if (st != THZ_OK)
                return thz_error_set(err, st, "sensor %zu, channel %zu: no noise figures", sensor,
                                     i);
            if (ci.frequency_thz <= f && (lo < 0.0 || ci.frequency_thz > lo_f)) {
                lo_f = ci.frequency_thz;
                lo = sc.netd_k;
            }
            if (ci.frequency_thz >= f && (hi < 0.0 || ci.frequency_thz < hi_f)) {
                hi_f = ci.frequency_thz;
                hi = sc.netd_k;
            }
        }
        if (lo < 0.0)
            b->netd_k[c] = hi;
        else if (hi < 0.0 || hi_f == lo_f)
            b->netd_k[c] = lo;
        else
            b->netd_k[c] = lo + (hi - lo) * (f - lo_f) / (hi_f - lo_f);
    }
    return THZ_OK;
}

/* Scene facts: the sensor, the targets, the default width and seed, the air. */
static thz_status resolve_scene(thz_bands *b, const thz_bands_options *o, thz_error *err)
{
    thz_scene *scene = NULL;
    thz_atm *atm = NULL;
    thz_status st = thz_scene_load_within(b->scene_path, b->root, &scene, err);
    if (st != THZ_OK)
        return st;
    thz_scene_info info;
    thz_scene_get_info(scene, &info);
    long sensor = o->sensor ? thz_scene_sensor_index(scene, o->sensor) : 0;
    if (sensor < 0) {
        st = thz_error_set(err, THZ_ERR_INPUT, "sensor: %s has no sensor named '%s'", b->scene_path,
                           o->sensor);
        goto done;
    }
    thz_sensor_info si;
    thz_scene_sensor(scene, (size_t)sensor, &si);
    b->setup.sensor = (size_t)sensor;
    b->scene_name = thz_strdup(info.name);
    b->sensor = thz_strdup(si.name);
    b->targets = thz_calloc(o->n_targets, sizeof *b->targets);
    if (!b->scene_name || !b->sensor || !b->targets) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t t = 0; t < o->n_targets; t++) {
        b->targets[t] = thz_scene_object_index(scene, o->targets[t]);
        if (b->targets[t] < 0) {
            st = thz_error_set(err, THZ_ERR_INPUT, "targets: %s has no object named '%s'",
                               b->scene_path, o->targets[t]);
            goto done;
        }
        for (size_t u = 0; u < t; u++)
            if (b->targets[u] == b->targets[t]) {
                st = thz_error_set(err, THZ_ERR_INPUT, "targets: '%s' named twice", o->targets[t]);
                goto done;
            }
    }
    st = resolve_netd(b, o, scene, (size_t)sensor, err);
    if (st != THZ_OK)
        goto done;
    thz_channel_info ci;
    thz_scene_channel(scene, 0, &ci);
    /* the default width: the first channel's; a measured response has none, its FWHM /
     * centre stands for it (at most 0.5, the widest a candidate may be) */
    double first_width = ci.relative_width;
    if (!(first_width > 0.0) && ci.fwhm_hz > 0.0 && ci.frequency_hz > 0.0)
        first_width = fmin(ci.fwhm_hz / ci.frequency_hz, 0.5);
    if (!o->n_widths)
        b->width_list[0] = o->relative_width > 0.0 ? o->relative_width : first_width;
    for (size_t c = 0; c < b->setup.n_candidates; c++)
        b->widths[c] = b->width_list[c % b->n_widths];
    b->setup.seed = o->has_seed ? o->seed : info.seed;
    if (strcmp(info.atmosphere_model, "none") != 0) {
        st = thz_atm_from_scene(scene, &atm, err);
        if (st != THZ_OK)
            goto done;
        char what[1200]; /* the scene's air refuses the candidates: name both */
        snprintf(what, sizeof what, "%s: the candidate frequencies (from_thz to to_thz)",
                 info.path ? info.path : "the scene");
        st = thz_atm_check_range(atm, b->candidates_thz[0] * 1e12,
                                 b->candidates_thz[b->setup.n_candidates - 1] * 1e12, what, err);
        if (st != THZ_OK)
            goto done;
        b->air_db_per_km = thz_calloc(b->setup.n_candidates, sizeof *b->air_db_per_km);
        if (!b->air_db_per_km) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (size_t c = 0; c < b->setup.n_candidates; c++)
            b->air_db_per_km[c] =
                thz_atm_attenuation_per_m(atm, b->candidates_thz[c] * 1e12) * THZ_NEPER_TO_DB * 1e3;
    }
done:
    thz_atm_destroy(atm);
    thz_scene_destroy(scene);
    return st;
}

/* Whether the chosen set's worst pair is told apart by more than the Monte Carlo noise
 * of the class means (docs/analysis.md "Outputs"): two identical targets get a B from
 * that noise alone, and a chosen set that means nothing; warned through ctx and kept
 * for bands.json. */
static thz_status check_worst_pair(thz_context *ctx, thz_bands *b, thz_error *err)
{
    const bands_search_result *r = &b->search;
    const bands_score *s = &r->scores[r->count - 1];
    size_t m = r->count, work_n = 2 * m * m + m;
    double *work = thz_calloc(work_n, sizeof *work);
    if (!work)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    bands_classes cl = {.n_candidates = b->setup.n_candidates,
                        .n_classes = b->values.n_classes,
                        .mean = b->values.mean,
                        .cov = b->values.cov,
                        .group = b->group};
    b->noise_b = bands_noise_bhattacharyya(&cl, r->sets + (m - 1) * r->count, m, s->worst_pair[0],
                                           s->worst_pair[1], b->values.mean_mc_var,
                                           b->values.spread_is_noise, work);
    free(work);
    if (!(s->worst_b <= b->noise_b))
        return THZ_OK;
    char msg[1024];
    snprintf(msg, sizeof msg,
             "'%s' and '%s' cannot be told apart: their Bhattacharyya distance on the chosen "
             "channels, %.3g, is not above the %.3g that the Monte Carlo noise of their mean "
             "brightness temperatures %s gives: the chosen set may answer that noise (more "
             "--paths lowers it), or the two are alike",
             b->values.class_names[s->worst_pair[0]], b->values.class_names[s->worst_pair[1]],
             s->worst_b, b->noise_b,
             b->values.spread_is_noise
                 ? "and of their spreads (one path of one sample per pixel estimates no "
                   "standard error to take out of the spreads)"
                 : "alone");
    b->warning = thz_strdup(msg);
    if (!b->warning)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    if (ctx && ctx->warning)
        ctx->warning(ctx->warning_user, msg);
    return THZ_OK;
}

static bands_report make_report(const thz_bands *b)
{
    return (bands_report){.scene_path = b->scene_path,
                          .scene_name = b->scene_name,
                          .sensor = b->sensor,
                          .setup = &b->setup,
                          .from_thz = b->from_thz,
                          .to_thz = b->to_thz,
                          .step_ghz = b->step_ghz,
                          .values = &b->values,
                          .search = &b->search,
                          .air_db_per_km = b->air_db_per_km,
                          .width_list = b->width_list,
                          .n_widths = b->n_widths,
                          .netd_source = b->netd_source,
                          .noise_b = b->noise_b,
                          .warning = b->warning};
}

thz_status thz_bands_select(thz_context *ctx, const char *scene_path, const thz_bands_options *o,
                            thz_bands **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_bands_select: no place for the bands"),
            err);
    *out = NULL;
    size_t n = 0;
    if (!scene_path || !o)
        return api_done(ctx,
                        thz_error_set(err, THZ_ERR_INPUT, "thz_bands_select: no %s",
                                      scene_path ? "options" : "scene"),
                        err);
    thz_status st = check_options(o, &n, err);
    if (st == THZ_OK)
        st = api_check_threads(ctx, "thz_bands_select", err);
    if (st != THZ_OK)
        return api_done(ctx, st, err);
    thz_bands *b = thz_calloc(1, sizeof *b);
    if (!b)
        return api_done(ctx, thz_error_set(err, THZ_ERR_NOMEM, "out of memory"), err);
    b->n_centres = n;
    b->n_widths = o->n_widths ? o->n_widths : 1;
    n *= b->n_widths;
    b->scene_path = thz_strdup(scene_path);
    b->root = thz_strdup(o->root);
    b->candidates_thz = thz_calloc(n, sizeof *b->candidates_thz);
    b->widths = thz_calloc(n, sizeof *b->widths);
    b->group = thz_calloc(n, sizeof *b->group);
    b->width_list = thz_calloc(b->n_widths, sizeof *b->width_list);
    b->netd_k = thz_calloc(n, sizeof *b->netd_k);
    if (!b->scene_path || (o->root && !b->root) || !b->candidates_thz || !b->widths || !b->group ||
        !b->width_list || !b->netd_k) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    b->from_thz = o->from_thz;
    b->to_thz = o->to_thz;
    b->step_ghz = o->step_ghz;
    for (size_t i = 0; i < o->n_widths; i++) { /* ascending (insertion sort: a few) */
        size_t j = i;
        for (; j > 0 && b->width_list[j - 1] > o->relative_widths[i]; j--)
            b->width_list[j] = b->width_list[j - 1];
        b->width_list[j] = o->relative_widths[i];
    }
    for (size_t c = 0; c < n; c++) { /* from + i step, rounded to the kHz the grid means */
        size_t i = c / b->n_widths;
        b->candidates_thz[c] = round((o->from_thz + (double)i * o->step_ghz * 1e-3) * 1e9) / 1e9;
        b->group[c] = i;
        b->netd_k[c] = o->netd_k; /* resolve_netd or bands_values may replace it */
    }
    b->setup = (bands_setup){.scene_path = b->scene_path,
                             .root = b->root,
                             .candidates_thz = b->candidates_thz,
                             .widths = b->widths,
                             .n_candidates = n,
                             .n_targets = o->n_targets,
                             .netd_k = b->netd_k,
                             .target_range_k = o->target_temperature_range_k,
                             .ambient_range_k = o->ambient_temperature_range_k,
                             .humidity_range = o->humidity_range,
                             .thickness_range = o->thickness_range,
                             .angle_range_deg = o->angle_range_deg,
                             .paths_per_sample = o->paths_per_sample};
    st = resolve_scene(b, o, err);
    if (st != THZ_OK)
        goto done;
    b->setup.targets = b->targets;
    st = bands_values_compute(ctx, &b->setup, &b->values, err);
    if (st != THZ_OK)
        goto done;
    bands_classes cl = {.n_candidates = n,
                        .n_classes = b->values.n_classes,
                        .mean = b->values.mean,
                        .cov = b->values.cov,
                        .group = b->group};
    st = bands_search(&cl, o->count, o->exhaustive_limit ? o->exhaustive_limit : 2000000,
                      &b->search, err);
    if (st == THZ_OK)
        st = check_worst_pair(ctx, b, err);
    if (st != THZ_OK)
        goto done;
    bands_report rep = make_report(b);
    b->json = bands_json(&rep, err);
    if (!b->json)
        st = err->status;
done:
    if (st != THZ_OK) {
        thz_bands_destroy(b);
        return api_done(ctx, st, err);
    }
    *out = b;
    return THZ_OK;
}

void thz_bands_get_info(const thz_bands *b, thz_bands_info *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!b)
        return;
    out->n_candidates = b->setup.n_candidates;
    out->count = b->search.count;
    out->n_classes = b->values.n_classes;
    out->search = b->search.search;
    out->score = b->search.scores[b->search.count - 1].worst_jm;
}

double thz_bands_selected_thz(const thz_bands *b, size_t i)
{
    if (!b || i >= b->search.count)
        return NAN;
    size_t K = b->search.count;
    return b->candidates_thz[b->search.sets[(K - 1) * K + i]];
}

double thz_bands_selected_relative_width(const thz_bands *b, size_t i)
{
    if (!b || i >= b->search.count)
        return NAN;
    size_t K = b->search.count;
    return b->widths[b->search.sets[(K - 1) * K + i]];
}

double thz_bands_score(const thz_bands *b, size_t k)
{
    return b && k >= 1 && k <= b->search.count ? b->search.scores[k - 1].worst_jm : NAN;
}

const char *thz_bands_json(const thz_bands *b)
{
    return b ? b->json : NULL;
}

thz_status thz_bands_write(const thz_bands *b, const char *outdir, thz_error *err)
{
    if (!b || !outdir || !outdir[0])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_bands_write: no %s",
                             b ? "output directory" : "band selection");
    output_stage *stage = NULL;
    thz_status st = output_stage_create(outdir, &stage, err);
    if (st != THZ_OK)
        return st;
    /* an earlier run's bands-air.png does not stay beside a scene whose air is clear */
    for (size_t i = 0; i < BANDS_OUTPUT_FILES && st == THZ_OK; i++)
        st = output_stage_claim(stage, bands_output_files[i], err);
    bands_report rep = make_report(b);
    if (st == THZ_OK)
        st = bands_write_files(output_stage_dir(stage), &rep, b->json, err);
    if (st != THZ_OK)
        output_stage_error_names_outdir(stage, err);
    if (st == THZ_OK)
        st = output_stage_commit(stage, err);
    output_stage_destroy(stage);
    return st;
}
