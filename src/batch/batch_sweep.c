/* A sequence's sweep: its dotted keys checked against every scene file, the number of
 * combinations of their values, and combination s set into a frame's scene (after the
 * keyframes' tracks, batch_keyframes.c) with its label; the sweep-NN directory names.
 * batch_sequence.c loads the sequence and builds the frames (batch_sequence_build.h).
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "batch/batch_sequence_build.h"
#include "core/json_text.h"

enum { SEQ_MAX_SWEEPS = 10000 };

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

thz_status seq_check_sweep(seq_build *b, const thz_sequence *seq, size_t *n_sweeps)
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

int seq_apply_sweep(const seq_build *b, size_t s, json_t *doc, json_t **values, char *label,
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

void batch_sweep_dir(const thz_sequence *seq, size_t s, char *buf, size_t size)
{
    snprintf(buf, size, "sweep-%0*zu", seq->sweep_digits, s);
}
