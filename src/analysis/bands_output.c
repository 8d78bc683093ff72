/* The files of a band selection (bands_output.h). */
#include "analysis/bands_output.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/json_text.h"
#include "core/path.h"
#include "io/plot.h"

static void put(json_t *obj, const char *key, json_t *v, bool *ok)
{
    if (!obj || !v || json_object_set_new(obj, key, v) != 0)
        *ok = false;
}

static void push(json_t *arr, json_t *v, bool *ok)
{
    if (!arr || !v || json_array_append_new(arr, v) != 0)
        *ok = false;
}

static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *array_of(const double *v, size_t n, bool *ok)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        push(a, num(v[i]), ok);
    return a;
}

/* The chosen centres of the best set of size k, THz, ascending. */
static json_t *set_thz(const bands_report *rep, size_t k, bool *ok)
{
    json_t *a = json_array();
    const size_t *set = rep->search->sets + (k - 1) * rep->search->count;
    for (size_t i = 0; i < k; i++)
        push(a, json_real(rep->setup->candidates_thz[set[i]]), ok);
    return a;
}

/* Their relative widths, aligned with set_thz. */
static json_t *set_widths(const bands_report *rep, size_t k, bool *ok)
{
    json_t *a = json_array();
    const size_t *set = rep->search->sets + (k - 1) * rep->search->count;
    for (size_t i = 0; i < k; i++)
        push(a, json_real(rep->setup->widths[set[i]]), ok);
    return a;
}

static json_t *pair_names(const bands_report *rep, const bands_score *s, bool *ok)
{
    json_t *a = json_array();
    push(a, json_string(rep->values->class_names[s->worst_pair[0]]), ok);
    push(a, json_string(rep->values->class_names[s->worst_pair[1]]), ok);
    return a;
}

