/* Running a sequence (thz_batch_run): every frame as `thzmap simulate` would, each into
 * its own atomic output directory (thz_output) holding frame.json with the hash of the
 * frame's inputs; OUTDIR/batch.json rewritten (temporary file, then rename) as frames
 * finish (batch_json_due) and at the end; the movies last, rebuilt from the frames' files.
 * A frame directory whose frame.json carries the frame's hash is finished and is not run
 * again, which is all that resuming a killed batch needs: a frame appears whole or not at
 * all. Under MPI the pending frames are dealt to the ranks by photon groups when there
 * are enough of them (batch_deal.c), and this process, rank 0, writes every frame in
 * frame order.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/file.h"
#include "core/json_text.h"
#include "core/path.h"

typedef enum frame_state { FRAME_PENDING, FRAME_REUSED, FRAME_COMPUTED, FRAME_FAILED } frame_state;

/* How a frame computed by this call got its photons (batch.json's frames[].photons). */
enum { BATCH_PHOTONS_FIRED = 0, BATCH_PHOTONS_REUSED, BATCH_PHOTONS_NONE };

typedef struct batch_state {
    const thz_sequence *seq;
    const char *outdir;
    frame_state *state;
    double *seconds;     /* per frame computed by this call, s */
    size_t *base;        /* per frame: the frame whose photons it renders from (batch_reuse.c) */
    size_t *rank;        /* per frame: the MPI rank that computes it (0: this process) */
    int *reused_photons; /* per frame computed by this call: BATCH_PHOTONS_* */
    batch_photon_cache cache;  /* the photons of the current base frame */
    json_t *movies;            /* the movies' descriptions (batch.json "movies") */
    char movies_skipped[1024]; /* why there are none or some are missing ("": none is) */
    const thz_batch_options *opt;
    thz_progress_fn run_progress; /* the caller's progress callback on ctx, restored after */
    void *run_progress_user;
    size_t frame;       /* the frame running */
    double frame_share; /* the share of it done, 0..1, never falling */
    int photons_seen;   /* it fires photons (then they are half of each channel) */
    double t0, seconds_frames, seconds_movies;
    double json_at_s, json_cost_s; /* batch.json: when last written, how long that took */
    size_t computed, reused;
    size_t fired, rerendered; /* photon phases run, frames rendered from kept photons */
} batch_state;

static double batch_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* mkdir -p */
static thz_status batch_mkdirs(const char *dir, thz_error *err)
{
    char path[THZ_PATH_MAX];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", dir);
    for (char *p = path + 1;; p++) {
        char c = *p;
        if (c != '/' && c != '\0')
            continue;
        *p = '\0';
        if (mkdir(path, 0777) != 0 && errno != EEXIST)
            return thz_error_set(err, THZ_ERR_IO, "%s: cannot create the directory: %s", path,
                                 strerror(errno));
        *p = c;
        if (!c)
            break;
    }
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) /* a file where OUTDIR is: bad usage */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: not a directory (expected a directory for the results, or a "
                             "name to create one)",
                             dir);
    return THZ_OK;
}

static void batch_hex(uint64_t h, char hex[17])
{
    snprintf(hex, 17, "%016llx", (unsigned long long)h);
}

/* A frame.json is a few kilobytes; anything far larger is not one. */
#define BATCH_FRAME_JSON_MAX ((uint64_t)64 << 20)

/* Whether frame f's directory holds a finished frame with the same inputs. */
static int batch_frame_done(const batch_state *b, size_t f)
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

/* Whether dir holds what a killed output commit leaves beside the directory it commits
 * (.thzmap-H-lock, .thzmap-H-stage-..., .thzmap-H-old-...; io/output_stage.c). */
static int batch_has_leftovers(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int found = 0;
    while (d && !found && (e = readdir(d)) != NULL)
        found = !strncmp(e->d_name, ".thzmap-", 8) && strcmp(e->d_name, ".thzmap-batch-lock");
    if (d)
        closedir(d);
    return found;
}

/* A batch killed inside a frame's commit after the exchange (while the replaced frame's
 * files were being deleted) leaves them and the lock beside a frame that is finished,
 * which no later run opens again: opening each finished frame's output and closing it
 * without a commit cleans them up (thz_output_open removes what a dead run left). Only
 * in the directories (OUTDIR, sweep-NN/) that hold such names; best effort: a frame
 * another process holds is left for later. */
