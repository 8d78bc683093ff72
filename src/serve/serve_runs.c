/* Jobs: simulate, render, batch and bands runs queued by the page and run one at a time
 * by a worker thread through the library, with progress (polled by GET /api/runs,
 * streamed by GET /api/runs/ID/events) and cancellation (DELETE, or the server
 * stopping). Outputs are written atomically, as by the CLI: a cancelled run leaves its
 * output directory as it was. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../cli/run_command.h"
#include "serve_jobs.h"

const char *const serve_state_names[] = {"queued", "running", "done", "failed", "cancelled"};
const char *const serve_command_names[] = {"simulate", "render", "batch", "bands"};

static double serve_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bool serve_job_finished(const serve_job *j)
{
    return j->state == JOB_DONE || j->state == JOB_FAILED || j->state == JOB_CANCELLED;
}

/* The job as JSON; the caller holds s->lock. */
static json_t *serve_job_json(const serve_job *j)
{
    double end = serve_job_finished(j) ? j->t_end : serve_now_s();
    /* a message cut to its size may end inside a character (an out path of accented
     * names): jansson refused it, and the job vanished from the list while its page polled
     * it for ever */
    char message[sizeof j->message], error[sizeof j->error];
    snprintf(message, sizeof message, "%s", j->message);
    snprintf(error, sizeof error, "%s", j->error);
    serve_text_fit(message);
    serve_text_fit(error);
    json_t *o = json_pack("{s:i, s:s, s:s, s:s, s:s, s:f, s:s, s:f}", "id", j->id, "command",
                          serve_command_names[j->command], "scene", j->scene, "out", j->out,
                          "state", serve_state_names[j->state], "progress", j->progress, "message",
                          message, "seconds", j->t_start > 0.0 ? end - j->t_start : 0.0);
    if (o) {
        json_object_set_new(o, "error", error[0] ? json_string(error) : json_null());
        /* a copy: the worker appends to the job's while the answer is written unlocked */
        json_t *w = j->warnings ? json_deep_copy(j->warnings) : json_array();
        if (w && j->warnings_dropped)
            json_array_append_new(w, json_sprintf("... and %zu more warnings (summary.json "
                                                  "of the run has them)",
                                                  j->warnings_dropped));
        json_object_set_new(o, "warnings", w);
    }
    return o;
}

void serve_job_free(serve_job *j)
{
    if (!j)
        return;
    for (size_t i = 0; i < j->n_targets; i++)
        free(j->targets[i]);
    free(j->targets);
    json_decref(j->warnings);
    free(j);
}

/* ---- progress and cancellation (on the worker thread) ------------------------------ */

typedef struct serve_job_ctx {
    serve *s;
    serve_job *job;
    double last_s;
} serve_job_ctx;

/* Updates the job (at most 10 times per second unless finishing a stage) and says
 * whether to stop. */
static int serve_job_report(serve_job_ctx *c, double fraction, const char *message)
{
    serve *s = c->s;
    double now = serve_now_s();
    pthread_mutex_lock(&s->lock);
    int stop = c->job->cancel || s->stopping;
    if (now - c->last_s >= 0.1 || fraction >= 1.0) {
        c->last_s = now;
        c->job->progress = fraction < 0.0 ? 0.0 : fraction > 1.0 ? 1.0 : fraction;
        snprintf(c->job->message, sizeof c->job->message, "%s", message);
        c->job->version++;
        pthread_cond_broadcast(&s->changed);
    }
    pthread_mutex_unlock(&s->lock);
    return stop;
}

/* A run's progress: each channel an equal share, photons the first half of it when the
 * run fires any (as the CLI's whole-run ETA counts). */
