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

/* The frame whose photons a finished frame's files were rendered from, numbered as this
 * sequence numbers frames: doc's photons_reused_from_frame, which the run that made it
 * numbered by its own frames per sweep value (doc's frame, sweep and index tell them),
 * moved to the number the same frame directory has now. -1 for null (it fired its own
 * photons, or fired none); -2 when that directory is no frame of this sequence or doc
 * does not say. */
static long batch_kept_base(const thz_sequence *seq, const json_t *doc)
{
    const json_t *from = json_object_get(doc, "photons_reused_from_frame");
    if (json_is_null(from))
        return -1;
    json_int_t b = json_integer_value(from), f = json_integer_value(json_object_get(doc, "frame")),
               s = json_integer_value(json_object_get(doc, "sweep")),
               i = json_integer_value(json_object_get(doc, "index"));
    /* (a sequence has at most 100 000 frames: larger numbers are no frame's) */
    if (!json_is_integer(from) || b < 0 || b > f || f > 1000000 || i < 0 || s < 0 || f - i < 0)
        return -2;
    /* the frames per sweep value it was run with; without a sweep value before this one's,
     * the base (at most this frame) is in the first and keeps its number */
    json_int_t per = s > 0 ? (f - i) / s : f + 1;
    if (per <= 0 || (s > 0 && (f - i) % s != 0))
        return -2;
    json_int_t bs = b / per, bi = b % per;
    if ((size_t)bs >= seq->n_sweeps || (size_t)bi >= seq->frames)
        return -2;
    return (long)((size_t)bs * seq->frames + (size_t)bi);
}

/* Frame f's frame.json as read from its directory into path (NULL when there is none or it
 * is no regular file of reasonable size); *text its bytes (malloc'd) when text is not
 * NULL. */
static json_t *batch_frame_json_read(const batch_state *b, size_t f, char path[THZ_PATH_MAX],
                                     char **text)
{
    if (text)
        *text = NULL;
    if (snprintf(path, THZ_PATH_MAX, "%s/%s/frame.json", b->outdir, b->seq->frame_dir[f]) >=
        THZ_PATH_MAX)
        return NULL;
    /* a FIFO or device there would block or never end (core/file.h) */
    thz_error ignored;
    uint64_t size = 0;
    if (file_check_regular(path, path, BATCH_FRAME_JSON_MAX, &size, &ignored) != THZ_OK)
        return NULL;
    if (!text)
        return json_load_file(path, 0, NULL);
    FILE *in = fopen(path, "rb");
    char *buf = in ? malloc((size_t)size + 1) : NULL;
    size_t n = buf ? fread(buf, 1, (size_t)size + 1, in) : 0;
    if (in)
        fclose(in);
    json_t *doc = NULL;
    if (buf && n <= (size_t)size) {
        buf[n] = '\0';
        doc = json_loadb(buf, n, 0, NULL);
    }
    if (doc)
        *text = buf;
    else
        free(buf);
    return doc;
}

int batch_frame_done(const batch_state *b, size_t f)
{
    char path[THZ_PATH_MAX], hex[17];
    json_t *doc = batch_frame_json_read(b, f, path, NULL);
    batch_hex(b->seq->hash[f], hex);
    const char *h = json_string_value(json_object_get(doc, "input_hash"));
    /* rendered from another frame's photons: that frame must still be its base (the first
     * of the frames before it that differ from it only in their sensors), else it is run
     * again: its photons_reused_from_frame would name a frame that no longer fires them */
    long kept = h && !strcmp(h, hex) ? batch_kept_base(b->seq, doc) : -2;
    json_decref(doc);
    return kept == -1 || (kept >= 0 && (size_t)kept == b->base[f]);
}

/* Writes text (and a newline when newline) to outdir/name through a temporary file,
 * outdir/.name.part, and a rename: a kill at any instant leaves the old file or the new. */
static thz_status batch_write_atomic(const char *outdir, const char *name, const char *text,
                                     bool newline, thz_error *err)
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
    if (fwrite(text, 1, n, f) != n || (newline && fputc('\n', f) == EOF) || fflush(f) != 0 ||
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

/* A frame's time for batch.json, in the text frame.json gives it: jansson's at 17 digits
 * (batch.json's 12 wrote 1.57894736842 where frame.json has 1.5789473684210527, and the
 * two did not compare equal). NULL when out of memory. */
static json_t *batch_time_json(double time_s)
{
    json_t *t = json_real(time_s);
    char *text = t ? json_dumps(t, JSON_ENCODE_ANY | JSON_REAL_PRECISION(17)) : NULL;
    json_t *raw = text ? thz_json_raw(text) : NULL;
    free(text);
    json_decref(t);
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
        json_object_set_new(e, "time_s", batch_time_json((double)(f % seq->frames) / seq->fps));
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
    json_object_set_new(root, "thzmap_revision", json_string(thz_revision()));
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
     * noise such as 293.0049133300781 K); the frames' time_s as frame.json writes it */
    char *text = thz_json_dumps_raw(root, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
    json_decref(root);
    if (!text)
        return thz_error_set(err, THZ_ERR_NOMEM, "batch.json: out of memory");
    thz_status st = batch_write_atomic(b->outdir, "batch.json", text, true, err);
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

thz_status batch_frame_refresh(const batch_state *b, size_t f, thz_error *err)
{
    char path[THZ_PATH_MAX], dir[THZ_PATH_MAX], part[THZ_PATH_MAX];
    if (snprintf(dir, sizeof dir, "%s/%s", b->outdir, b->seq->frame_dir[f]) >= (int)sizeof dir ||
        snprintf(part, sizeof part, "%s/.frame.json.part", dir) >= (int)sizeof part)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", b->outdir);
    unlink(part); /* a refresh killed before its rename left it */
    char *old = NULL;
    json_t *doc = batch_frame_json_read(b, f, path, &old);
    long kept = batch_kept_base(b->seq, doc);
    json_decref(doc);
    if (!old || kept == -2) { /* (gone or changed since: the next batch runs it again) */
        free(old);
        return THZ_OK;
    }
    char *text = batch_frame_json(b->seq, f, kept);
    thz_status st = text ? THZ_OK : thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    if (st == THZ_OK && strcmp(old, text) != 0)
        st = batch_write_atomic(dir, "frame.json", text, false, err);
    free(text);
    free(old);
    return st;
}
