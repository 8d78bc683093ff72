/* A frame's scene error at a value the sequence set, named where the sequence file sets
 * it: the scene's JSON path (objects[1].transform...) turned into the sequence's keys
 * (objects by name), matched against the sweep's keys and the keyframes' tracks, and the
 * message rewritten. batch_sequence.c calls it when a frame's scene fails to load;
 * batch_keyframes.c and batch_sweep.c set the values (batch_sequence_build.h).
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "batch/batch_sequence_build.h"
#include "core/error.h"
#include "core/json_text.h"

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

int seq_blame(const seq_build *b, const thz_sequence *seq, size_t f, json_t *doc, const char *label,
              double time_s)
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
