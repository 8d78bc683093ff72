/* The files of a classification (classify_output.h): classification.json, the class
 * map as ENVI and as a figure in a qualitative palette with a legend. */
#include "analysis/classify_output.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/json_text.h"
#include "core/path.h"
#include "io/envi.h"
#include "io/output.h"
#include "io/plot.h"

/* The first classes' colours (sRGB 0..255): a qualitative palette of 20, its first ten
 * the common "tab10" and then their lighter companions ("tab20"). */
static const unsigned char class_palette[20][3] = {
    {31, 119, 180},  {255, 127, 14},  {44, 160, 44},   {214, 39, 40},   {148, 103, 189},
    {140, 86, 75},   {227, 119, 194}, {127, 127, 127}, {188, 189, 34},  {23, 190, 207},
    {174, 199, 232}, {255, 187, 120}, {152, 223, 138}, {255, 152, 150}, {197, 176, 213},
    {196, 156, 148}, {247, 182, 210}, {199, 199, 199}, {219, 219, 141}, {158, 218, 229},
};

/* Squared sRGB distance. */
static int colour_distance2(const unsigned char *a, const unsigned char *b)
{
    int d = 0;
    for (int i = 0; i < 3; i++)
        d += ((int)a[i] - b[i]) * ((int)a[i] - b[i]);
    return d;
}

/* Candidate j beyond the palette: hue by the golden ratio, saturation 0.45-0.95 and
 * value 0.55-0.95 (never near the black of "nothing hit") by a plastic-number sequence,
 * so that successive candidates lie far apart. */
