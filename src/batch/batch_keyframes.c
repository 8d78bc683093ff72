/* A sequence's keyframes: each value a keyframe names (e.g.
 * objects.person.transform.translate_m) gathered into a track of times and numbers, its
 * path checked against the scene, and every track interpolated at a frame's time into
 * the frame's scene (linearly; rotate_deg by slerp). batch_sequence.c loads the sequence
 * and builds the frames, batch_sweep.c sets the sweep's values after the tracks'
 * (batch_sequence_build.h).
 */
#include <jansson.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch/batch_sequence_build.h"
#include "core/alloc.h"
#include "core/error.h"

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
    if (depth == 1 || (depth == 2 && (!strcmp(seg[0], "objects") || !strcmp(seg[0], "sensors") ||
                                      !strcmp(seg[0], "materials")))) {
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

thz_status seq_keyframes(seq_build *b, json_t *keyframes)
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

int seq_apply_tracks(const seq_build *b, double time_s, json_t *doc)
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
        /* keyframes of whole numbers (a seed, a count): an interpolated value within the
         * interpolation's rounding of a whole number is that number (1 to 7 over seven
         * frames gave 4.999999999999999, refused as no whole number) */
        if (tr->all_integers && !tr->rotation) {
            double vmax = 1.0;
            for (size_t j = 0; j < tr->k * tr->n; j++)
                vmax = fmax(vmax, fabs(tr->v[j]));
            for (size_t m = 0; m < tr->n; m++)
                if (fabs(x[m] - nearbyint(x[m])) <= 4.0 * DBL_EPSILON * vmax)
                    x[m] = nearbyint(x[m]);
        }
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
