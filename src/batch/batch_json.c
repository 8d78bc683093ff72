/* A batch's records: OUTDIR/batch.json (every frame's state, the sweeps, the movies, the
 * timings), rewritten through a temporary file and a rename as frames finish, at most
 * once a second and a tenth of the time spent (batch_json_due); each frame's frame.json
 * (which frame, the hash of its inputs, its scene), and reading it back to tell a
 * finished frame. batch_run.c runs the frames, batch_outdir.c keeps OUTDIR
 * (batch_run_state.h).
 */
#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "batch/batch_internal.h"
#include "batch/batch_run_state.h"
#include "core/error.h"
#include "core/file.h"
#include "core/json_text.h"
#include "core/path.h"

static void batch_hex(uint64_t h, char hex[17])
{
    snprintf(hex, 17, "%016llx", (unsigned long long)h);
}

/* A frame.json is a few kilobytes; anything far larger is not one. */
#define BATCH_FRAME_JSON_MAX ((uint64_t)64 << 20)

int batch_frame_done(const batch_state *b, size_t f)
{
    char path[THZ_PATH_MAX], hex[17];
    if (snprintf(path, sizeof path, "%s/%s/frame.json", b->outdir, b->seq->frame_dir[f]) >=
        (int)sizeof path)
        return 0;
    /* a FIFO or device there would block or never end (core/file.h) */
    thz_error ignored;
    if (file_check_regular(path, path, BATCH_FRAME_JSON_MAX, NULL, &ignored) != THZ_OK)
        return 0;
    json_t *doc = json_load_file(path, 0, NULL);
    batch_hex(b->seq->hash[f], hex);
    const char *h = json_string_value(json_object_get(doc, "input_hash"));
    int done = h && !strcmp(h, hex);
    json_decref(doc);
    return done;
}

/* Writes text to outdir/name through a temporary file and a rename. */
static thz_status batch_write_atomic(const char *outdir, const char *name, const char *text,
                                     thz_error *err)
{
    char path[THZ_PATH_MAX], tmp[THZ_PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", outdir, name) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s/.%s.part", outdir, name) >= (int)sizeof tmp)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", outdir);
    FILE *f = fopen(tmp, "wb");
    if (!f)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot create: %s", tmp, strerror(errno));
    size_t n = strlen(text);
    int why = 0; /* the first failure's errno: a full disk says so */
    errno = 0;
    if (fwrite(text, 1, n, f) != n || fputc('\n', f) == EOF || fflush(f) != 0 ||
        fsync(fileno(f)) != 0)
        why = errno ? errno : EIO;
    if (fclose(f) != 0 && !why)
        why = errno ? errno : EIO;
    if (!why && rename(tmp, path) != 0)
        why = errno ? errno : EIO;
    if (why) {
        unlink(tmp);
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot write: %s", path, strerror(why));
    }
    return THZ_OK;
}

static const char *batch_state_name(frame_state s)
{
    return s == FRAME_PENDING ? "pending" : s == FRAME_FAILED ? "failed" : "done";
}

/* Sweep value s's values by key as JSON, the numbers as the sequence file wrote them
 * (0.3, where json_dumps writes 0.29999999999999999 or rounds to its precision): a
 * placeholder for thz_json_dumps_raw. JSON null without a sweep. */
static json_t *batch_sweep_values(const thz_sequence *seq, size_t s)
{
    if (!seq->sweep_json || !seq->sweep_json[s])
        return json_null();
    char *text = thz_json_shortest(seq->sweep_json[s]);
    json_t *raw = text ? thz_json_raw(text) : NULL;
    free(text);
    return raw;
}