static int serve_on_progress(void *user, const thz_progress *p)
{
    serve_job_ctx *c = user;
    if (c->job->command == CMD_BATCH) {
        /* the batch's own callback reports the same events with the batch's share; a
         * report from here would take its turn (ten a second) with a frozen share */
        pthread_mutex_lock(&c->s->lock);
        int stop = c->job->cancel || c->s->stopping;
        pthread_mutex_unlock(&c->s->lock);
        return stop;
    }
    double frac = p->total ? (double)p->done / (double)p->total : 0.0;
    bool photons = strcmp(p->stage, "photons") == 0;
    if (photons)
        c->job->photons_seen = true;
    double share = (double)p->channel + (photons                ? 0.5 * frac
                                         : c->job->photons_seen ? 0.5 + 0.5 * frac
                                                                : frac);
    share /= (double)(p->n_channels ? p->n_channels : 1);
    if (strcmp(p->stage, "output") == 0)
        share = 1.0;
    if (strcmp(p->stage, "prepare") == 0) /* before the first channel */
        share = 0.0;
    bool bands = strcmp(p->stage, "bands") == 0; /* channel: the render, nominal first */
    if (bands) /* the nominal render about half the time, the nuisances' coarse ones the rest */
        share = p->n_channels == 1 ? frac /* no nuisances: the nominal render alone */
                : p->channel == 0 || p->n_channels < 2
                    ? 0.5 * frac
                    : 0.5 + 0.5 * ((double)(p->channel - 1) + frac) / (double)(p->n_channels - 1);
    /* with the unit of the stage's count (rows; the photons stage's is its name); the output
     * has no channel */
    char message[256];
    if (strcmp(p->stage, "output") == 0)
        snprintf(message, sizeof message, "writing the results");
    else if (bands && p->n_channels == 0)
        snprintf(message, sizeof message, "nominal render, %llu/%llu candidate channels",
                 (unsigned long long)p->done, (unsigned long long)p->total);
    else if (bands)
        snprintf(message, sizeof message, "render %zu/%zu, %llu/%llu candidate channels",
                 p->channel + 1, p->n_channels, (unsigned long long)p->done,
                 (unsigned long long)p->total);
    else if (strcmp(p->stage, "prepare") == 0)
        snprintf(message, sizeof message, "preparing the back-side sources: %llu/%llu objects",
                 (unsigned long long)p->done, (unsigned long long)p->total);
    else
        snprintf(message, sizeof message, "channel %zu/%zu, %s %llu/%llu%s", p->channel + 1,
                 p->n_channels, p->stage, (unsigned long long)p->done, (unsigned long long)p->total,
                 strcmp(p->stage, "render") == 0 ? " rows" : ""); /* "photons 2000/8000" */
    return serve_job_report(c, share, message);
}

static int serve_on_batch_progress(void *user, const thz_batch_progress *p)
{
    serve_job_ctx *c = user;
    char message[256];
    snprintf(message, sizeof message, "frame %zu/%zu (%s; %zu computed, %zu reused)",
             p->frame < p->n_frames ? p->frame + 1 : p->n_frames, p->n_frames, p->stage,
             p->computed, p->reused);
    return serve_job_report(c, p->fraction, message);
}

/* A warning of the job: kept in its "warnings" (it passed as the message alone, which
 * the next progress report replaced) and shown as the message until then. */
static void serve_on_warning(void *user, const char *message)
{
    serve_job_ctx *c = user;
    serve_job *j = c->job;
    char text[1024];
    snprintf(text, sizeof text, "%s", message);
    serve_text_fit(text);
    pthread_mutex_lock(&c->s->lock);
    snprintf(j->message, sizeof j->message, "warning: %.240s", text);
    if (!j->warnings)
        j->warnings = json_array();
    if (j->warnings && json_array_size(j->warnings) < SERVE_JOB_WARNINGS)
        json_array_append_new(j->warnings, json_string(text));
    else
        j->warnings_dropped++;
    j->version++;
    pthread_cond_broadcast(&c->s->changed);
    pthread_mutex_unlock(&c->s->lock);
}

/* ---- running a job ----------------------------------------------------------------- */

/* The jobs load their scene or sequence within the root (thz_scene_load_within): a file
 * it names outside the root fails the job before anything is written. */
