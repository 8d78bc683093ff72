/* Loading a sequence file ("thzmap-sequence/1"): its keys checked with JSON paths, its
 * keyframes gathered into tracks (one per value a keyframe names, e.g.
 * objects.person.transform.translate_m), every frame's scene built as JSON text from
 * its scene file (the one "scene", tracks interpolated at the frame's time; or the
 * frame's file of the list "scenes"; then the sweep value set) and checked by loading
 * it, and the hash of each frame's inputs.
 */
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/json_text.h"
#include "scene/load.h"

enum { SEQ_MAX_FRAMES = 100000, SEQ_MAX_SWEEPS = 10000, SEQ_MAX_DEPTH = 8 };
#define SEQ_MIN_FPS 1e-9 /* frames per second */

/* A value that keyframes name: its path (segments; objects and sensors by name), and
 * per keyframe that names it the time and n numbers. */
typedef struct seq_track {
    const char *seg[SEQ_MAX_DEPTH];
    size_t depth;
    size_t n;         /* numbers per value: 1 for a number, else the array's length */
    int is_array;     /* the value is an array (even of one number) */
    int all_integers; /* every keyframe value is whole: write whole results as integers */
    int rotation;     /* rotate_deg: slerp */
    size_t k;         /* keyframes naming it */
    double *t, *v;    /* k times; k * n values */
    size_t *kf;       /* k indexes into "keyframes": where each value is written */
} seq_track;

typedef struct seq_build {
    const char *label;    /* the sequence file, in messages */
    json_t **scenes;      /* the scene documents (seq->n_scenes) */
    json_t *scene;        /* the one that keyframe and sweep paths are checked against */
    char scene_name[160]; /* that scene, in messages: "the scene", "scenes[2] (b.json)" */
    seq_track *tracks;
    size_t n_tracks;
    json_t *sweep;       /* the sweep object, or NULL */
    json_t *file_hashes; /* path -> hash of the files frames name (hex string) */
    size_t keyframe;     /* the keyframe being read (its index in "keyframes") */
    thz_error *err;
} seq_build;

static thz_status seq_fail(const seq_build *b, const char *where, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static thz_status seq_fail(const seq_build *b, const char *where, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return thz_error_set(b->err, THZ_ERR_INPUT, "%s: %s: %s", b->label, where, what);
}

static const char *seq_type(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT:
        return "an object";
    case JSON_ARRAY:
        return "an array";
    case JSON_STRING:
        return "a string";
    case JSON_INTEGER:
    case JSON_REAL:
        return "a number";
    case JSON_TRUE:
    case JSON_FALSE:
        return "a boolean";
    default:
        return "null";
    }
}

/* The element of scene[list] ("objects", "sensors") whose "name" is name, or NULL. */
static json_t *seq_named(json_t *scene, const char *list, const char *name)
{
    json_t *arr = json_object_get(scene, list), *e;
    size_t i;
    json_array_foreach(arr, i, e)
    {
        const char *n = json_string_value(json_object_get(e, "name"));
        if (n && strcmp(n, name) == 0)
            return e;
    }
    return NULL;
}

/* Sets the value at path seg[0..depth-1] of doc (objects and sensors by name; missing
 * objects on the way are created); takes a reference to value. */