thz_status batch_write_json(batch_state *b, thz_error *err)
{
    double t_start = batch_now_s();
    const thz_sequence *seq = b->seq;
    json_t *root = json_object(), *frames = json_array(), *sweeps = json_array();
    size_t done = 0;
    for (size_t f = 0; f < seq->n_frames; f++) {
        char hex[17];
        batch_hex(seq->hash[f], hex);
        json_t *e = json_object();
        json_object_set_new(e, "frame", json_integer((json_int_t)f));
        json_object_set_new(e, "sweep", json_integer((json_int_t)(f / seq->frames)));
        json_object_set_new(e, "index", json_integer((json_int_t)(f % seq->frames)));
        json_object_set_new(e, "time_s", json_real((double)(f % seq->frames) / seq->fps));
        json_object_set_new(e, "dir", thz_json_text(seq->frame_dir[f]));
        if (seq->scene_list)
            json_object_set_new(e, "scene",
                                thz_json_text(seq->scene_paths[batch_frame_scene(seq, f)]));
        json_object_set_new(e, "input_hash", json_string(hex));
        json_object_set_new(e, "status", json_string(batch_state_name(b->state[f])));
        if (b->state[f] == FRAME_COMPUTED || b->state[f] == FRAME_REUSED)
            json_object_set_new(
                e, "computed",
                json_string(b->state[f] == FRAME_COMPUTED ? "this run" : "an earlier run"));
        if (b->state[f] == FRAME_COMPUTED)
            json_object_set_new(e, "photons",
                                json_string(b->reused_photons[f] == BATCH_PHOTONS_REUSED ? "reused"
                                            : b->reused_photons[f] == BATCH_PHOTONS_NONE
                                                ? "none"
                                                : "fired"));
        json_object_set_new(e, "photon_base_frame", json_integer((json_int_t)b->base[f]));
        json_object_set_new(e, "seconds",
                            b->state[f] == FRAME_COMPUTED ? json_real(b->seconds[f]) : json_null());
        json_array_append_new(frames, e);
        done += b->state[f] == FRAME_COMPUTED || b->state[f] == FRAME_REUSED;
    }
    for (size_t s = 0; s < seq->n_sweeps && seq->has_sweep; s++) {
        char dir[32];
        batch_sweep_dir(seq, s, dir, sizeof dir);
        json_t *e = json_object();
        json_object_set_new(e, "dir", json_string(dir));
        json_object_set_new(e, "values", batch_sweep_values(seq, s));
        json_object_set_new(e, "label", thz_json_text(seq->sweep_label[s]));
        json_array_append_new(sweeps, e);
    }
    json_t *t = json_object();
    json_object_set_new(t, "frames", json_real(b->seconds_frames));
    json_object_set_new(t, "movies", json_real(b->seconds_movies));
    json_object_set_new(t, "total", json_real(batch_now_s() - b->t0));
    json_object_set_new(root, "format", json_string("thzmap-batch/1"));
    json_object_set_new(root, "thzmap_version", json_string(THZ_VERSION_STRING));
    json_object_set_new(root, "sequence", thz_json_text(seq->path));
    if (seq->scene_list) {
        json_t *scenes = json_array();
        for (size_t k = 0; k < seq->n_scenes; k++)
            json_array_append_new(scenes, thz_json_text(seq->scene_paths[k]));
        json_object_set_new(root, "scene", json_null());
        json_object_set_new(root, "scenes", scenes);
    } else {
        json_object_set_new(root, "scene", thz_json_text(seq->scene_paths[0]));
    }
    json_object_set_new(root, "fps", json_real(seq->fps));
    json_object_set_new(root, "frames_per_sweep", json_integer((json_int_t)seq->frames));
    json_object_set_new(root, "n_frames", json_integer((json_int_t)seq->n_frames));
    json_object_set_new(root, "frames_done", json_integer((json_int_t)done));
    json_object_set_new(root, "frames_computed", json_integer((json_int_t)b->computed));
    json_object_set_new(root, "frames_reused", json_integer((json_int_t)b->reused));
    json_object_set_new(root, "photon_phases_fired", json_integer((json_int_t)b->fired));
    json_object_set_new(root, "frames_rerendered", json_integer((json_int_t)b->rerendered));
    json_object_set_new(root, "complete", json_boolean(done == seq->n_frames && b->movies));
    json_object_set_new(root, "sweeps", sweeps);
    json_object_set_new(root, "frames", frames);
    if (b->movies)
        json_object_set(root, "movies", b->movies);
    else
        json_object_set_new(root, "movies", json_array());
    json_object_set_new(root, "movies_skipped",
                        b->movies_skipped[0] ? thz_json_text(b->movies_skipped) : json_null());
    json_object_set_new(root, "timings_s", t);
    /* 12 digits, as summary.json: its reals are times and statistics (17 printed float
     * noise such as 293.0049133300781 K) */
    char *text = thz_json_dumps_raw(root, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
    json_decref(root);
    if (!text)
        return thz_error_set(err, THZ_ERR_NOMEM, "batch.json: out of memory");
    thz_status st = batch_write_atomic(b->outdir, "batch.json", text, err);
    free(text);
    b->json_at_s = batch_now_s();
    b->json_cost_s = b->json_at_s - t_start;
    return st;
}

bool batch_json_due(const batch_state *b, size_t f, thz_status st)
{
    if (st != THZ_OK || f + 1 >= b->seq->n_frames)
        return true;
    double wait = 10.0 * b->json_cost_s > 1.0 ? 10.0 * b->json_cost_s : 1.0;
    return batch_now_s() - b->json_at_s >= wait;
}

char *batch_frame_json(const thz_sequence *seq, size_t f, long reused_from)
{
    char hex[17];
    batch_hex(seq->hash[f], hex);
    json_t *root = json_object();
    json_object_set_new(root, "format", json_string("thzmap-frame/1"));
    json_object_set_new(root, "frame", json_integer((json_int_t)f));
    json_object_set_new(root, "sweep", json_integer((json_int_t)(f / seq->frames)));
    json_object_set_new(root, "index", json_integer((json_int_t)(f % seq->frames)));
    json_object_set_new(root, "time_s", json_real((double)(f % seq->frames) / seq->fps));
    json_object_set_new(root, "sweep_values", batch_sweep_values(seq, f / seq->frames));
    json_object_set_new(root, "sweep_label",
                        seq->has_sweep ? thz_json_text(seq->sweep_label[f / seq->frames])
                                       : json_null());
    json_object_set_new(root, "input_hash", json_string(hex));
    json_object_set_new(root, "photons_reused_from_frame",
                        reused_from >= 0 ? json_integer(reused_from) : json_null());
    size_t k = batch_frame_scene(seq, f);
    json_object_set_new(root, "scene_file", thz_json_text(seq->scene_paths[k]));
    json_object_set_new(root, "scene_dir", thz_json_text(seq->scene_dirs[k]));
    json_object_set_new(root, "scene", json_loads(seq->frame_json[f], 0, NULL));
    /* 17 digits: the scene must read back to the same doubles, to rerun the frame to the
     * same bytes (0.3 prints as 0.29999999999999999, the same double) */
    char *text = thz_json_dumps_raw(root, JSON_INDENT(2) | JSON_REAL_PRECISION(17));
    json_decref(root);
    return text;
}