static thz_status serve_run_scene(thz_context *ctx, serve_job_ctx *c, thz_error *err)
{
    const serve *s = c->s;
    const serve_job *j = c->job;
    thz_scene *scene = NULL;
    thz_run *run = NULL;
    thz_output *output = NULL;
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.photons_per_channel = j->photons;
    settings.has_seed = j->has_seed;
    settings.seed = j->seed;
    settings.integrator = j->integrator[0] ? j->integrator : NULL;
    settings.target_noise_k = j->target_noise_k;
    settings.max_seconds = j->max_seconds;
    settings.keep_photons = j->save_photon_map;
    thz_write_options write = {.photon_map = j->save_photon_map};
    long sensor = -1;
    const char *map = j->photon_map[0] ? j->photon_map : NULL;
    thz_status st = thz_scene_load_within(j->scene, s->root, &scene, err);
    if (st == THZ_OK) { /* what `thzmap simulate|render` prints before it runs */
        thz_scene_info info;
        thz_scene_get_info(scene, &info);
        const char *integrator = j->integrator[0] ? j->integrator : info.integrator;
        char said[320];
        if (j->command == CMD_SIMULATE && j->photons && !thz_integrator_needs_photons(integrator)) {
            snprintf(said, sizeof said,
                     "options.photons %" PRIu64 " is not used: the %s integrator fires no "
                     "photons (give options.integrator photon-map or final-gather to fire them)",
                     j->photons, integrator);
            serve_on_warning(c, said);
        }
        if (j->command == CMD_RENDER && j->photon_map[0] &&
            !thz_integrator_needs_photons(integrator)) {
            snprintf(said, sizeof said,
                     "options.photon_map is not used: the %s integrator renders without "
                     "photons (give options.integrator photon-map or final-gather to render "
                     "from it)",
                     integrator);
            serve_on_warning(c, said);
            map = NULL;
        }
        for (size_t i = 0; i < thz_scene_warning_count(scene); i++)
            serve_on_warning(c, thz_scene_warning(scene, i));
        st = thz_output_open(j->out, &output, err);
    }
    *cli_exit_guard() = output;
    if (st == THZ_OK && j->sensor[0] && (sensor = thz_scene_sensor_index(scene, j->sensor)) < 0) {
        snprintf(err->message, sizeof err->message, "render: the scene has no sensor named '%s'",
                 j->sensor);
        err->status = st = THZ_ERR_INPUT;
    }
    /* a render reads the photon-map file a channel at a time, as `thzmap render` does */
    if (st == THZ_OK && j->command == CMD_RENDER && map)
        st = thz_render_file(ctx, scene, map, sensor, &settings, &run, err);
    else if (st == THZ_OK)
        st = j->command == CMD_RENDER
                 ? thz_render_run(ctx, scene, NULL, sensor, &settings, &run, err)
                 : thz_simulate(ctx, scene, &settings, &run, err);
    if (st == THZ_OK)
        st = thz_output_add_run(ctx, output, run, &write, err);
    if (st == THZ_OK)
        st = thz_output_commit(output, err);
    *cli_exit_guard() = NULL;
    thz_output_destroy(output);
    thz_run_destroy(run);
    thz_scene_destroy(scene);
    return st;
}

static thz_status serve_run_batch(thz_context *ctx, serve_job_ctx *c, thz_error *err)
{
    thz_sequence *seq = NULL;
    thz_status st = thz_sequence_load_within(c->job->scene, c->s->root, &seq, err);
    thz_batch_options opt = {.progress = serve_on_batch_progress,
                             .progress_user = c,
                             .no_movies = c->job->no_movies,
                             .open_output = cli_exit_guard()};
    if (st == THZ_OK)
        st = thz_batch_run(ctx, seq, c->job->out, &opt, NULL, err);
    thz_sequence_destroy(seq);
    return st;
}

static thz_status serve_run_bands(thz_context *ctx, const serve *s, const serve_job *j,
                                  thz_error *err)
{
    thz_bands_options opt;
    thz_bands_options_init(&opt);
    opt.root = s->root;
    opt.count = j->count;
    if (j->from_thz > 0.0)
        opt.from_thz = j->from_thz;
    if (j->to_thz > 0.0)
        opt.to_thz = j->to_thz;
    if (j->step_ghz > 0.0)
        opt.step_ghz = j->step_ghz;
    if (j->netd_k > 0.0) {
        opt.has_netd = 1;
        opt.netd_k = j->netd_k;
    }
    opt.has_seed = j->has_seed;
    opt.seed = j->seed;
    opt.targets = (const char *const *)j->targets;
    opt.n_targets = j->n_targets;
    thz_bands *bands = NULL;
    thz_status st = thz_bands_select(ctx, j->scene, &opt, &bands, err);
    if (st == THZ_OK)
        st = thz_bands_write(bands, j->out, err);
    thz_bands_destroy(bands);
    return st;
}

