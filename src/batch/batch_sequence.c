/* Loading a sequence file ("thzmap-sequence/1"): its top-level keys checked with JSON
 * paths, every frame's scene built as JSON text from its scene file (the one "scene",
 * tracks interpolated at the frame's time; or the frame's file of the list "scenes";
 * then the sweep value set) and checked by loading it, and the hash of each frame's
 * inputs; also the paths that keyframes and sweeps set, checked and set in a scene.
 * batch_keyframes.c gathers the keyframes into tracks, batch_sweep.c reads the sweep,
 * batch_blame.c names a bad value where the sequence sets it (batch_sequence_build.h).
 */
#include <jansson.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "batch/batch_sequence_build.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/json_text.h"
#include "scene/load.h"

enum { SEQ_MAX_FRAMES = 100000 };
#define SEQ_MIN_FPS 1e-9 /* frames per second */

thz_status seq_fail(const seq_build *b, const char *where, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return thz_error_set(b->err, THZ_ERR_INPUT, "%s: %s: %s", b->label, where, what);
}

const char *seq_type(const json_t *v)
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

int seq_set(json_t *doc, const char *const *seg, size_t depth, json_t *value)
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

thz_status seq_check_path(const seq_build *b, const char *where, const char *const *seg,
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
    /* materials by name as the scene has them: a misspelt name made a new material that
     * no object uses, and the keyframe or sweep value changed nothing, silently */
    if (!strcmp(seg[0], "materials") && depth >= 2 &&
        !json_object_get(json_object_get(b->scene, "materials"), seg[1])) {
        char what[300];
        snprintf(what, sizeof what, "%s has no material named \"%s\"", b->scene_name, seg[1]);
        return seq_fail(b, where, "%s", what);
    }
    if (leaf && depth < (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors") ? 3u : 2u))
        return seq_fail(b, where, "%s",
                        "expected a path to a value, e.g. objects.NAME.temperature_k");
    return THZ_OK;
}

size_t seq_split(char *buf, const char **seg)
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

static thz_status sequence_load(thz_context *ctx, const char *path, const char *root_dir,
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
    for (size_t f = 0; st == THZ_OK && f <= seq->n_frames; f++) {
        thz_progress p = {.stage = "frames", .done = f, .total = seq->n_frames};
        if (progress && progress(ctx->progress_user, &p)) /* the last: all checked */
            st = thz_error_set(err, THZ_ERR_CANCELLED, "%s: cancelled", path);
        else if (f < seq->n_frames)
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

thz_status thz_sequence_load_ctx(thz_context *ctx, const char *path, const char *root_dir,
                                 thz_sequence **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    return api_done(ctx, sequence_load(ctx, path, root_dir, out, err), err);
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