static void batch_clean_finished(const batch_state *b)
{
    const thz_sequence *seq = b->seq;
    for (size_t s = 0; s < seq->n_sweeps; s++) {
        char parent[THZ_PATH_MAX], dir[THZ_PATH_MAX], sweep[32];
        batch_sweep_dir(seq, s, sweep, sizeof sweep);
        if (seq->has_sweep)
            snprintf(parent, sizeof parent, "%s/%s", b->outdir, sweep);
        else
            snprintf(parent, sizeof parent, "%s", b->outdir);
        if (!batch_has_leftovers(parent))
            continue;
        for (size_t f = s * seq->frames; f < (s + 1) * seq->frames; f++) {
            if (b->state[f] != FRAME_REUSED ||
                snprintf(dir, sizeof dir, "%s/%s", b->outdir, seq->frame_dir[f]) >= (int)sizeof dir)
                continue;
            thz_output *output = NULL;
            thz_error ignored;
            if (thz_output_open(dir, &output, &ignored) == THZ_OK)
                thz_output_destroy(output);
        }
    }
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

static thz_status batch_write_json(batch_state *b, thz_error *err)
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

/* Whether batch.json is due after a frame: once a second at most, and at most a tenth
 * of the time spent (a long sequence's file is megabytes, and writing it after every
 * frame made 20 000 frames take 2.3 times as long per frame as 100); always after the
 * last frame and after one that failed or was cancelled. The frame directories, not
 * batch.json, tell a later batch what is done. */
static bool batch_json_due(const batch_state *b, size_t f, thz_status st)
{
    if (st != THZ_OK || f + 1 >= b->seq->n_frames)
        return true;
    double wait = 10.0 * b->json_cost_s > 1.0 ? 10.0 * b->json_cost_s : 1.0;
    return batch_now_s() - b->json_at_s >= wait;
}

/* frame.json: which frame this directory is and the hash of its inputs (and the scene
 * it was run with, to rerun it by hand). No timings: it is the same in every run. */
static char *batch_frame_json(const thz_sequence *seq, size_t f, long reused_from)
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

/* Runs frame f into its directory (atomically, with frame.json): computed here (as
 * `thzmap simulate` for a base frame, keeping its photons when the next frame reuses them,
 * else as `thzmap render` from its base frame's photons), or received from the MPI rank
 * the frame was dealt to (b->rank[f] > 0), which computed it the same way. */
static thz_status batch_run_frame(thz_context *ctx, batch_state *b, size_t f, thz_error *err)
{
    const thz_sequence *seq = b->seq;
    char dir[THZ_PATH_MAX];
    if (snprintf(dir, sizeof dir, "%s/%s", b->outdir, seq->frame_dir[f]) >= (int)sizeof dir)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", b->outdir);
    double t0 = batch_now_s(), seconds = 0.0;
    size_t rank = b->rank[f];
    batch_frame fr = {0};
    thz_output *output = NULL;
    char *frame_json = NULL;
    thz_status st = rank == 0 ? batch_frame_load(seq, b->base, f, &fr, err) : THZ_OK;
    /* the frame's scene warnings, as simulate prints its scene's (a caller may fold the
     * repeats of later frames) */
    for (size_t i = 0;
         st == THZ_OK && fr.scene && ctx && ctx->warning && i < thz_scene_warning_count(fr.scene);
         i++)
        ctx->warning(ctx->warning_user, thz_scene_warning(fr.scene, i));
    if (st == THZ_OK && rank == 0) /* sharing within frames: the other ranks serve its scene */
        st = api_mpi_next_scene(ctx, f, err);
    if (st == THZ_OK)
        st = thz_output_open(dir, &output, err);
    thz_output **guard = b->opt ? b->opt->open_output : NULL;
    if (guard)
        *guard = output;
    bool remote_failed = false; /* the rank it was dealt to failed (not this one) */
    if (st == THZ_OK && rank == 0)
        st = batch_frame_compute(ctx, seq, b->base, &b->cache, f, &fr, err);
    else if (st == THZ_OK)
        st = batch_deal_receive(ctx, seq, f, rank, &fr, &seconds, &remote_failed, err);
    if (st == THZ_OK) {
        frame_json = batch_frame_json(seq, f, fr.reused ? (long)b->base[f] : -1);
        if (!frame_json)
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    if (st == THZ_OK)
        st = thz_output_add_run(ctx, output, fr.run, NULL, err);
    if (st == THZ_OK)
        st = thz_output_add_file(output, "frame.json", frame_json, strlen(frame_json), err);
    if (st == THZ_OK)
        st = thz_output_commit(output, err);
    if (st == THZ_OK) {
        /* a frame whose integrator fires none (path) neither fired nor reused photons */
        b->reused_photons[f] = fr.reused  ? BATCH_PHOTONS_REUSED
                               : fr.fired ? BATCH_PHOTONS_FIRED
                                          : BATCH_PHOTONS_NONE;
        b->fired += (size_t)fr.fired;
        b->rerendered += (size_t)fr.reused;
    }
    if (guard)
        *guard = NULL;
    thz_output_destroy(output);
    batch_frame_fini(&fr, &b->cache, f, st == THZ_OK);
    free(frame_json);
    b->seconds[f] = rank == 0 ? batch_now_s() - t0 : seconds;
    if (st != THZ_OK && st != THZ_ERR_CANCELLED && err) {
        if (!remote_failed)
            thz_error_prefix(err, "%s: ", seq->frame_dir[f]);
        else
            thz_error_prefix(err, "%s (MPI rank %zu): ", seq->frame_dir[f], rank);
    }
    return st;
}

/* Under MPI, with at least as many pending photon groups as ranks: deals the groups to the
 * ranks (b->rank; docs/mpi.md "Batch frames") and tells them (*dealt = 1). Else every
 * frame stays rank 0's, each shared with the other ranks (photon batches, pixel tiles). */
static thz_status batch_deal(thz_context *ctx, batch_state *b, int *dealt, thz_error *err)
{
    *dealt = 0;
    size_t ranks = api_mpi_ranks(ctx), nf = b->seq->n_frames, n = 0;
    if (ranks < 2)
        return THZ_OK;
    uint64_t *pending = thz_calloc(nf ? nf : 1, sizeof *pending);
    size_t *owner = thz_calloc(nf ? nf : 1, sizeof *owner);
    thz_status st = pending && owner ? THZ_OK : thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t f = 0; st == THZ_OK && f < nf; f++)
        if (b->state[f] == FRAME_PENDING)
            pending[n++] = f;
    if (st == THZ_OK && batch_deal_owners(b->base, pending, n, ranks, owner) >= ranks) {
        st = api_mpi_deal(ctx, pending, n, err);
        for (size_t i = 0; st == THZ_OK && i < n; i++)
            b->rank[pending[i]] = owner[i];
        *dealt = st == THZ_OK;
    }
    free(pending);
    free(owner);
    return st;
}

static int batch_report(const thz_batch_options *opt, const batch_state *b, size_t frame,
                        const char *stage)
{
    if (!opt || !opt->progress)
        return 0;
    size_t n = b->seq->n_frames;
    double done = (double)(b->computed + b->reused) + (frame < n ? b->frame_share : 0.0);
    thz_batch_progress p = {.frame = frame,
                            .n_frames = n,
                            .computed = b->computed,
                            .reused = b->reused,
                            .seconds = batch_now_s() - b->t0,
                            .stage = stage,
                            .fraction = n ? fmin(done / (double)n, 1.0) : 1.0};
    return opt->progress(opt->progress_user, &p);
}

/* ctx's progress callback while a frame runs: passes the run's progress on to the
 * caller's own callback, and reports the batch's (stage "run") with the share of the
 * frame done: each channel an equal share, its photons (when the frame fires any) the
 * first half of it and its rendering the rest. */
static int batch_on_run_progress(void *user, const thz_progress *p)
{
    batch_state *b = user;
    int stop = b->run_progress ? b->run_progress(b->run_progress_user, p) : 0;
    double frac = p->total ? (double)p->done / (double)p->total : 0.0;
    double share = !strcmp(p->stage, "output") ? 1.0 : b->frame_share; /* all channels done */
    if (!strcmp(p->stage, "photons") || !strcmp(p->stage, "render")) {
        int photons = p->stage[0] == 'p';
        b->photons_seen |= photons;
        double in_channel = photons ? 0.5 * frac : b->photons_seen ? 0.5 + 0.5 * frac : frac;
        share = p->n_channels ? ((double)p->channel + in_channel) / (double)p->n_channels : 0.0;
    }
    /* a stage that starts over (truth maps, another sensor) does not move it back */
    if (share > b->frame_share)
        b->frame_share = fmin(share, 1.0);
    return stop | batch_report(b->opt, b, b->frame, "run");
}

/* Every frame to run is refused before the first starts, as its own run would refuse it,
 * when it would not fit in memory (thz_simulate_check: 10^11 photons of a sweep's second
 * value were refused only after the first value's frames had run). Frames that render
 * from a base frame's photons need that base's maps: their base's first pending frame is
 * checked for them. Frames of an integrator that fires no photons need only their images,
 * which loading them checked. Stage "check" reports each frame checked (the checks build each
 * scene's ray casting and fire a pilot of photons). */
static thz_status batch_check_memory(batch_state *b, thz_error *err)
{
    const thz_sequence *seq = b->seq;
    size_t checked_base = SIZE_MAX;
    /* on this thread alone: a pilot is small, and no thread starts before the first frame
     * (where a library that cannot start one ends the process, an open frame is cleaned
     * up: thz_batch_options.open_output) */
    thz_context *one = thz_context_create();
    if (!one)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_context_set_threads(one, 1);
    thz_status st = THZ_OK;
    for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++) {
        if (b->state[f] != FRAME_PENDING || b->base[f] == checked_base)
            continue;
        if (batch_report(b->opt, b, f, "check")) {
            st = thz_error_set(err, THZ_ERR_CANCELLED, "cancelled");
            break;
        }
        checked_base = b->base[f];
        thz_scene *scene = NULL;
        st = thz_sequence_frame_scene(seq, f, &scene, err);
        /* an integrator that fires no photons (path) needs its images, which loading the
         * frame checked */
        thz_scene_info info;
        if (st == THZ_OK && thz_scene_get_info(scene, &info) == THZ_OK &&
            thz_integrator_needs_photons(info.integrator))
            st = thz_simulate_check(one, scene, NULL, err);
        thz_scene_destroy(scene);
        if (st != THZ_OK && err)
            thz_error_prefix(err, "%s: %s: ", seq->path, seq->frame_dir[f]);
    }
    thz_context_destroy(one);
    return st;
}

