/* What the files that load a sequence share: the load in progress (seq_build), the
 * tracks that keyframes gather, and the paths keyframes and sweeps set.
 * batch_sequence.c reads the top-level keys, builds and checks every frame and holds the
 * path helpers below; batch_keyframes.c gathers the keyframes into tracks and
 * interpolates them at a frame's time; batch_sweep.c checks the sweep's keys and sets a
 * sweep value; batch_blame.c names a bad value where the sequence file sets it. Nothing
 * here is public.
 */
#ifndef THZ_BATCH_BATCH_SEQUENCE_BUILD_H
#define THZ_BATCH_BATCH_SEQUENCE_BUILD_H

#include <stddef.h>

#include <jansson.h>

#include "batch/batch_internal.h"

enum { SEQ_MAX_DEPTH = 8 };

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

/* ---- batch_sequence.c: messages and the paths a sequence sets ---- */

/* THZ_ERR_INPUT: "LABEL: WHERE: what" (where: the JSON path in the sequence file). */
thz_status seq_fail(const seq_build *b, const char *where, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* "an object", "a number", ...: v's JSON type, in messages. */
const char *seq_type(const json_t *v);
/* Sets the value at path seg[0..depth-1] of doc (objects and sensors by name; missing
 * objects on the way are created); takes a reference to value. */
int seq_set(json_t *doc, const char *const *seg, size_t depth, json_t *value);
/* Checks that the path names something keyframes or sweeps may set: a block of the
 * scene, and an object or sensor the scene has (leaf: a path to a value). */
thz_status seq_check_path(const seq_build *b, const char *where, const char *const *seg,
                          size_t depth, int leaf);
/* Splits a sweep key "a.b.c" into seg (pointing into buf). */
size_t seq_split(char *buf, const char **seg);

/* ---- batch_keyframes.c: keyframes gathered into tracks ---- */

/* Reads "keyframes" into b's tracks (checking times and paths). */
thz_status seq_keyframes(seq_build *b, json_t *keyframes);
/* Sets every track's value at time_s (interpolated; rotations slerped) into doc. */
int seq_apply_tracks(const seq_build *b, double time_s, json_t *doc);

/* ---- batch_sweep.c: the sweep's values ---- */

/* Checks the sweep's keys against every scene file (with "scenes", each must have the
 * objects and sensors it names); *n_sweeps: the number of combinations. */
thz_status seq_check_sweep(seq_build *b, const thz_sequence *seq, size_t *n_sweeps);
/* Sets sweep combination s (the first key varies slowest) into doc; *values gets its
 * values by key (the sequence file's own, copied; NULL without a sweep), label the same
 * as text ("key = value, ...", numbers in their shortest form). */
int seq_apply_sweep(const seq_build *b, size_t s, json_t *doc, json_t **values, char *label,
                    size_t size);

/* ---- batch_blame.c: a frame's error named where the sequence sets the value ---- */

/* An error of frame f's scene at a value the sequence set (a sweep's value, which wins,
 * or a keyframe's): the message names that place in the sequence file first, then the
 * scene's path, the frame and its time: "seq.json: keyframes[0].sensors.cam.fov: unknown
 * key (the scene s.json's sensors[0].fov, frame-00000, t = 0 s)". 1 when rewritten; 0 when
 * the error lies elsewhere (the scene is bad itself), and err is left as it was. */
int seq_blame(const seq_build *b, const thz_sequence *seq, size_t f, json_t *doc, const char *label,
              double time_s);

#endif