char *bands_json(const bands_report *rep, thz_error *err)
{
    const bands_setup *s = rep->setup;
    const bands_values *v = rep->values;
    const bands_search_result *r = rep->search;
    size_t K = r->count, n = s->n_candidates;
    const bands_score *final = &r->scores[K - 1];
    bool ok = true;
    json_t *root = json_object();
    put(root, "thzmap_version", json_string(THZ_VERSION_STRING), &ok);
    put(root, "thzmap_revision", json_string(thz_revision()), &ok);
    put(root, "scene", thz_json_text(rep->scene_path), &ok);
    put(root, "scene_name", json_string(rep->scene_name), &ok);
    put(root, "sensor", json_string(rep->sensor), &ok);
    put(root, "count", json_integer((json_int_t)K), &ok);
    put(root, "selected_thz", set_thz(rep, K, &ok), &ok);
    put(root, "selected_relative_width", set_widths(rep, K, &ok), &ok);
    put(root, "score", json_real(final->worst_jm), &ok);
    put(root, "criterion",
        json_string("worst-pair Jeffries-Matusita distance JM = 2 (1 - exp(-B)) of Gaussian "
                    "classes, 0..2 (B: Bhattacharyya distance)"),
        &ok);
    put(root, "bhattacharyya", num(final->worst_b), &ok);
    put(root, "mean_jm", num(final->mean_jm), &ok);
    put(root, "worst_pair", pair_names(rep, final, &ok), &ok);
    put(root, "monte_carlo_bhattacharyya", num(rep->noise_b), &ok);
    json_t *warnings = json_array();
    put(root, "warnings", warnings, &ok);
    if (rep->warning)
        push(warnings, json_string(rep->warning), &ok);
    put(root, "search", json_string(r->search), &ok);
    put(root, "sets_scored", json_integer((json_int_t)r->evaluations), &ok);
    json_t *per_k = json_array();
    put(root, "per_k", per_k, &ok);
    for (size_t k = 1; k <= K && ok; k++) {
        json_t *e = json_object();
        push(per_k, e, &ok);
        put(e, "k", json_integer((json_int_t)k), &ok);
        put(e, "selected_thz", set_thz(rep, k, &ok), &ok);
        put(e, "selected_relative_width", set_widths(rep, k, &ok), &ok);
        put(e, "score", json_real(r->scores[k - 1].worst_jm), &ok);
        put(e, "bhattacharyya", num(r->scores[k - 1].worst_b), &ok);
        put(e, "mean_jm", num(r->scores[k - 1].mean_jm), &ok);
        put(e, "worst_pair", pair_names(rep, &r->scores[k - 1], &ok), &ok);
    }
    json_t *cand = json_object();
    put(root, "candidates", cand, &ok);
    put(cand, "from_thz", json_real(rep->from_thz), &ok);
    put(cand, "to_thz", json_real(rep->to_thz), &ok);
    put(cand, "step_ghz", json_real(rep->step_ghz), &ok);
    /* one width: a number, as before widths could be searched; several: null */
    put(cand, "relative_width", rep->n_widths == 1 ? json_real(rep->width_list[0]) : json_null(),
        &ok);
    put(cand, "relative_widths", array_of(rep->width_list, rep->n_widths, &ok), &ok);
    put(cand, "frequency_thz", array_of(s->candidates_thz, n, &ok), &ok);
    put(cand, "candidate_relative_width", array_of(s->widths, n, &ok), &ok);
    json_t *noise = json_object();
    put(root, "noise", noise, &ok);
    put(noise, "source", json_string(rep->netd_source), &ok);
    put(noise, "netd_k", array_of(s->netd_k, n, &ok), &ok);
    json_t *nu = json_object();
    put(root, "nuisances", nu, &ok);
    put(nu, "target_temperature_range_k", json_real(s->target_range_k), &ok);
    put(nu, "ambient_temperature_range_k", json_real(s->ambient_range_k), &ok);
    put(nu, "air_temperature_varied", json_boolean(v->air_temperature_varied), &ok);
    put(nu, "humidity_range", json_real(s->humidity_range), &ok);
    put(nu, "humidity_varied", json_boolean(v->humidity_varied), &ok);
    put(nu, "thickness_range", json_real(s->thickness_range), &ok);
    put(nu, "thickness_varied", json_boolean(v->thickness_varied), &ok);
    put(nu, "angle_range_deg", json_real(s->angle_range_deg), &ok);
    put(nu, "angle_varied", json_boolean(v->angle_varied), &ok);
    put(nu, "render_paths_per_sample", json_integer(v->coarse_paths), &ok);
    put(nu, "render_oversampling", json_integer(1), &ok);
    json_t *classes = json_array();
    put(root, "classes", classes, &ok);
    for (size_t k = 0; k < v->n_classes && ok; k++) {
        json_t *c = json_object();
        push(classes, c, &ok);
        put(c, "name", json_string(v->class_names[k]), &ok);
        put(c, "pixels", json_integer((json_int_t)v->class_pixels[k]), &ok);
        put(c, "mean_tb_k", array_of(v->mean + k * n, n, &ok), &ok);
        put(c, "pixel_sd_k", array_of(v->pixel_sd + k * n, n, &ok), &ok);
        put(c, "nuisance_sd_k", array_of(v->nuisance_sd + k * n, n, &ok), &ok);
        put(c, "netd_k", array_of(v->netd_k + k * n, n, &ok), &ok);
    }
    put(root, "air_attenuation_db_per_km",
        rep->air_db_per_km ? array_of(rep->air_db_per_km, n, &ok) : json_null(), &ok);
    put(root, "renders", json_integer((json_int_t)v->renders), &ok);
    put(root, "paths_per_sample", json_integer(s->paths_per_sample), &ok);
    put(root, "seed", json_integer((json_int_t)s->seed), &ok);
    put(root, "seconds", json_real(v->seconds), &ok);
    char *text =
        ok ? json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))
           : NULL;
    json_decref(root);
    if (!text)
        thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    return text;
}

