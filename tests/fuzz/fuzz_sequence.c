/* Fuzzes the batch's readers (src/batch/): a sequence file (batch_sequence.c,
 * batch_scenes.c, batch_keyframes.c, batch_sweep.c and the scene loader for each frame)
 * and the resume state, the frame.json a batch reads back from OUTDIR to tell a finished
 * frame (batch_json.c).
 * - An input not starting with 'R' is a sequence file, in a directory holding the scenes
 *   of tests/fuzz/files/sequence/ (scene.json, other.json); read by thz_sequence_load,
 *   or thz_sequence_load_within that directory when its size is odd. An accepted
 *   sequence must give every frame (number, directory, scene text) and its first and last
 *   frame's scene must load.
 * - 'R', a byte f, then the frame.json of frame f (modulo 6) of files/sequence/resume.json
 *   (a sweep of 2 values of 3 frames, the last two rendered from the first's photons):
 *   batch_frame_done tells whether it is finished, batch_frame_refresh rewrites it. A
 *   finished frame stays finished once refreshed, and a second refresh changes nothing.
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <ftw.h>
#include <jansson.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "batch/batch_run_state.h"
#include "fuzz.h"

static char dir[PATH_MAX];    /* the temporary directory: sequence.json and the scenes */
static char outdir[PATH_MAX]; /* the resume mode's OUTDIR */
static thz_sequence *resume_seq;
static size_t *resume_base;

static char *read_whole(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            cap = 2 * cap + 8192;
            char *grown = realloc(buf, cap);
            if (!grown)
                abort();
            buf = grown;
        }
        size_t got = fread(buf + n, 1, 4096, f);
        n += got;
        if (got < 4096)
            break;
    }
    fclose(f);
    buf[n] = '\0';
    *size = n;
    return buf;
}

static void copy_fixture(const char *name)
{
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/files/sequence/%s", FUZZ_DIR, name) >= (int)sizeof path)
        abort();
    size_t n = 0;
    char *text = read_whole(path, &n);
    if (!text)
        abort();
    const char *copy = fuzz_temp_file(name, (const uint8_t *)text, n);
    if (snprintf(dir, sizeof dir, "%s", copy) >= (int)sizeof dir)
        abort();
    *strrchr(dir, '/') = '\0';
    free(text);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    remove(path);
    return 0;
}

static void remove_outdir(void)
{
    nftw(outdir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_use_fixture_data(); /* a sweep may set the `lines` atmosphere */
    copy_fixture("scene.json");
    copy_fixture("other.json");
    copy_fixture("resume.json");
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/resume.json", dir) >= (int)sizeof path)
        abort();
    thz_error err = {0};
    if (thz_sequence_load(path, &resume_seq, &err) != THZ_OK) {
        fprintf(stderr, "fuzz_sequence: %s\n", err.message);
        abort();
    }
    size_t n = thz_sequence_frame_count(resume_seq);
    resume_base = calloc(n, sizeof *resume_base);
    if (!resume_base || batch_photon_bases(resume_seq, resume_base, &err) != THZ_OK)
        abort();
    const char *tmp = getenv("TMPDIR");
    if (snprintf(outdir, sizeof outdir, "%s/thz-fuzz-out-XXXXXX", tmp && *tmp ? tmp : "/tmp") >=
        (int)sizeof outdir)
        abort();
    if (!mkdtemp(outdir))
        abort();
    atexit(remove_outdir);
    for (size_t f = 0; f < n; f++) {
        if (snprintf(path, sizeof path, "%s/%s", outdir, resume_seq->frame_dir[f]) >=
            (int)sizeof path)
            abort();
        if (batch_mkdirs(path, &err) != THZ_OK)
            abort();
    }
    return 0;
}

/* Sequences whose load is slow by design: each frame's scene is built and loaded (a few
 * ms under the sanitizers), and a sequence may have 100 000 frames. */
static bool asks_for_many_frames(const char *text)
{
    json_t *doc = json_loads(text, 0, NULL);
    if (!doc)
        return false;
    json_t *frames = json_object_get(doc, "frames");
    double n = json_is_number(frames) ? json_number_value(frames) : 1.0;
    json_t *scenes = json_object_get(doc, "scenes");
    if (json_is_array(scenes))
        n *= (double)json_array_size(scenes);
    const char *key;
    json_t *v;
    json_object_foreach(json_object_get(doc, "sweep"), key, v)
    {
        if (json_is_array(v))
            n *= (double)json_array_size(v);
    }
    json_decref(doc);
    return n > 64;
}

static void fuzz_sequence_file(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
    bool skip = asks_for_many_frames(text);
    free(text);
    if (skip)
        return;
    const char *path = fuzz_temp_file("sequence.json", data, size);
    thz_sequence *seq = NULL;
    thz_error err = {0};
    thz_status st = size % 2 ? thz_sequence_load_within(path, dir, &seq, &err)
                             : thz_sequence_load(path, &seq, &err);
    if (st != THZ_OK) {
        fuzz_report(err.message);
        if (!err.message[0] || seq)
            abort(); /* a refusal says why and leaves no sequence */
        return;
    }
    size_t n = thz_sequence_frame_count(seq);
    if (!seq || n == 0 || n != thz_sequence_frames_per_sweep(seq) * thz_sequence_sweep_count(seq))
        abort();
    for (size_t i = 0; i < n; i++) {
        thz_frame_info info;
        char c;
        if (thz_sequence_frame(seq, i, &info) != THZ_OK || !info.dir || !info.dir[0] ||
            info.index != i % thz_sequence_frames_per_sweep(seq) ||
            thz_sequence_frame_json(seq, i, &c, 1) == 0)
            abort();
    }
    for (size_t i = 0; i<n; i += n - 1> 0 ? n - 1 : 1) { /* the first and the last */
        thz_scene *scene = NULL;
        if (thz_sequence_frame_scene(seq, i, &scene, &err) != THZ_OK) {
            fprintf(stderr, "fuzz_sequence: frame %zu of an accepted sequence: %s\n", i,
                    err.message);
            abort();
        }
        thz_scene_destroy(scene);
    }
    thz_sequence_destroy(seq);
}

static void fuzz_resume(const uint8_t *data, size_t size)
{
    if (size < 2)
        return;
    size_t f = data[1] % thz_sequence_frame_count(resume_seq);
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s/frame.json", outdir, resume_seq->frame_dir[f]) >=
        (int)sizeof path)
        abort();
    FILE *out = fopen(path, "wb");
    if (!out || (size > 2 && fwrite(data + 2, 1, size - 2, out) != size - 2) || fclose(out))
        abort();
    batch_state b = {.seq = resume_seq, .outdir = outdir, .base = resume_base};
    int done = batch_frame_done(&b, f);
    thz_error err = {0};
    for (int pass = 0; pass < 2; pass++) {
        size_t n0 = 0, n1 = 0;
        char *before = read_whole(path, &n0);
        if (batch_frame_refresh(&b, f, &err) != THZ_OK) {
            fuzz_report(err.message);
            if (!err.message[0])
                abort();
            free(before);
            return;
        }
        char *after = read_whole(path, &n1);
        if (done && !batch_frame_done(&b, f))
            abort(); /* a refresh lost a finished frame */
        if (pass == 1 && (n0 != n1 || memcmp(before, after, n0) != 0))
            abort(); /* a refresh of a refreshed frame.json changed it */
        free(before);
        free(after);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 0 && data[0] == 'R')
        fuzz_resume(data, size);
    else
        fuzz_sequence_file(data, size);
    return 0;
}
