/* The public API of classification (thzmap/analysis.h): a handle over
 * analysis/classify.c, on cubes (api_cube.c) or a run directory's files. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "analysis/classify.h"
#include "analysis/classify_output.h"
#include "api/api.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/file.h"
#include "core/path.h"
#include "io/envi.h"
#include "io/output.h"
#include "thzmap/thzmap.h"

struct thz_classification {
    classify_result r;
    classify_method method;
    char *sensor, *source, *run_dir;
    uint32_t columns, rows;
    char **class_names; /* n_classes */
    char **object_names;
    size_t n_object_names;
    uint64_t seed;
    double train_fraction, netd_k;
    char *json;
};

/* ---- classification ------------------------------------------------------------------ */

void thz_classify_options_init(thz_classify_options *opt)
{
    if (!opt)
        return;
    memset(opt, 0, sizeof *opt);
    opt->method = "sam";
    opt->train_fraction = 0.5;
    opt->seed = 1;
}

const char *thz_classify_method(size_t i)
{
    return i < CLASSIFY_METHOD_COUNT ? classify_method_name((classify_method)i) : NULL;
}

void thz_classification_destroy(thz_classification *c)
{
    if (!c)
        return;
    if (c->class_names)
        for (size_t k = 0; k < c->r.n_classes; k++)
            free(c->class_names[k]);
    free(c->class_names);
    for (size_t i = 0; i < c->n_object_names; i++)
        free(c->object_names[i]);
    free(c->object_names);
    classify_result_fini(&c->r);
    free(c->sensor);
    free(c->source);
    free(c->run_dir);
    free(c->json);
    free(c);
}

static thz_status classify_check_options(const thz_classify_options *opt, classify_method *m,
                                         thz_error *err)
{
    int method = classify_method_from_name(opt->method ? opt->method : "sam");
    if (method < 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "unknown method '%s' (expected sam, mahalanobis, lda, "
                             "matched-filter or ace)",
                             opt->method);
    if (!(opt->train_fraction > 0.0 && opt->train_fraction < 1.0))
        return thz_error_set(err, THZ_ERR_INPUT, "training fraction %g: expected 0 < f < 1",
                             opt->train_fraction);
    if (!(opt->netd_k >= 0.0) || !isfinite(opt->netd_k))
        return thz_error_set(err, THZ_ERR_INPUT, "NETD %g K: expected a number >= 0", opt->netd_k);
    if (opt->seed > (uint64_t)INT64_MAX) /* classification.json records it exactly */
        return thz_error_set(err, THZ_ERR_INPUT, "seed %llu: expected 0 to %lld",
                             (unsigned long long)opt->seed, (long long)INT64_MAX);
    *m = (classify_method)method;
    return THZ_OK;
}

/* What classification.json and the class images say, from c. */
static classify_report report_of(const thz_classification *c)
{
    return (classify_report){.result = &c->r,
                             .run_dir = c->run_dir,
                             .sensor = c->sensor,
                             .source = c->source,
                             .method = c->method,
                             .seed = c->seed,
                             .train_fraction = c->train_fraction,
                             .netd_k = c->netd_k,
                             .columns = c->columns,
                             .rows = c->rows,
                             .class_names = (const char *const *)c->class_names,
                             .object_names = c->object_names,
                             .n_object_names = c->n_object_names};
}