/* Appends to title (size bytes, *used of them taken); stops quietly when it is full. */
__attribute__((format(printf, 4, 5))) static void
bands_title_add(char *title, size_t size, size_t *used, const char *fmt, ...)
{
    if (*used >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(title + *used, size - *used, fmt, ap);
    va_end(ap);
    *used = n < 0 ? size : *used + (size_t)n;
}

static thz_status join(char *path, const char *dir, const char *name, thz_error *err)
{
    return thz_path_join(path, THZ_PATH_MAX, dir, name, err);
}

enum { BANDS_JSON, BANDS_SCORE_PNG, BANDS_SPECTRA_PNG, BANDS_AIR_PNG };
const char *const bands_output_files[BANDS_OUTPUT_FILES] = {[BANDS_JSON] = "bands.json",
                                                            [BANDS_SCORE_PNG] = "bands-score.png",
                                                            [BANDS_SPECTRA_PNG] =
                                                                "bands-spectra.png",
                                                            [BANDS_AIR_PNG] = "bands-air.png"};

thz_status bands_write_files(const char *dir, const bands_report *rep, const char *json_text,
                             thz_error *err)
{
    const bands_setup *s = rep->setup;
    const bands_values *v = rep->values;
    const bands_search_result *r = rep->search;
    size_t K = r->count, n = s->n_candidates, nw = rep->n_widths, nx = n / nw;
    char path[THZ_PATH_MAX], title[1024];
    thz_status st = plot_check_device(err);
    if (st == THZ_OK)
        st = join(path, dir, bands_output_files[BANDS_JSON], err);
    if (st != THZ_OK)
        return st;
    st = file_write_text(path, json_text, err);
    if (st != THZ_OK)
        return st;

    /* the spectra and the air over the centres, at the narrowest width searched */
    double *x = thz_calloc(K > n ? K : n, sizeof *x), *y = thz_calloc(K, sizeof *y);
    double *fx = thz_calloc(nx, sizeof *fx), *my = thz_calloc(v->n_classes * nx, sizeof *my);
    double *air = thz_calloc(nx, sizeof *air);
    plot_band *bands = thz_calloc(K, sizeof *bands);
    char(*names)[32] = thz_calloc(K, sizeof *names);
    if (!x || !y || !fx || !my || !air || !bands || !names) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < nx; i++) {
        fx[i] = s->candidates_thz[i * nw];
        air[i] = rep->air_db_per_km ? rep->air_db_per_km[i * nw] : 0.0;
        for (size_t k = 0; k < v->n_classes; k++)
            my[k * nx + i] = v->mean[k * n + i * nw];
    }
    for (size_t k = 0; k < K; k++) {
        x[k] = (double)(k + 1);
        y[k] = r->scores[k].worst_jm;
    }
    const char *score_name[] = {"worst pair"};
    snprintf(title, sizeof title, "%s: best set of K channels (%s)", rep->scene_name, r->search);
    st = join(path, dir, bands_output_files[BANDS_SCORE_PNG], err);
    if (st == THZ_OK)
        st = plot_lines_whole_x(path, K, x, 1, score_name, y, title, "channels K",
                                "Jeffries-Matusita distance (0..2)", err);
    /* The chosen centres, each width's together: "0.28 THz (relative width 0.01); 0.12,
     * 0.3 THz (relative width 0.03)" (a bare "(0.01)" read as a frequency) */
    size_t used = 0;
    bands_title_add(title, sizeof title, &used, "%s: mean Tb per class; chosen:", rep->scene_name);
    const size_t *set = r->sets + (K - 1) * K;
    bool first_group = true;
    for (size_t w = 0; w < nw; w++) {
        size_t in_group = 0;
        for (size_t i = 0; i < K; i++)
            if (set[i] % nw == w) /* candidates are centre-major */
                bands_title_add(title, sizeof title, &used, "%s %.4g",
                                in_group++    ? ","
                                : first_group ? ""
                                              : ";",
                                s->candidates_thz[set[i]]);
        if (!in_group)
            continue;
        first_group = false;
        if (nw > 1)
            bands_title_add(title, sizeof title, &used, " THz (relative width %.3g)",
                            rep->width_list[w]);
        else
            bands_title_add(title, sizeof title, &used, " THz");
    }
    if (st == THZ_OK)
        st = join(path, dir, bands_output_files[BANDS_SPECTRA_PNG], err);
    if (st == THZ_OK)
        st = plot_lines(path, nx, fx, v->n_classes, (const char *const *)v->class_names, my, title,
                        nw > 1 ? "frequency (THz), at the narrowest width" : "frequency (THz)",
                        "brightness temperature (K)", err);
    if (st == THZ_OK && rep->air_db_per_km) {
        for (size_t i = 0; i < K; i++) {
            double f0 = s->candidates_thz[set[i]], half = 0.5 * s->widths[set[i]] * f0;
            snprintf(names[i], sizeof names[i], "%.4g THz", f0);
            bands[i] =
                (plot_band){.name = names[i], .lo = f0 - half, .centre = f0, .hi = f0 + half};
        }
        plot_curve curve = {.name = "air", .y = air, .rgb = {31, 119, 180}, .width = 2.0};
        snprintf(title, sizeof title, "%s: the air's attenuation and the chosen channels",
                 rep->scene_name);
        st = join(path, dir, bands_output_files[BANDS_AIR_PNG], err);
        if (st == THZ_OK)
            st = plot_attenuation(path, nx, fx, 1, &curve, K, bands, title, "frequency (THz)",
                                  "attenuation (dB/km)", err);
    }
done:
    free(x);
    free(y);
    free(fx);
    free(my);
    free(air);
    free(bands);
    free(names);
    return st;
}
