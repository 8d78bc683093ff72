/* Running a sequence (thz_batch_run): every frame as `thzmap simulate` would, each into
 * its own atomic output directory (thz_output) holding frame.json with the hash of the
 * frame's inputs; OUTDIR/batch.json rewritten (temporary file, then rename) as frames
 * finish (batch_json_due) and at the end; the movies last, rebuilt from the frames' files.
 * A frame directory whose frame.json carries the frame's hash is finished and is not run
 * again, which is all that resuming a killed batch needs: a frame appears whole or not at
 * all. Under MPI the pending frames are dealt to the ranks by photon groups when there
 * are enough of them (batch_deal.c), and this process, rank 0, writes every frame in
 * frame order. batch_json.c writes batch.json and frame.json, batch_outdir.c creates,
 * locks and cleans OUTDIR (batch_run_state.h).
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "batch/batch_run_state.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/path.h"

double batch_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
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
    else if (st == THZ_OK) {
        /* its seconds: its computing there and its writing here, as a frame of rank 0's
         * (not the wait for it or its transfer) */
        double r0 = batch_now_s();
        st = batch_deal_receive(ctx, seq, f, rank, &fr, &seconds, &remote_failed, err);
        seconds -= batch_now_s() - r0;
    }
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
    b->seconds[f] = batch_now_s() - t0 + seconds;
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

/* Reads again, under OUTDIR's lock, whether the frames found finished still are: the
 * first reading comes before the lock (and the memory check, which builds every frame to
 * run), and a batch of other values that ran into OUTDIR and ended meanwhile left its own
 * frames there, which this batch then counted as its own (batch.json of one sequence
 * over the images of another). Such frames are run again. Whether any was. */
static bool batch_recheck_done(batch_state *b)
{
    bool changed = false;
    for (size_t f = 0; f < b->seq->n_frames; f++)
        if (b->state[f] == FRAME_REUSED && !batch_frame_done(b, f)) {
            b->state[f] = FRAME_PENDING;
            b->reused--;
            changed = true;
        }
    return changed;
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
        return api_done(ctx,
                        thz_error_set(err, THZ_ERR_INPUT, "thz_batch_run: no %s",
                                      seq ? "output directory" : "sequence"),
                        err);
    thz_status checked = api_check_threads(ctx, "thz_batch_run", err);
    if (checked != THZ_OK)
        return api_done(ctx, checked, err);
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
    if (st == THZ_OK && b.reused > 0 && batch_recheck_done(&b))
        st = batch_check_memory(&b, err);
    if (st == THZ_OK && b.reused > 0)
        batch_clean_finished(&b);
    /* a kept frame's frame.json says what this sequence's would (its time at a changed
     * fps, its number at a changed frames per sweep value), as batch.json does */
    for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++)
        if (b.state[f] == FRAME_REUSED)
            st = batch_frame_refresh(&b, f, err);
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
    return api_done(ctx, st, err);
}