static void colour_candidate(size_t j, unsigned char *rgb)
{
    double h = fmod(0.5 + (double)j * 0.6180339887498949, 1.0) * 6.0;
    double s = 0.45 + 0.5 * fmod((double)j * 0.7548776662466927, 1.0);
    double v = 0.55 + 0.4 * fmod((double)j * 0.5698402909980532, 1.0);
    double f = h - floor(h), p = v * (1.0 - s), q = v * (1.0 - s * f),
           t = v * (1.0 - s * (1.0 - f));
    double c[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
    int sector = (int)h % 6;
    for (int i = 0; i < 3; i++)
        rgb[i] = (unsigned char)lround(255.0 * c[sector][i]);
}

void classify_class_colours(size_t n_classes, unsigned char (*rgb)[3])
{
    static const unsigned char black[3] = {0, 0, 0}, white[3] = {255, 255, 255};
    /* the distance (squared) a new colour keeps from every earlier one, black (nothing
     * hit) and white (the page): halved after 64 candidates in a row fail, down to 1
     * (merely different), so that it ends for any count */
    int min_d2 = 40 * 40, failed = 0;
    size_t j = 0;
    for (size_t k = 0; k < n_classes; k++) {
        if (k < 20) {
            memcpy(rgb[k], class_palette[k], sizeof rgb[k]);
            continue;
        }
        for (;; j++) {
            colour_candidate(j, rgb[k]);
            bool ok = colour_distance2(rgb[k], black) >= min_d2 &&
                      colour_distance2(rgb[k], white) >= min_d2;
            for (size_t i = 0; i < k && ok; i++)
                ok = colour_distance2(rgb[k], rgb[i]) >= min_d2;
            if (ok)
                break;
            if (++failed == 64) {
                failed = 0;
                min_d2 = min_d2 > 1 ? min_d2 / 2 : 1;
            }
        }
        j++;
        failed = 0;
    }
}

static void put(json_t *obj, const char *key, json_t *v, bool *ok)
{
    if (!v || json_object_set_new(obj, key, v) != 0)
        *ok = false;
}

static void push(json_t *arr, json_t *v, bool *ok)
{
    if (!v || json_array_append_new(arr, v) != 0)
        *ok = false;
}

static json_t *real_or_null(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

char *classify_json(const classify_report *rep, thz_error *err)
{
    const classify_result *r = rep->result;
    size_t nc = r->n_classes;
    bool ok = true;
    unsigned char(*rgb)[3] = thz_malloc_array(nc + 1, sizeof *rgb);
    json_t *root = rgb ? json_object() : NULL;
    if (!root)
        goto nomem;
    classify_class_colours(nc, rgb);
    put(root, "thzmap_version", json_string(THZ_VERSION_STRING), &ok);
    put(root, "thzmap_revision", json_string(thz_revision()), &ok);
    put(root, "run_dir", thz_json_text(rep->run_dir), &ok);
    put(root, "sensor", rep->sensor ? json_string(rep->sensor) : json_null(), &ok);
    put(root, "source", json_string(rep->source), &ok);
    put(root, "method", json_string(classify_method_name(rep->method)), &ok);
    put(root, "seed", json_integer((json_int_t)rep->seed), &ok);
    put(root, "train_fraction", json_real(rep->train_fraction), &ok);
    put(root, "added_netd_k", rep->netd_k > 0.0 ? json_real(rep->netd_k) : json_null(), &ok);
    put(root, "columns", json_integer(rep->columns), &ok);
    put(root, "rows", json_integer(rep->rows), &ok);
    uint64_t total = 0;
    for (size_t i = 0; i < nc * nc; i++)
        total += r->confusion[i];
    put(root, "pixels", json_integer((json_int_t)total), &ok);
    put(root, "training_pixels", json_integer((json_int_t)r->n_train), &ok);
    put(root, "held_out_pixels", json_integer((json_int_t)r->n_held_out), &ok);
    put(root, "accuracy", real_or_null(r->accuracy), &ok);
    put(root, "held_out_accuracy", real_or_null(r->held_out_accuracy), &ok);
    json_t *classes = json_array(), *confusion = json_array();
    put(root, "classes", classes, &ok);
    put(root, "confusion", confusion, &ok);
    for (size_t k = 0; k < nc && ok; k++) {
        json_t *c = json_object(), *row = json_array(), *roc = json_object();
        json_t *fpr = json_array(), *tpr = json_array(), *color = json_array();
        push(classes, c, &ok);
        push(confusion, row, &ok);
        if (!ok || !roc || !fpr || !tpr || !color) {
            json_decref(roc);
            json_decref(fpr);
            json_decref(tpr);
            json_decref(color);
            ok = false;
            break;
        }
        uint64_t n = 0;
        for (size_t j = 0; j < nc; j++) {
            push(row, json_integer((json_int_t)r->confusion[k * nc + j]), &ok);
            n += r->confusion[k * nc + j];
        }
        put(c, "object", json_integer(r->class_object[k]), &ok);
        put(c, "name", json_string(rep->class_names[k]), &ok);
        put(c, "pixels", json_integer((json_int_t)n), &ok);
        put(c, "accuracy", real_or_null(r->class_accuracy[k]), &ok);
        put(c, "auc", real_or_null(r->auc[k]), &ok);
        for (int i = 0; i < 3; i++)
            push(color, json_integer(rgb[k][i]), &ok);
        put(c, "color", color, &ok);
        put(c, "roc", roc, &ok);
        put(roc, "false_positive_rate", fpr, &ok);
        put(roc, "true_positive_rate", tpr, &ok);
        for (size_t i = 0; i < CLASSIFY_ROC_POINTS; i++) {
            push(fpr, real_or_null(r->roc_fpr[k * CLASSIFY_ROC_POINTS + i]), &ok);
            push(tpr, real_or_null(r->roc_tpr[k * CLASSIFY_ROC_POINTS + i]), &ok);
        }
    }
    if (!ok)
        goto nomem;
    char *text = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(root);
    free(rgb);
    if (!text)
        goto nomem_text;
    return text;
nomem:
    json_decref(root);
    free(rgb);
nomem_text:
    thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    return NULL;
}

static thz_status write_text(const char *dir, const char *name, const char *text, thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status st = thz_path_join(path, sizeof path, dir, name, err);
    if (st != THZ_OK)
        return st;
    return file_write_text(path, text, err);
}

thz_status classify_write_files(const char *dir, const classify_report *rep, const char *json_text,
                                thz_error *err)
{
    const classify_result *r = rep->result;
    size_t pixels = (size_t)rep->columns * rep->rows;
    thz_status st = write_text(dir, "classification.json", json_text, err);
    if (st != THZ_OK)
        return st;
    float *map = thz_malloc_array(pixels, sizeof *map);
    int32_t *slot = thz_malloc_array(pixels, sizeof *slot); /* the class, -1: nothing hit */
    unsigned char(*rgb)[3] = thz_malloc_array(r->n_classes + 1, sizeof *rgb);
    if (!map || !slot || !rgb) {
        free(map);
        free(slot);
        free(rgb);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    classify_class_colours(r->n_classes, rgb);
    for (size_t p = 0; p < pixels; p++) {
        map[p] = (float)r->assigned[p];
        size_t k = 0;
        while (k < r->n_classes && r->class_object[k] != r->assigned[p])
            k++;
        slot[p] = k < r->n_classes ? (int32_t)k : -1;
    }
    const char *stem_sensor = rep->sensor ? rep->sensor : "cube";
    char stem[THZ_PATH_MAX], description[1024], png[THZ_PATH_MAX], name[THZ_PATH_MAX], title[1024];
    st = output_file_name(stem, sizeof stem, stem_sensor, "class", "")
             ? THZ_OK
             : thz_error_set(err, THZ_ERR_IO, "sensor %.64s...: file name too long", stem_sensor);
    snprintf(description, sizeof description,
             "thzmap %s: class map of %s by %s: object index of the assigned class (-1: nothing "
             "hit) [1]",
             THZ_VERSION_STRING, rep->source, classify_method_name(rep->method));
    const char *band_names[] = {"class"};
    envi_info info = {.description = description,
                      .data_units = "1",
                      .samples = rep->columns,
                      .lines = rep->rows,
                      .bands = 1,
                      .band_names = band_names,
                      .has_ignore_value = 1,
                      .ignore_value = -1.0,
                      .object_names = (const char *const *)rep->object_names,
                      .n_object_names = rep->n_object_names};
    if (st == THZ_OK)
        st = envi_write_float32(dir, stem, &info, map, err);
    if (st == THZ_OK) {
        int n = snprintf(name, sizeof name, "%.4000s.png", stem);
        st = n > 0 && (size_t)n < sizeof name
                 ? thz_path_join(png, sizeof png, dir, name, err)
                 : thz_error_set(err, THZ_ERR_IO, "%s.png: file name too long", stem);
    }
    snprintf(title, sizeof title, "%.400s: classes by %s", rep->source,
             classify_method_name(rep->method));
    if (st == THZ_OK)
        st = plot_classes(png, slot, rep->columns, rep->rows, r->n_classes, rep->class_names,
                          (const unsigned char(*)[3])rgb, title, err);
    free(map);
    free(slot);
    free(rgb);
    return st;
}