static void serve_run_job(serve *s, serve_job *j)
{
    serve_job_ctx c = {.s = s, .job = j};
    thz_error err = {0};
    thz_status st = THZ_ERR_NOMEM;
    thz_context *ctx = thz_context_create();
    if (ctx) {
        thz_context_set_threads(ctx, j->threads);
        thz_context_set_progress(ctx, serve_on_progress, &c);
        thz_context_set_warning(ctx, serve_on_warning, &c);
        st = j->command == CMD_BATCH   ? serve_run_batch(ctx, &c, &err)
             : j->command == CMD_BANDS ? serve_run_bands(ctx, s, j, &err)
                                       : serve_run_scene(ctx, &c, &err);
        thz_context_destroy(ctx);
    }
    pthread_mutex_lock(&s->lock);
    j->t_end = serve_now_s();
    if (st == THZ_OK) {
        j->state = JOB_DONE;
        j->progress = 1.0;
        size_t n_warn = json_array_size(j->warnings) + j->warnings_dropped;
        if (n_warn)
            snprintf(j->message, sizeof j->message, "done; results in %.200s (%zu warning%s)",
                     j->out, n_warn, n_warn == 1 ? "" : "s");
        else
            snprintf(j->message, sizeof j->message, "done; results in %.200s", j->out);
    } else if (st == THZ_ERR_CANCELLED) {
        j->state = JOB_CANCELLED;
        if (j->command == CMD_BATCH) /* finished frames stay, for a later batch to reuse */
            snprintf(j->message, sizeof j->message,
                     "cancelled; the frames finished before stay in %.200s", j->out);
        else
            snprintf(j->message, sizeof j->message, "cancelled; nothing written to %.200s", j->out);
    } else {
        j->state = JOB_FAILED;
        snprintf(j->error, sizeof j->error, "%s",
                 err.message[0] ? err.message : thz_status_name(st));
        snprintf(j->message, sizeof j->message, "failed");
    }
    j->version++;
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
}