/* Takes OUTDIR's batch lock (held until fd is closed or the process ends). */
static thz_status batch_lock(const char *outdir, int *fd, thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status st = thz_path_join(path, sizeof path, outdir, ".thzmap-batch-lock", err);
    if (st != THZ_OK)
        return st;
    *fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (*fd < 0)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* A process-associated (POSIX) lock, not flock: children forked for plotting
     * (core/child.c) would inherit a flock and hold it after a SIGKILL of the batch. */
    struct flock lk = {.l_type = F_WRLCK, .l_whence = SEEK_SET};
    if (fcntl(*fd, F_SETLK, &lk) != 0) {
        close(*fd);
        *fd = -1;
        return thz_error_set(err, THZ_ERR_IO,
                             "%s: another thzmap batch is running into this directory", outdir);
    }
    return THZ_OK;
}

thz_status thz_batch_run(thz_context *ctx, const thz_sequence *seq, const char *outdir,
                         const thz_batch_options *opt, thz_batch_result *result, thz_error *err)
{
    thz_error local;
    if (!err) {
        thz_error_clear(&local);
        err = &local;
    }
    if (result)
        memset(result, 0, sizeof *result);
    if (!seq || !outdir || !outdir[0])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_batch_run: no %s",
                             seq ? "output directory" : "sequence");
    thz_status checked = api_check_threads(ctx, "thz_batch_run", err);
    if (checked != THZ_OK)
        return checked;
    batch_state b = {
        .seq = seq, .outdir = outdir, .opt = opt, .t0 = batch_now_s(), .cache = {.base = SIZE_MAX}};
    b.state = thz_calloc(seq->n_frames, sizeof *b.state);
    b.seconds = thz_calloc(seq->n_frames, sizeof *b.seconds);
    b.base = thz_calloc(seq->n_frames, sizeof *b.base);
    b.reused_photons = thz_calloc(seq->n_frames, sizeof *b.reused_photons);
    b.rank = thz_calloc(seq->n_frames, sizeof *b.rank);
    int lock_fd = -1, dealt = 0;
    thz_status st = b.state && b.seconds && b.base && b.reused_photons && b.rank
                        ? batch_photon_bases(seq, b.base, err)
                        : thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    /* (read before OUTDIR is created or locked: the memory check writes nothing) */
    for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++)
        if (batch_frame_done(&b, f)) {
            b.state[f] = FRAME_REUSED;
            b.reused++;
        }
    if (st == THZ_OK)
        st = batch_check_memory(&b, err);
    if (st == THZ_OK)
        st = batch_mkdirs(outdir, err);
    if (st == THZ_OK)
        st = batch_lock(outdir, &lock_fd, err);
    if (st == THZ_OK && b.reused > 0)
        batch_clean_finished(&b);
    /* a sensor too large for the movie encoder: said before the frames run */
    bool movies = !(opt && opt->no_movies);
    if (st == THZ_OK && movies && seq->movies_unmade) {
        snprintf(b.movies_skipped, sizeof b.movies_skipped, "%s", seq->movies_unmade);
        if (ctx && ctx->warning)
            ctx->warning(ctx->warning_user, b.movies_skipped);
    }
    if (st == THZ_OK)
        st = batch_write_json(&b, err);
    if (st == THZ_OK)
        st = batch_deal(ctx, &b, &dealt, err);
    if (ctx) { /* the frames' runs report through batch_on_run_progress */
        b.run_progress = ctx->progress;
        b.run_progress_user = ctx->progress_user;
        ctx->progress = batch_on_run_progress;
        ctx->progress_user = &b;
    }
    for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++) {
        if (b.state[f] == FRAME_REUSED)
            continue;
        if (batch_report(opt, &b, f, "frame")) {
            st = thz_error_set(err, THZ_ERR_CANCELLED, "cancelled");
            break;
        }
        double t0 = batch_now_s();
        b.frame = f;
        b.frame_share = 0.0;
        b.photons_seen = 0;
        st = batch_run_frame(ctx, &b, f, err);
        b.frame_share = 0.0;
        b.seconds_frames += batch_now_s() - t0;
        if (st == THZ_OK) {
            b.state[f] = FRAME_COMPUTED;
            b.computed++;
        } else if (st != THZ_ERR_CANCELLED) {
            b.state[f] = FRAME_FAILED;
        }
        if (st != THZ_OK)
            batch_photon_cache_clear(&b.cache);
        thz_error werr;
        if (batch_json_due(&b, f, st) && batch_write_json(&b, &werr) != THZ_OK && st == THZ_OK) {
            *err = werr;
            st = werr.status;
        }
    }
    if (ctx) {
        ctx->progress = b.run_progress;
        ctx->progress_user = b.run_progress_user;
    }
    if (dealt)
        api_mpi_deal_end(ctx);
    if (st == THZ_OK && movies) {
        if (batch_report(opt, &b, seq->n_frames, "movie"))
            st = thz_error_set(err, THZ_ERR_CANCELLED, "cancelled");
        double t0 = batch_now_s();
        b.movies = st == THZ_OK ? json_array() : NULL;
        if (st == THZ_OK)
            st = b.movies ? batch_movies_write(seq, outdir, b.movies, b.movies_skipped,
                                               sizeof b.movies_skipped, err)
                          : thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        /* an interrupt while the movies were encoded (they are not cancellable one by
         * one) still stops the batch: it said "complete" and exited 0 */
        if (st == THZ_OK && batch_report(opt, &b, seq->n_frames, "movie"))
            st = thz_error_set(err, THZ_ERR_CANCELLED, "cancelled");
        /* (not again when the frames' start said so) */
        if (st == THZ_OK && b.movies_skipped[0] && ctx && ctx->warning &&
            !(seq->movies_unmade && !strcmp(seq->movies_unmade, b.movies_skipped)))
            ctx->warning(ctx->warning_user, b.movies_skipped);
        b.seconds_movies = batch_now_s() - t0;
        if (st != THZ_OK) {
            json_decref(b.movies);
            b.movies = NULL;
        }
    }
    if (st == THZ_OK)
        st = batch_write_json(&b, err);
    if (st == THZ_OK)
        batch_report(opt, &b, seq->n_frames, "done");
    if (result) {
        result->n_frames = seq ? seq->n_frames : 0;
        result->computed = b.computed;
        result->reused = b.reused;
        result->movies = b.movies ? json_array_size(b.movies) : 0;
        result->seconds = batch_now_s() - b.t0;
    }
    json_decref(b.movies);
    batch_photon_cache_clear(&b.cache);
    free(b.state);
    free(b.seconds);
    free(b.base);
    free(b.reused_photons);
    free(b.rank);
    if (lock_fd >= 0)
        close(lock_fd);
    return st;
}