/* Classifies, names the classes, and makes the JSON text. */
static thz_status classify_build(const thz_cube *cube, const thz_cube *truth,
                                 const thz_classify_options *opt, const char *run_dir,
                                 const char *sensor, thz_classification **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_classify: no place for the classification");
    *out = NULL;
    thz_classify_options defaults;
    thz_classify_options_init(&defaults);
    if (!opt)
        opt = &defaults;
    if (!cube || !truth)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_classify_cube: no cube or truth");
    classify_method method = CLASSIFY_SAM;
    thz_status st = classify_check_options(opt, &method, err);
    if (st != THZ_OK)
        return st;
    const envi_cube *cc = &cube->c, *tc = &truth->c;
    if (tc->bands != 1 || tc->samples != cc->samples || tc->lines != cc->lines)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: the truth is %u x %u with %zu bands; expected one band of "
                             "%u x %u like %s",
                             truth->stem, tc->samples, tc->lines, tc->bands, cc->samples, cc->lines,
                             cube->stem);
    /* In one band every positive spectrum has the angle 0 to every class: SAM would give
     * every pixel to the first class (37.5 % on plate-in-box, with no word of why). ACE's
     * squared cosine is 1 for every pixel there, its sign only the side of the background
     * mean: every class scored +-1, ties to the first (0.42 on three separable classes). */
    if ((method == CLASSIFY_SAM || method == CLASSIFY_ACE) && cc->bands < 2)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s has 1 channel: %s compares spectral shapes (%s), which needs 2 "
                             "channels or more; use another method: mahalanobis, lda or "
                             "matched-filter",
                             cube->stem, method == CLASSIFY_SAM ? "sam" : "ace",
                             method == CLASSIFY_SAM ? "the angle between spectra"
                                                    : "a pixel's whitened cosine to a target's");
    size_t pixels = (size_t)cc->samples * cc->lines;
    thz_classification *c = thz_calloc(1, sizeof *c);
    int32_t *ids = thz_calloc(pixels, sizeof *ids);
    float *values = thz_malloc_array(pixels * cc->bands, sizeof *values);
    double *sigma = thz_calloc(cc->bands, sizeof *sigma);
    if (!c || !ids || !values || !sigma) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t p = 0; p < pixels; p++) {
        float v = tc->data[p];
        if (!(v == floorf(v) && v >= -1.0f && v < 16777216.0f)) {
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: pixel %zu holds %g, not an object index or -1", truth->stem, p,
                               (double)v);
            goto done;
        }
        ids[p] = (int32_t)v;
    }
    /* what classify_run would refuse in terms of pixels: here, in the files' terms */
    int32_t first = -1;
    bool two = false;
    for (size_t p = 0; p < pixels && !two; p++) {
        if (ids[p] >= 0 && first < 0)
            first = ids[p];
        two = ids[p] >= 0 && ids[p] != first;
    }
    if (!two) {
        st = first < 0 ? thz_error_set(err, THZ_ERR_INPUT,
                                       "%s%s%s: the truth map shows no object (all -1)",
                                       run_dir ? run_dir : "", run_dir ? "/" : "", truth->stem)
                       : thz_error_set(err, THZ_ERR_INPUT,
                                       "%s%s%s: the truth map shows one object only (index %d): "
                                       "nothing to tell it from; classify needs two classes",
                                       run_dir ? run_dir : "", run_dir ? "/" : "", truth->stem,
                                       (int)first);
        goto done;
    }
    for (size_t i = 0; i < pixels * cc->bands; i++)
        if (!isfinite(cc->data[i])) {
            size_t p = i % pixels;
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s%s%s: band %zu, row %zu, column %zu holds a value that is not "
                               "finite",
                               run_dir ? run_dir : "", run_dir ? "/" : "", cube->stem,
                               i / pixels + 1, p / cc->samples + 1, p % cc->samples + 1);
            goto done;
        }
    memcpy(values, cc->data, pixels * cc->bands * sizeof *values);
    for (size_t b = 0; b < cc->bands; b++)
        sigma[b] = opt->netd_k;
    if (opt->netd_k > 0.0)
        classify_add_noise(values, cc->bands, pixels, sigma, opt->seed);
    st = classify_run(values, cc->bands, pixels, ids, method, opt->train_fraction, opt->seed, &c->r,
                      err);
    if (st != THZ_OK) {
        thz_error_prefix(err, "%s: ", cube->stem);
        goto done;
    }
    c->method = method;
    c->columns = cc->samples;
    c->rows = cc->lines;
    c->seed = opt->seed;
    c->train_fraction = opt->train_fraction;
    c->netd_k = opt->netd_k;
    c->source = thz_strdup(cube->stem);
    c->sensor = thz_strdup(sensor);
    c->run_dir = thz_strdup(run_dir);
    c->class_names = thz_calloc(c->r.n_classes, sizeof *c->class_names);
    c->object_names = thz_calloc(tc->n_object_names, sizeof *c->object_names);
    if (!c->source || !c->class_names || !c->object_names || (sensor && !c->sensor) ||
        (run_dir && !c->run_dir)) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < tc->n_object_names; i++, c->n_object_names++)
        if (!(c->object_names[i] = thz_strdup(tc->object_names[i]))) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            goto done;
        }
    for (size_t k = 0; k < c->r.n_classes; k++) {
        size_t o = (size_t)c->r.class_object[k];
        char name[64];
        snprintf(name, sizeof name, "object %zu", o);
        c->class_names[k] = thz_strdup(o < tc->n_object_names ? tc->object_names[o] : name);
        if (!c->class_names[k]) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
    classify_report rep = report_of(c);
    c->json = classify_json(&rep, err);
    if (!c->json)
        st = err ? err->status : THZ_ERR_NOMEM;
done:
    free(ids);
    free(values);
    free(sigma);
    if (st != THZ_OK) {
        thz_classification_destroy(c);
        return st;
    }
    *out = c;
    return THZ_OK;
}