static int seq_set(json_t *doc, const char *const *seg, size_t depth, json_t *value)
{
    json_t *node = doc;
    size_t i = 0;
    if (depth >= 2 && (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors"))) {
        node = seq_named(doc, seg[0], seg[1]);
        i = 2;
    }
    for (; node && i + 1 < depth; i++) {
        json_t *next = json_object_get(node, seg[i]);
        if (!json_is_object(next)) {
            next = json_object();
            if (json_object_set_new(node, seg[i], next) != 0)
                return -1;
        }
        node = next;
    }
    if (!json_is_object(node))
        return -1;
    return json_object_set(node, seg[depth - 1], value);
}

static const char *const seq_blocks[] = {"objects", "sensors", "atmosphere", "materials"};

/* Checks that the path names something keyframes or sweeps may set: a block of the
 * scene, and an object or sensor the scene has. */
static thz_status seq_check_path(const seq_build *b, const char *where, const char *const *seg,
                                 size_t depth, int leaf)
{
    int known = 0;
    for (size_t i = 0; i < sizeof seq_blocks / sizeof seq_blocks[0]; i++)
        known |= !strcmp(seg[0], seq_blocks[i]);
    if (!known && (!strcmp(seg[0], "photons") || !strcmp(seg[0], "render")))
        known = 1; /* a value of theirs, not the whole block: the leaf check below */
    if (!known)
        return seq_fail(b, where,
                        "\"%s\" cannot be set (expected objects, sensors, atmosphere, materials, "
                        "photons or render)",
                        seg[0]);
    if ((!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors")) && depth >= 2 &&
        !seq_named(b->scene, seg[0], seg[1])) {
        char what[300];
        snprintf(what, sizeof what, "%s has no %s named \"%s\"", b->scene_name,
                 !strcmp(seg[0], "objects") ? "object" : "sensor", seg[1]);
        return seq_fail(b, where, "%s", what);
    }
    if (leaf && depth < (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors") ? 3u : 2u))
        return seq_fail(b, where, "%s",
                        "expected a path to a value, e.g. objects.NAME.temperature_k");
    return THZ_OK;
}

static seq_track *seq_track_find(seq_build *b, const char *const *seg, size_t depth)
{
    for (size_t i = 0; i < b->n_tracks; i++) {
        seq_track *tr = &b->tracks[i];
        if (tr->depth != depth)
            continue;
        size_t j = 0;
        while (j < depth && !strcmp(tr->seg[j], seg[j]))
            j++;
        if (j == depth)
            return tr;
    }
    return NULL;
}

/* Adds keyframe value v (at time t) to the track of path seg; where names it. */
static thz_status seq_add_value(seq_build *b, const char *where, const char *const *seg,
                                size_t depth, double t, const json_t *v)
{
    size_t n = json_is_array(v) ? json_array_size(v) : 1;
    int ok = json_is_number(v) || (json_is_array(v) && n > 0);
    for (size_t i = 0; ok && json_is_array(v) && i < n; i++)
        ok = json_is_number(json_array_get(v, i));
    if (!ok)
        return seq_fail(b, where, "expected a number or an array of numbers, got %s", seq_type(v));
    int rotation = !strcmp(seg[depth - 1], "rotate_deg");
    if (rotation && (!json_is_array(v) || n != 3))
        return seq_fail(b, where, "%s", "expected [rx, ry, rz] in degrees");
    seq_track *tr = seq_track_find(b, seg, depth);
    if (!tr) {
        seq_track *grown = thz_realloc_array(b->tracks, b->n_tracks + 1, sizeof *grown);
        if (!grown)
            return thz_error_set(b->err, THZ_ERR_NOMEM, "%s: out of memory", b->label);
        b->tracks = grown;
        tr = &b->tracks[b->n_tracks++];
        memset(tr, 0, sizeof *tr);
        memcpy(tr->seg, seg, depth * sizeof *seg);
        tr->depth = depth;
        tr->n = n;
        tr->is_array = json_is_array(v);
        tr->all_integers = 1;
        tr->rotation = rotation;
    } else if (tr->n != n || tr->is_array != json_is_array(v)) {
        return seq_fail(b, where, "%s",
                        "expected the same kind of value (number, or array of as many numbers) "
                        "as in the earlier keyframes");
    }
    double *t2 = thz_realloc_array(tr->t, tr->k + 1, sizeof *t2);
    if (t2)
        tr->t = t2;
    size_t *kf2 = t2 ? thz_realloc_array(tr->kf, tr->k + 1, sizeof *kf2) : NULL;
    if (kf2)
        tr->kf = kf2;
    double *v2 = kf2 ? thz_realloc_array(tr->v, (tr->k + 1) * n, sizeof *v2) : NULL;
    if (!v2)
        return thz_error_set(b->err, THZ_ERR_NOMEM, "%s: out of memory", b->label);
    tr->v = v2;
    tr->t[tr->k] = t;
    tr->kf[tr->k] = b->keyframe;
    for (size_t i = 0; i < n; i++) {
        const json_t *x = json_is_array(v) ? json_array_get(v, i) : v;
        tr->v[tr->k * n + i] = json_number_value(x);
        tr->all_integers &= json_is_integer(x);
    }
    tr->k++;
    return THZ_OK;
}

/* Walks a keyframe's value at path seg (where: its JSON path), adding its leaves. */
static thz_status seq_walk(seq_build *b, char *where, size_t where_size, const char **seg,
                           size_t depth, double t, json_t *v)
{
    if (!json_is_object(v)) {
        thz_status st = seq_check_path(b, where, seg, depth, 1);
        return st != THZ_OK ? st : seq_add_value(b, where, seg, depth, t, v);
    }
    if (depth == SEQ_MAX_DEPTH)
        return seq_fail(b, where, "%s", "nested too deeply");
    /* the block's name even when it names nothing ("cameras": {} is a typo, not a no-op) */
    if (depth == 1 || (depth == 2 && (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors")))) {
        thz_status st = seq_check_path(b, where, seg, depth, 0);
        if (st != THZ_OK)
            return st;
    }
    const char *key;
    json_t *child;
    size_t len = strlen(where);
    json_object_foreach(v, key, child)
    {
        snprintf(where + len, where_size - len, ".%s", key);
        seg[depth] = key;
        thz_status st = seq_walk(b, where, where_size, seg, depth + 1, t, child);
        if (st != THZ_OK)
            return st;
    }
    where[len] = '\0';
    return THZ_OK;
}

static thz_status seq_keyframes(seq_build *b, json_t *keyframes)
{
    if (!json_is_array(keyframes))
        return seq_fail(b, "keyframes", "expected an array of keyframes, got %s",
                        seq_type(keyframes));
    size_t i;
    json_t *kf;
    double last_t = -1.0;
    json_array_foreach(keyframes, i, kf)
    {
        char where[1024];
        snprintf(where, sizeof where, "keyframes[%zu]", i);
        if (!json_is_object(kf))
            return seq_fail(b, where, "expected an object, got %s", seq_type(kf));
        json_t *tv = json_object_get(kf, "time_s");
        if (!json_is_number(tv) || json_number_value(tv) < 0.0) {
            strcat(where, ".time_s");
            return seq_fail(b, where, "%s", "expected a time >= 0 s");
        }
        double t = json_number_value(tv);
        if (t <= last_t) {
            strcat(where, ".time_s");
            return seq_fail(b, where, "%s",
                            "expected keyframe times in increasing order (each later than the "
                            "one before)");
        }
        last_t = t;
        b->keyframe = i;
        const char *key;
        json_t *val;
        json_object_foreach(kf, key, val)
        {
            if (!strcmp(key, "time_s"))
                continue;
            char w[1024];
            if (snprintf(w, sizeof w, "%s.%s", where, key) >= (int)sizeof w)
                return seq_fail(b, where, "%s", "key too long");
            const char *seg[SEQ_MAX_DEPTH] = {key};
            if (!json_is_object(val))
                return seq_fail(b, w, "expected an object, got %s", seq_type(val));
            thz_status st = seq_walk(b, w, sizeof w, seg, 1, t, val);
            if (st != THZ_OK)
                return st;
        }
    }
    return THZ_OK;
}

/* Splits a sweep key "a.b.c" into seg (pointing into buf). */
static size_t seq_split(char *buf, const char **seg)
{
    size_t depth = 0;
    for (char *p = buf; depth < SEQ_MAX_DEPTH;) {
        seg[depth++] = p;
        p = strchr(p, '.');
        if (!p)
            break;
        *p++ = '\0';
    }
    return depth;
}

static thz_status seq_check_sweep_in(seq_build *b, size_t *n_sweeps)
{
    *n_sweeps = 1;
    if (!b->sweep)
        return THZ_OK;
    if (!json_is_object(b->sweep) || json_object_size(b->sweep) == 0)
        return seq_fail(b, "sweep", "expected an object {\"dotted.key\": [values]}, got %s",
                        json_is_object(b->sweep) ? "an empty one" : seq_type(b->sweep));
    const char *key;
    json_t *vals;
    json_object_foreach(b->sweep, key, vals)
    {
        char where[600], buf[512];
        snprintf(where, sizeof where, "sweep.%s", key);
        snprintf(buf, sizeof buf, "%s", key);
        const char *seg[SEQ_MAX_DEPTH];
        size_t depth = seq_split(buf, seg);
        for (size_t i = 0; i < depth; i++)
            if (!seg[i][0])
                return seq_fail(b, where, "%s",
                                "expected a dotted key like atmosphere.relative_humidity");
        thz_status st = seq_check_path(b, where, seg, depth, 1);
        if (st != THZ_OK)
            return st;
        if (!json_is_array(vals) || json_array_size(vals) == 0)
            return seq_fail(b, where, "expected a non-empty array of values, got %s",
                            json_is_array(vals) ? "an empty one" : seq_type(vals));
        *n_sweeps *= json_array_size(vals);
        if (*n_sweeps > SEQ_MAX_SWEEPS)
            return seq_fail(b, "sweep", "%s", "more than 10000 combinations of values");
    }
    return THZ_OK;
}

/* Checks the sweep's keys against every scene file (with "scenes", each must have the
 * objects and sensors it names). */
static thz_status seq_check_sweep(seq_build *b, const thz_sequence *seq, size_t *n_sweeps)
{
    thz_status st = THZ_OK;
    for (size_t k = 0; st == THZ_OK && k < seq->n_scenes; k++) {
        b->scene = b->scenes[k];
        if (seq->scene_list) {
            const char *name = strrchr(seq->scene_paths[k], '/');
            snprintf(b->scene_name, sizeof b->scene_name, "scenes[%zu] (%s)", k,
                     name ? name + 1 : seq->scene_paths[k]);
        }
        st = seq_check_sweep_in(b, n_sweeps);
    }
    b->scene = b->scenes[0];
    snprintf(b->scene_name, sizeof b->scene_name, "the scene");
    return st;
}

/* Sets sweep combination s (the first key varies slowest) into doc; *values gets its
 * values by key (the sequence file's own, copied; NULL without a sweep), label the same
 * as text ("key = value, ...", numbers in their shortest form). */
static int seq_apply_sweep(const seq_build *b, size_t s, json_t *doc, json_t **values, char *label,
                           size_t size)
{
    label[0] = '\0';
    *values = NULL;
    if (!b->sweep)
        return 0;
    if (!(*values = json_object()))
        return -1;
    size_t stride = 1;
    const char *key;
    json_t *vals;
    json_object_foreach(b->sweep, key, vals) stride *= json_array_size(vals);
    json_object_foreach(b->sweep, key, vals)
    {
        stride /= json_array_size(vals);
        json_t *v = json_array_get(vals, (s / stride) % json_array_size(vals));
        char buf[512];
        snprintf(buf, sizeof buf, "%s", key);
        const char *seg[SEQ_MAX_DEPTH];
        size_t depth = seq_split(buf, seg);
        if (seq_set(doc, seg, depth, v) != 0 ||
            json_object_set_new(*values, key, json_deep_copy(v)) != 0)
            return -1;
        char *text = thz_json_shortest(v);
        if (!text)
            return -1;
        size_t len = strlen(label);
        snprintf(label + len, size - len, "%s%s = %s", len ? ", " : "", key, text);
        free(text);
    }
    return 0;
}

static int seq_apply_tracks(const seq_build *b, double time_s, json_t *doc)
{
    for (size_t i = 0; i < b->n_tracks; i++) {
        const seq_track *tr = &b->tracks[i];
        double out[64];
        double *x = tr->n <= 64 ? out : thz_malloc_array(tr->n, sizeof *x);
        if (!x)
            return -1;
        if (tr->rotation)
            thz_interp_rotation(tr->t, tr->v, tr->k, time_s, x);
        else
            thz_interp_linear(tr->t, tr->v, tr->k, tr->n, time_s, x);
        json_t *v = tr->is_array ? json_array() : NULL;
        for (size_t m = 0; m < tr->n; m++) {
            json_t *num = tr->all_integers && fabs(x[m]) < 9.0e15 && x[m] == floor(x[m])
                              ? json_integer((json_int_t)x[m])
                              : json_real(x[m]);
            if (tr->is_array)
                json_array_append_new(v, num);
            else
                v = num;
        }
        if (x != out)
            free(x);
        int rc = seq_set(doc, tr->seg, tr->depth, v);
        json_decref(v);
        if (rc != 0)
            return -1;
    }
    return 0;
}

void batch_sweep_dir(const thz_sequence *seq, size_t s, char *buf, size_t size)
{
    snprintf(buf, size, "sweep-%0*zu", seq->sweep_digits, s);
}

/* The keys of a scene's JSON path as a sequence names them: "objects[1].transform.
 * translate_m[2]" of doc gives seg {"objects", "person", "transform", "translate_m"} (an
 * object or sensor by its name) and *suffix "[2]" (the rest, from the first other
 * index); 0 when path is not such a path. The segments point into buf or doc. */
static size_t seq_scene_path(json_t *doc, const char *path, char *buf, size_t size,
                             const char **seg, const char **suffix)
{
    if (!path[0] || strlen(path) >= size)
        return 0;
    for (const char *c = path; *c; c++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.[]", *c))
            return 0;
    size_t depth = 0;
    const char *p = path;
    char *out = buf; /* the keys, each ended by '\0' (no longer than path) */
    *suffix = "";
    while (*p && depth < SEQ_MAX_DEPTH) {
        if (*p == '[') {
            /* objects[i] or sensors[i]: by name; any other index ends the keys */
            char *end;
            unsigned long i = strtoul(p + 1, &end, 10);
            const char *name = NULL;
            if (depth == 1 && (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors")) &&
                *end == ']')
                name = json_string_value(
                    json_object_get(json_array_get(json_object_get(doc, seg[0]), i), "name"));
            if (!name) {
                *suffix = p;
                return depth;
            }
            seg[depth++] = name;
            p = end + 1;
        } else {
            size_t n = strcspn(p, ".[");
            memcpy(out, p, n);
            out[n] = '\0';
            seg[depth++] = out;
            out += n + 1;
            p += n;
        }
        if (*p == '.')
            p++;
    }
    return *p ? 0 : depth;
}

/* Whether key (n segments) is a prefix of path (depth segments). */
static int seq_prefix(const char *const *key, size_t n, const char *const *path, size_t depth)
{
    size_t i = 0;
    while (i < n && i < depth && !strcmp(key[i], path[i]))
        i++;
    return i == n;
}

/* An error of frame f's scene at a value the sequence set (a sweep's value, which wins,
 * or a keyframe's): the message names that place in the sequence file first, then the
 * scene's path, the frame and its time: "seq.json: keyframes[0].sensors.cam.fov: unknown
 * key (the scene s.json's sensors[0].fov, frame-00000, t = 0 s)". 1 when rewritten; 0 when
 * the error lies elsewhere (the scene is bad itself), and err is left as it was. */
static int seq_blame(const seq_build *b, const thz_sequence *seq, size_t f, json_t *doc,
                     const char *label, double time_s)
{
    size_t k = batch_frame_scene(seq, f);
    const char *msg = b->err->message, *scene = seq->scene_paths[k];
    size_t n = strlen(scene);
    if (b->err->status != THZ_ERR_INPUT || strncmp(msg, scene, n) || strncmp(msg + n, ": ", 2))
        return 0;
    const char *path = msg + n + 2, *colon = strstr(path, ": ");
    if (!colon)
        return 0;
    char scene_path[512], buf[512], key_buf[512], where[1024], note[160] = "";
    if ((size_t)(colon - path) >= sizeof scene_path)
        return 0;
    memcpy(scene_path, path, (size_t)(colon - path));
    scene_path[colon - path] = '\0';
    const char *seg[SEQ_MAX_DEPTH], *suffix;
    size_t depth = seq_scene_path(doc, scene_path, buf, sizeof buf, seg, &suffix);
    if (!depth)
        return 0;
    size_t blamed = 0; /* segments of the place found (0: none) */
    /* the sweep's value first: set after the keyframes, it wins where both name a key */
    size_t stride = 1, s = f / seq->frames;
    const char *key;
    json_t *vals;
    if (b->sweep)
        json_object_foreach(b->sweep, key, vals) stride *= json_array_size(vals);
    if (b->sweep)
        json_object_foreach(b->sweep, key, vals)
        {
            stride /= json_array_size(vals);
            const char *kseg[SEQ_MAX_DEPTH];
            snprintf(key_buf, sizeof key_buf, "%s", key);
            size_t kd = seq_split(key_buf, kseg);
            if (!blamed && seq_prefix(kseg, kd, seg, depth)) {
                snprintf(where, sizeof where, "sweep.%s[%zu]", key,
                         (s / stride) % json_array_size(vals));
                blamed = kd;
            }
        }
    for (size_t i = 0; !blamed && i < b->n_tracks; i++) {
        const seq_track *tr = &b->tracks[i];
        if (!seq_prefix(tr->seg, tr->depth, seg, depth))
            continue;
        size_t j;
        double u;
        batch_segment(tr->t, tr->k, time_s, &j, &u);
        size_t at = u > 0.0 ? tr->kf[j + 1] : tr->kf[j];
        if (u > 0.0 && u < 1.0)
            snprintf(note, sizeof note, "interpolated between keyframes[%zu] and keyframes[%zu]; ",
                     tr->kf[j], tr->kf[j + 1]);
        snprintf(where, sizeof where, "keyframes[%zu]", at);
        for (size_t m = 0; m < tr->depth; m++) {
            size_t len = strlen(where);
            snprintf(where + len, sizeof where - len, ".%s", tr->seg[m]);
        }
        blamed = tr->depth;
    }
    if (!blamed)
        return 0;
    for (size_t m = blamed; m < depth; m++) {
        size_t len = strlen(where);
        snprintf(where + len, sizeof where - len, ".%s", seg[m]);
    }
    size_t len = strlen(where);
    snprintf(where + len, sizeof where - len, "%s", suffix);
    const char *name = strrchr(scene, '/');
    char t[40];
    thz_number_text(time_s, t, sizeof t);
    char reason[sizeof b->err->message]; /* (the message is rewritten from it) */
    snprintf(reason, sizeof reason, "%s", colon + 2);
    thz_error_set(b->err, THZ_ERR_INPUT, "%s: %s: %s (%sthe scene %s's %s, %s%s%s, t = %s s)",
                  b->label, where, reason, note, name ? name + 1 : scene, scene_path,
                  seq->frame_dir[f], label[0] ? ": " : "", label, t);
    return 1;
}

/* Builds frame f's scene text, dir, hash and sweep label; checks that it loads. */
static thz_status seq_frame(seq_build *b, thz_sequence *seq, size_t f)
{
    size_t s = f / seq->frames, i = f % seq->frames;
    double time_s = (double)i / seq->fps;
    size_t k = batch_frame_scene(seq, f);
    json_t *doc = json_deep_copy(b->scenes[k]);
    char label[1024];
    json_t *values = NULL;
    if (!doc || seq_apply_tracks(b, time_s, doc) != 0 ||
        seq_apply_sweep(b, s, doc, &values, label, sizeof label) != 0) {
        json_decref(doc);
        json_decref(values);
        return thz_error_set(b->err, THZ_ERR_NOMEM, "%s: out of memory", b->label);
    }
    if (i == 0 && !seq->sweep_label[s]) {
        seq->sweep_label[s] = thz_strdup(label);
        seq->sweep_json[s] = json_incref(values);
    }
    json_decref(values);
    seq->frame_json[f] = json_dumps(doc, JSON_COMPACT);
    char dir[64], sweep[32];
    batch_sweep_dir(seq, s, sweep, sizeof sweep);
    if (seq->has_sweep)
        snprintf(dir, sizeof dir, "%s/frame-%05zu", sweep, i);
    else
        snprintf(dir, sizeof dir, "frame-%05zu", i);
    seq->frame_dir[f] = thz_strdup(dir);
    if (!seq->frame_json[f] || !seq->frame_dir[f] || !seq->sweep_label[s]) {
        json_decref(doc);
        return thz_error_set(b->err, THZ_ERR_NOMEM, "%s: out of memory", b->label);
    }
    /* loaded (and so confined to seq->root) before the hash reads the files it names */
    thz_scene *scene = NULL;
    thz_status st = thz_sequence_frame_scene(seq, f, &scene, b->err);
    /* a sensor too large for the movie encoder is known now, not after every frame ran:
     * its movies are skipped (frame 0's sensors; other frames with other sensors make no
     * movies at all, batch_movies_write) */
    char why[1024];
    if (st == THZ_OK && f == 0 && !batch_movie_sizes(scene, why, sizeof why) &&
        !(seq->movies_unmade = thz_strdup(why)))
        st = thz_error_set(b->err, THZ_ERR_NOMEM, "%s: out of memory", b->label);
    thz_scene_destroy(scene);
    /* a bad value the sequence set is named where the sequence sets it; else the scene's
     * own error, after the frame (its directory, as the warnings and later errors say) */
    if (st != THZ_OK && b->err && seq_blame(b, seq, f, doc, label, time_s))
        ;
    else if (st != THZ_OK && b->err && seq->scene_list)
        thz_error_prefix(b->err, "%s: %s (scenes[%zu]%s%s): ", b->label, seq->frame_dir[f], k,
                         label[0] ? ", " : "", label);
    else if (st != THZ_OK && b->err)
        thz_error_prefix(b->err, "%s: %s (%s%st = %g s): ", b->label, seq->frame_dir[f], label,
                         label[0] ? ", " : "", time_s);
    if (st == THZ_OK) {
        uint64_t h = batch_hash_bytes(BATCH_HASH_INIT, "thzmap " THZ_VERSION_STRING,
                                      sizeof("thzmap " THZ_VERSION_STRING) - 1);
        h = batch_hash_bytes(h, seq->frame_json[f], strlen(seq->frame_json[f]));
        /* the directory as the file system names it: `s/cam.json` from the parent and
         * `cam.json` from s/ are the same inputs (the text made them differ) */
        char *real = realpath(seq->scene_dirs[k], NULL);
        const char *scene_dir = real ? real : seq->scene_dirs[k];
        h = batch_hash_bytes(h, scene_dir, strlen(scene_dir));
        free(real);
        seq->hash[f] = batch_hash_files(b->file_hashes, seq->scene_dirs[k], doc, h);
    }
    json_decref(doc);
    return st;
}

static thz_status seq_top(seq_build *b, json_t *root, const char *seq_dir, thz_sequence *seq,
                          json_t **keyframes)
{
    static const char *const keys[] = {"format", "scene",     "scenes", "fps",
                                       "frames", "keyframes", "sweep"};
    enum { N_KEYS = sizeof keys / sizeof keys[0] };
    if (!json_is_object(root))
        return seq_fail(b, "(top level)", "expected an object, got %s", seq_type(root));
    const char *key;
    json_t *v;
    /* the format first: a scene file given here would otherwise be told its first key is
     * unknown */
    const char *format = json_string_value(json_object_get(root, "format"));
    if (format && (!strcmp(format, LOAD_FORMAT) || !strcmp(format, LOAD_FORMAT_1_1)))
        return seq_fail(b, "format",
                        "expected \"" LOAD_SEQUENCE_FORMAT "\", got \"%s\" (a scene file, "
                        "which `thzmap simulate` runs; a sequence names it in \"scene\")",
                        format);
    if (!format || strcmp(format, LOAD_SEQUENCE_FORMAT))
        return seq_fail(b, "format", "%s", "expected \"" LOAD_SEQUENCE_FORMAT "\"");
    json_object_foreach(root, key, v)
    {
        size_t i = 0;
        while (i < N_KEYS && strcmp(key, keys[i]))
            i++;
        if (i == N_KEYS)
            return seq_fail(
                b, key, "%s",
                "unknown key (expected format, scene or scenes, fps, frames, keyframes, sweep)");
    }
    thz_status st = batch_scenes_load(b->label, root, seq_dir, seq, &b->scenes, b->err);
    if (st != THZ_OK)
        return st;
    b->scene = b->scenes[0];
    *keyframes = json_object_get(root, "keyframes");
    json_t *fps = json_object_get(root, "fps"), *frames = json_object_get(root, "frames");
    /* a least rate: frame times i / fps stay finite (5e-324 made them infinite: no
     * time_s in frame.json, null in batch.json), and any slow process fits (1e-9: a frame
     * in 31.7 years) */
    if (fps && (!json_is_number(fps) || !(json_number_value(fps) >= SEQ_MIN_FPS))) {
        char got[40];
        if (json_is_number(fps))
            thz_number_text(json_number_value(fps), got, sizeof got);
        else
            snprintf(got, sizeof got, "%s", seq_type(fps));
        return seq_fail(b, "fps",
                        "expected frames per second of at least 1e-9 (a frame in 31.7 years), "
                        "got %s",
                        got);
    }
    if (!fps && *keyframes)
        return seq_fail(b, "fps", "%s", "required with keyframes (frames per second > 0)");
    seq->fps = fps ? json_number_value(fps) : 1.0;
    if (frames && (!json_is_integer(frames) || json_integer_value(frames) < 1 ||
                   json_integer_value(frames) > SEQ_MAX_FRAMES))
        return seq_fail(b, "frames", "%s", "expected a whole number of frames from 1 to 100000");
    b->sweep = json_object_get(root, "sweep");
    /* a list: one frame per scene file, as it is */
    seq->frames = seq->scene_list ? seq->n_scenes : frames ? (size_t)json_integer_value(frames) : 1;
    return THZ_OK;
}

thz_status thz_sequence_load_ctx(thz_context *ctx, const char *path, const char *root_dir,
                                 thz_sequence **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_sequence_load: no place for the sequence");
    *out = NULL;
    if (!path)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_sequence_load: no path");
    thz_sequence *seq = thz_calloc(1, sizeof *seq);
    seq_build b = {
        .label = path, .err = err, .file_hashes = json_object(), .scene_name = "the scene"};
    json_t *root = NULL;
    char *real = NULL;
    const char *refusal = NULL;
    thz_status st = THZ_OK;
    if (!seq || !b.file_hashes)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    else
        st = load_root_real(root_dir, &seq->root, err);
    if (st == THZ_OK) {
        st = load_file_confine(path, seq->root, &real, &refusal);
        if (st == THZ_ERR_INPUT)
            thz_error_set(err, st, "%s: the sequence file %s", path, refusal);
        else if (st != THZ_OK)
            thz_error_set(err, st, "out of memory");
    }
    if (st == THZ_OK)
        st = load_json_file(path, real, NULL, "sequence", LOAD_MAX_SCENE_BYTES, &root, err);
    free(real);
    json_t *keyframes = NULL;
    if (st == THZ_OK) {
        seq->path = thz_strdup(path);
        char dir[4096];
        snprintf(dir, sizeof dir, "%s", path);
        char *slash = strrchr(dir, '/');
        if (slash)
            *slash = '\0';
        st = seq_top(&b, root, slash ? (dir[0] ? dir : "/") : ".", seq, &keyframes);
    }
    if (st == THZ_OK && keyframes)
        st = seq_keyframes(&b, keyframes);
    if (st == THZ_OK)
        st = seq_check_sweep(&b, seq, &seq->n_sweeps);
    if (st == THZ_OK) {
        seq->has_sweep = b.sweep != NULL;
        seq->sweep_digits = 2; /* sweep-00 .. sweep-99; more digits past 100 values */
        for (size_t v = 100; v < seq->n_sweeps; v *= 10)
            seq->sweep_digits++;
        seq->n_frames = seq->frames * seq->n_sweeps;
        /* frames and sweep values are limited each; their product too, before a frame is
         * built (each frame's scene is loaded here, which 10^9 frames would take days) */
        if (seq->n_frames > SEQ_MAX_FRAMES)
            st =
                thz_error_set(err, THZ_ERR_INPUT,
                              "%s: frames: %zu frames per sweep value x %zu sweep values = %zu "
                              "frames, more than the %d a sequence may have",
                              path, seq->frames, seq->n_sweeps, seq->n_frames, (int)SEQ_MAX_FRAMES);
    }
    if (st == THZ_OK) {
        seq->frame_json = thz_calloc(seq->n_frames, sizeof *seq->frame_json);
        seq->frame_dir = thz_calloc(seq->n_frames, sizeof *seq->frame_dir);
        seq->hash = thz_calloc(seq->n_frames, sizeof *seq->hash);
        seq->sweep_label = thz_calloc(seq->n_sweeps, sizeof *seq->sweep_label);
        seq->sweep_json = thz_calloc(seq->n_sweeps, sizeof *seq->sweep_json);
        if (!seq->frame_json || !seq->frame_dir || !seq->hash || !seq->sweep_label ||
            !seq->sweep_json)
            st = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    }
    /* each frame's scene is loaded (a few ms each: minutes for 10^5 frames): reported */
    thz_progress_fn progress = ctx ? ctx->progress : NULL;
    for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++) {
        thz_progress p = {.stage = "frames", .done = f, .total = seq->n_frames};
        if (progress && progress(ctx->progress_user, &p))
            st = thz_error_set(err, THZ_ERR_CANCELLED, "%s: cancelled", path);
        else
            st = seq_frame(&b, seq, f);
    }
    for (size_t i = 0; i < b.n_tracks; i++) {
        free(b.tracks[i].t);
        free(b.tracks[i].v);
        free(b.tracks[i].kf);
    }
    free(b.tracks);
    json_decref(b.file_hashes);
    batch_scenes_free(b.scenes, seq ? seq->n_scenes : 0);
    json_decref(root); /* the tracks' segments pointed into it: freed after them */
    if (st != THZ_OK) {
        thz_sequence_destroy(seq);
        return st;
    }
    *out = seq;
    return THZ_OK;
}

thz_status thz_sequence_load_within(const char *path, const char *root_dir, thz_sequence **out,
                                    thz_error *err)
{
    return thz_sequence_load_ctx(NULL, path, root_dir, out, err);
}

thz_status thz_sequence_load(const char *path, thz_sequence **out, thz_error *err)
{
    return thz_sequence_load_ctx(NULL, path, NULL, out, err);
}