static void *serve_worker(void *arg)
{
    serve *s = arg;
    pthread_mutex_lock(&s->lock);
    while (!s->stopping) {
        serve_job *next = NULL;
        for (size_t i = 0; i < s->n_jobs && !next; i++)
            if (s->jobs[i]->state == JOB_QUEUED)
                next = s->jobs[i];
        if (!next) {
            pthread_cond_wait(&s->changed, &s->lock);
            continue;
        }
        next->state = JOB_RUNNING;
        next->t_start = serve_now_s();
        snprintf(next->message, sizeof next->message, "starting");
        next->version++;
        pthread_cond_broadcast(&s->changed);
        pthread_mutex_unlock(&s->lock);
        serve_run_job(s, next);
        pthread_mutex_lock(&s->lock);
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

bool serve_runs_start(serve *s)
{
    s->worker_started = pthread_create(&s->worker, NULL, serve_worker, s) == 0;
    return s->worker_started;
}

void serve_runs_stop(serve *s)
{
    pthread_mutex_lock(&s->lock);
    s->stopping = true;
    for (size_t i = 0; i < s->n_jobs; i++) {
        serve_job *j = s->jobs[i];
        j->cancel = true;
        if (j->state == JOB_QUEUED) {
            j->state = JOB_CANCELLED;
            j->version++;
        }
    }
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
    if (s->worker_started)
        pthread_join(s->worker, NULL);
    s->worker_started = false;
    /* Every job is final now: give the event streams a moment to send it and their end
     * (the daemon's stop closes their connections at once, and a page following a run
     * would not learn that it was cancelled); a client that does not read is not waited
     * for beyond that. */
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += SERVE_STREAMS_END_S;
    pthread_mutex_lock(&s->lock);
    while (s->streams > 0)
        if (pthread_cond_timedwait(&s->changed, &s->lock, &until) != 0)
            break;
    pthread_mutex_unlock(&s->lock);
}

void serve_runs_free(serve *s)
{
    for (size_t i = 0; i < s->n_jobs; i++)
        serve_job_free(s->jobs[i]);
    free(s->jobs);
    s->jobs = NULL;
    s->n_jobs = 0;
}

/* ---- endpoints --------------------------------------------------------------------------- */

static serve_job *serve_find_job(serve *s, long id)
{
    for (size_t i = 0; i < s->n_jobs; i++)
        if (s->jobs[i]->id == id)
            return s->jobs[i];
    return NULL;
}

typedef struct serve_stream {
    serve *s;
    int id;
    unsigned seen; /* the job's version last sent; 0: nothing sent yet */
    bool ended;
} serve_stream;

/* The event stream's reader: blocks (its own connection thread) until the job changes,
 * sending a comment every 15 s to keep the connection open. */
static ssize_t serve_stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    serve_stream *st = cls;
    serve *s = st->s;
    if (st->ended)
        return MHD_CONTENT_READER_END_OF_STREAM;
    pthread_mutex_lock(&s->lock);
    serve_job *j = serve_find_job(s, st->id);
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += 15;
    /* at stop every job is cancelled and the worker joined before the daemon stops, so
     * a running job soon ends: its stream waits for that final state (the page shows it)
     * rather than ending at once */
    while (j && j->version == st->seen && !(s->stopping && serve_job_finished(j)))
        if (pthread_cond_timedwait(&s->changed, &s->lock, &until) != 0)
            break;
    ssize_t n;
    if (j && j->version != st->seen) {
        json_t *o = serve_job_json(j);
        char *text =
            o ? json_dumps(o, JSON_COMPACT | JSON_ENSURE_ASCII | JSON_REAL_PRECISION(9)) : NULL;
        json_decref(o);
        st->seen = j->version;
        st->ended = serve_job_finished(j);
        n = text ? snprintf(buf, max, "event: progress\ndata: %s\n\n%s", text,
                            st->ended ? "event: end\ndata: {}\n\n" : "")
                 : snprintf(buf, max, ": out of memory\n\n");
        free(text);
    } else if (!j || (s->stopping && serve_job_finished(j))) {
        st->ended = true;
        n = snprintf(buf, max, "event: end\ndata: {}\n\n");
    } else {
        n = snprintf(buf, max, ": keep-alive\n\n");
    }
    pthread_mutex_unlock(&s->lock);
    return n < 0 || (size_t)n >= max ? MHD_CONTENT_READER_END_WITH_ERROR : n;
}

/* The daemon lets go of a stream (its response destroyed): one stream fewer to wait for
 * at stop. */
static void serve_stream_free(void *cls)
{
    serve_stream *st = cls;
    serve *s = st->s;
    pthread_mutex_lock(&s->lock);
    s->streams--;
    pthread_cond_broadcast(&s->changed);
    pthread_mutex_unlock(&s->lock);
    free(st);
}

static enum MHD_Result serve_events(serve_request *r, long id)
{
    serve_stream *st = calloc(1, sizeof *st);
    if (!st)
        return MHD_NO;
    *st = (serve_stream){.s = r->s, .id = (int)id};
    pthread_mutex_lock(&r->s->lock);
    r->s->streams++;
    pthread_mutex_unlock(&r->s->lock);
    struct MHD_Response *resp = MHD_create_response_from_callback(
        MHD_SIZE_UNKNOWN, 8192, serve_stream_read, st, serve_stream_free);
    if (!resp) {
        serve_stream_free(st);
        return MHD_NO;
    }
    MHD_add_response_header(resp, "Content-Type", "text/event-stream");
    serve_data_headers(resp); /* as every /api/ answer: CSP, nosniff, no-store */
    enum MHD_Result ret = MHD_queue_response(r->conn, 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

enum MHD_Result serve_runs(serve_request *r)
{
    serve *s = r->s;
    const char *rest = r->url + strlen("/api/runs");
    if (*rest == '\0' || strcmp(rest, "/") == 0) {
        if (strcmp(r->method, "POST") == 0)
            return serve_runs_post(r);
        if (strcmp(r->method, "GET") != 0)
            return serve_reply_error(r, 405, "%s is not allowed on /api/runs", r->method);
        json_t *list = json_array();
        pthread_mutex_lock(&s->lock);
        for (size_t i = 0; i < s->n_jobs; i++)
            json_array_append_new(list, serve_job_json(s->jobs[i]));
        pthread_mutex_unlock(&s->lock);
        return serve_reply_json(r, 200, list);
    }
    char *end = NULL;
    long id = strtol(rest + 1, &end, 10);
    bool events = strcmp(end, "/events") == 0;
    if (end == rest + 1 || (*end && !events))
        return serve_reply_error(r, 404, "no such endpoint: %s", r->url);
    pthread_mutex_lock(&s->lock);
    serve_job *j = serve_find_job(s, id);
    if (!j) {
        pthread_mutex_unlock(&s->lock);
        return serve_reply_error(r, 404, "no job %ld", id);
    }
    if (events) {
        pthread_mutex_unlock(&s->lock);
        if (strcmp(r->method, "GET") != 0)
            return serve_reply_error(r, 405, "%s is not allowed on %s", r->method, r->url);
        return serve_events(r, id);
    }
    unsigned status = 200;
    if (strcmp(r->method, "DELETE") == 0) {
        if (serve_job_finished(j)) {
            status = 409;
        } else {
            j->cancel = true;
            if (j->state == JOB_QUEUED) {
                j->state = JOB_CANCELLED;
                j->t_end = serve_now_s();
                snprintf(j->message, sizeof j->message, "cancelled before it started");
            }
            j->version++;
            pthread_cond_broadcast(&s->changed);
        }
    } else if (strcmp(r->method, "GET") != 0) {
        pthread_mutex_unlock(&s->lock);
        return serve_reply_error(r, 405, "%s is not allowed on %s", r->method, r->url);
    }
    json_t *o = serve_job_json(j);
    pthread_mutex_unlock(&s->lock);
    if (status == 409) {
        json_decref(o);
        return serve_reply_error(r, 409, "job %ld has already finished", id);
    }
    return serve_reply_json(r, status, o);
}