thz_status thz_classify_cube(const thz_cube *cube, const thz_cube *truth,
                             const thz_classify_options *opt, thz_classification **out,
                             thz_error *err)
{
    return classify_build(cube, truth, opt, NULL, NULL, out, err);
}

/* "S.<quantity>" as the run names its files (io/output.h). */
static thz_status run_stem(char *buf, size_t size, const char *sensor, const char *quantity,
                           thz_error *err)
{
    if (!output_file_name(buf, size, sensor, quantity, ""))
        return thz_error_set(err, THZ_ERR_INPUT, "sensor name too long: %.64s...", sensor);
    return THZ_OK;
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A sensor the run in RUN_DIR does not have (neither S.measured_brightness_temperature.hdr
 * nor S.brightness_temperature.hdr there) was said as the cube file that cannot be opened,
 * leaving the user to guess the sensors' names: refused naming the sensors the run has, by
 * its *.brightness_temperature.hdr files; a RUN_DIR that is not there, so. THZ_OK when the
 * cube is there or RUN_DIR cannot be listed otherwise (its reads then say what is wrong). `cube` is
 * S.brightness_temperature without ".hdr", `measured` S.measured_brightness_temperature.hdr. */
static thz_status check_run_sensor(const char *run_dir, const char *sensor, const char *cube,
                                   const char *measured, thz_error *err)
{
    char path[THZ_PATH_MAX], cube_hdr[THZ_PATH_MAX];
    struct stat st;
    if (snprintf(cube_hdr, sizeof cube_hdr, "%s.hdr", cube) >= (int)sizeof cube_hdr)
        return THZ_OK;
    const char *names[2] = {cube_hdr, measured};
    for (int i = 0; i < 2; i++)
        if (thz_path_join(path, sizeof path, run_dir, names[i], NULL) != THZ_OK ||
            stat(path, &st) == 0 || errno != ENOENT)
            return THZ_OK;
    DIR *dir = opendir(run_dir);
    if (!dir && (errno == ENOENT || errno == ENOTDIR)) /* it said the cube's file */
        return thz_error_set(err, THZ_ERR_INPUT, "%s: no run directory there (%s)", run_dir,
                             strerror(errno));
    if (!dir)
        return THZ_OK;
    static const char suffix[] = ".brightness_temperature.hdr";
    const size_t ns = sizeof suffix - 1;
    char **found = NULL;
    size_t n = 0, cap = 0;
    thz_status status = THZ_OK;
    for (struct dirent *e; (e = readdir(dir));) {
        size_t len = strlen(e->d_name);
        if (len <= ns || strcmp(e->d_name + len - ns, suffix) != 0)
            continue;
        char **grown = n < cap ? found : thz_grow_array(found, &cap, 8, sizeof *found);
        if (!grown) {
            status = THZ_ERR_NOMEM;
            break;
        }
        found = grown;
        found[n] = malloc(len - ns + 1);
        if (!found[n]) {
            status = THZ_ERR_NOMEM;
            break;
        }
        memcpy(found[n], e->d_name, len - ns);
        found[n++][len - ns] = '\0';
    }
    closedir(dir);
    if (status == THZ_OK) {
        if (n > 1) /* found is NULL for none */
            qsort(found, n, sizeof *found, compare_names);
        /* whole names, as many as leave the message room for its paths (err holds 1024
         * bytes), then how many more */
        char list[400] = "", more[48] = "";
        size_t used = 0, listed = 0;
        for (; listed < n; listed++) {
            int w = snprintf(list + used, sizeof list - used, "%s\"%s\"", listed ? ", " : "",
                             found[listed]);
            if (w < 0 || (size_t)w >= sizeof list - used) {
                list[used] = '\0';
                break;
            }
            used += (size_t)w;
        }
        if (listed < n)
            snprintf(more, sizeof more, "%s%zu more", listed ? " and " : "", n - listed);
        if (n == 0)
            status = thz_error_set(err, THZ_ERR_INPUT,
                                   "%s: the run there has no sensor \"%s\", nor any other (no "
                                   "*.brightness_temperature.hdr: not a directory thzmap "
                                   "simulate wrote?)",
                                   run_dir, sensor);
        else
            status = thz_error_set(err, THZ_ERR_INPUT,
                                   "%s: the run there has no sensor \"%s\"; its sensor%s: %s%s",
                                   run_dir, sensor, n == 1 ? "" : "s", list, more);
    } else {
        status = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    for (size_t i = 0; i < n; i++)
        free(found[i]);
    free(found);
    return status;
}

thz_status thz_classify_run(const char *run_dir, const char *sensor,
                            const thz_classify_options *opt, thz_classification **out,
                            thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_classify_run: no place for the classification");
    *out = NULL;
    if (!run_dir || !sensor || !sensor[0])
        return thz_error_set(err, THZ_ERR_INPUT, "no run directory or sensor given");
    char stem[THZ_PATH_MAX], truth_stem[THZ_PATH_MAX], name[THZ_PATH_MAX], path[THZ_PATH_MAX];
    thz_status st = run_stem(stem, sizeof stem, sensor, "measured_brightness_temperature.hdr", err);
    if (st == THZ_OK)
        st = thz_path_join(path, sizeof path, run_dir, stem, err);
    if (st == THZ_OK)
        st = run_stem(truth_stem, sizeof truth_stem, sensor, "object_id", err);
    if (st == THZ_OK)
        st = run_stem(name, sizeof name, sensor, "brightness_temperature", err);
    if (st == THZ_OK)
        st = check_run_sensor(run_dir, sensor, name, stem, err);
    if (st != THZ_OK)
        return st;
    /* RUN_DIR is read a file at a time: a run that committed its results there meanwhile
     * (another process's simulate into it) paired one run's cube with the other's truth,
     * a classification of neither (accuracy 0.27 where each run alone gives 0.99). The
     * directory, the same before and after the reads (a commit replaces it, or renames
     * files into it: a new inode or a new modification time), says that none did; else
     * it is read again. */
    thz_cube *cube = NULL, *truth = NULL;
    for (int attempt = 0;; attempt++) {
        struct stat before, after;
        bool known = stat(run_dir, &before) == 0; /* else its reads say what is wrong */
        char cube_stem[THZ_PATH_MAX];
        /* the measured cube where the sensor has noise; the noise-free one where it has
         * none (no measured header). A measured header that is there but cannot be read
         * is an error: the noise-free cube instead would be classified without the
         * noise the user's sensor has, silently. */
        struct stat hs;
        st = THZ_OK;
        if (lstat(path, &hs) == 0) {
            st = file_check_regular(path, NULL, ENVI_MAX_HEADER_BYTES, NULL, err);
            snprintf(cube_stem, sizeof cube_stem, "%.*s", (int)(strlen(stem) - 4),
                     stem); /* the measured cube: without ".hdr" */
        } else {
            memcpy(cube_stem, name, sizeof cube_stem);
        }
        if (st == THZ_OK)
            st = thz_cube_read(run_dir, cube_stem, &cube, err);
        if (st == THZ_OK)
            st = thz_cube_read(run_dir, truth_stem, &truth, err);
        bool stable = !known || (stat(run_dir, &after) == 0 && file_dir_unchanged(&before, &after));
        if (stable)
            break;
        thz_cube_destroy(cube);
        thz_cube_destroy(truth);
        cube = truth = NULL;
        if (attempt == 9) {
            st = thz_error_set(err, THZ_ERR_IO,
                               "%s: changed while it was read (a run writing its results "
                               "there?); classify it once that run has ended",
                               run_dir);
            break;
        }
    }
    if (st == THZ_OK)
        st = classify_build(cube, truth, opt, run_dir, sensor, out, err);
    thz_cube_destroy(cube);
    thz_cube_destroy(truth);
    return st;
}

void thz_classification_get_info(const thz_classification *c, thz_classification_info *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!c)
        return;
    out->method = classify_method_name(c->method);
    out->sensor = c->sensor;
    out->source = c->source;
    out->n_classes = c->r.n_classes;
    out->columns = c->columns;
    out->rows = c->rows;
    out->training_pixels = c->r.n_train;
    out->held_out_pixels = c->r.n_held_out;
    out->pixels = c->r.n_train + c->r.n_held_out;
    out->accuracy = c->r.accuracy;
    out->held_out_accuracy = c->r.held_out_accuracy;
}

long thz_classification_class_object(const thz_classification *c, size_t k)
{
    return c && k < c->r.n_classes ? (long)c->r.class_object[k] : -1;
}

const char *thz_classification_class_name(const thz_classification *c, size_t k)
{
    return c && k < c->r.n_classes ? c->class_names[k] : NULL;
}

double thz_classification_class_accuracy(const thz_classification *c, size_t k)
{
    return c && k < c->r.n_classes ? c->r.class_accuracy[k] : NAN;
}

double thz_classification_auc(const thz_classification *c, size_t k)
{
    return c && k < c->r.n_classes ? c->r.auc[k] : NAN;
}

const uint64_t *thz_classification_confusion(const thz_classification *c)
{
    return c ? c->r.confusion : NULL;
}

const int32_t *thz_classification_map(const thz_classification *c)
{
    return c ? c->r.assigned : NULL;
}

const uint8_t *thz_classification_training(const thz_classification *c)
{
    return c ? c->r.train : NULL;
}

const char *thz_classification_json(const thz_classification *c)
{
    return c ? c->json : NULL;
}

thz_status thz_classification_write(const thz_classification *c, const char *outdir, thz_error *err)
{
    if (!c || !outdir || !outdir[0])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_classification_write: no %s",
                             c ? "output directory" : "classification");
    output_stage *stage = NULL;
    thz_status st = output_stage_create(outdir, &stage, err);
    if (st != THZ_OK)
        return st;
    classify_report rep = report_of(c);
    st = classify_write_files(output_stage_dir(stage), &rep, c->json, err);
    if (st != THZ_OK)
        output_stage_error_names_outdir(stage, err);
    if (st == THZ_OK)
        st = output_stage_commit(stage, err);
    output_stage_destroy(stage);
    return st;
}
