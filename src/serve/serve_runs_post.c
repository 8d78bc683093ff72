/* POST /api/runs: the job a request body describes, checked (every error names the JSON
 * path of the body it is about), and queued. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "serve_jobs.h"

/* A string option of 1 to size - 1 bytes (copied into out); false after replying 400. */
static bool serve_opt_string(serve_request *r, json_t *v, const char *path, char *out, size_t size,
                             enum MHD_Result *ret)
{
    if (!json_is_string(v) || json_string_length(v) == 0) {
        *ret = serve_reply_bad_json(r, path, "expected a non-empty string");
        return false;
    }
    if (json_string_length(v) >= size) {
        *ret = serve_reply_bad_json(r, path, "expected at most %zu bytes, got %zu", size - 1,
                                    json_string_length(v));
        return false;
    }
    snprintf(out, size, "%s", json_string_value(v));
    return true;
}

/* A number > 0 (or >= 0 with zero_ok); false after replying 400. */
static bool serve_opt_number(serve_request *r, json_t *v, const char *path, double max, double *out,
                             enum MHD_Result *ret)
{
    double x = json_is_number(v) ? json_number_value(v) : NAN;
    if (!(x > 0.0 && x <= max)) {
        *ret = serve_reply_bad_json(r, path, "expected a number > 0 and <= %g", max);
        return false;
    }
    *out = x;
    return true;
}

static bool serve_opt_whole(serve_request *r, json_t *v, const char *path, uint64_t min,
                            uint64_t max, uint64_t *out, enum MHD_Result *ret)
{
    double x = json_is_integer(v) ? (double)json_integer_value(v)
               : json_is_real(v)  ? json_real_value(v)
                                  : NAN;
    if (!(x >= (double)min && x <= (double)max && x == floor(x))) {
        *ret = serve_reply_bad_json(r, path, "expected a whole number from %llu to %llu",
                                    (unsigned long long)min, (unsigned long long)max);
        return false;
    }
    *out = json_is_integer(v) ? (uint64_t)json_integer_value(v) : (uint64_t)x;
    return true;
}

static bool serve_opt_bool(serve_request *r, json_t *v, const char *path, bool *out,
                           enum MHD_Result *ret)
{
    if (!json_is_boolean(v)) {
        *ret = serve_reply_bad_json(r, path, "expected true or false");
        return false;
    }
    *out = json_is_true(v);
    return true;
}

/* The path REL in `v` checked against the root into out; with must_exist, a regular
 * file (a FIFO would hold the job, and the server's stop, until someone writes to it).
 * False after replying. */
static bool serve_opt_path(serve_request *r, json_t *v, const char *path, bool must_exist,
                           char *out, enum MHD_Result *ret)
{
    char rel[SERVE_MAX_REL_BYTES];
    if (!serve_opt_string(r, v, path, rel, sizeof rel, ret))
        return false;
    serve_path_status st = serve_path(r->s, rel, must_exist, out);
    if (st != SERVE_PATH_OK) {
        *ret = serve_reply_path(r, st, path, ": ", rel);
        return false;
    }
    if (!must_exist)
        return true;
    int fd = serve_open_regular(out); /* a regular file this server may read, as GET's */
    if (fd >= 0) {
        close(fd);
        return true;
    }
    if (errno == EACCES)
        *ret = serve_reply_error(r, 403, "%s: %s: permission denied", path, rel);
    else
        *ret = serve_reply_bad_json(r, path, "%s: not a regular file", rel);
    return false;
}

/* True when a simulate job queued or running will write the photon map at `map` (a path
 * as serve_path resolves it): a render queued behind it reads the map when it starts, so
 * the map need not exist yet (it was refused with 404). */
static bool serve_map_coming(serve *s, const char *map)
{
    static const char name[] = "photon-map.thzpm";
    size_t len = strlen(map), name_len = sizeof name - 1;
    if (len <= name_len || strcmp(map + len - name_len, name) != 0 ||
        map[len - name_len - 1] != '/')
        return false;
    bool coming = false;
    pthread_mutex_lock(&s->lock);
    for (size_t i = 0; i < s->n_jobs && !coming; i++) {
        const serve_job *q = s->jobs[i];
        coming = !serve_job_finished(q) && q->command == CMD_SIMULATE && q->save_photon_map &&
                 strlen(q->out) == len - name_len - 1 &&
                 strncmp(q->out, map, len - name_len - 1) == 0;
    }
    pthread_mutex_unlock(&s->lock);
    return coming;
}

/* The integrator a simulate or render job runs: its option, else the scene's
 * render.integrator, else "path", the scene format's default (docs/scene-format.md), into
 * buf. NULL when the scene does not name one the loader would take: loading it then fails
 * the job in the loader's words. *from says where the name came from. */
static const char *serve_job_integrator(const serve_job *j, char *buf, size_t size,
                                        const char **from)
{
    *from = "options.integrator";
    if (j->integrator[0])
        return j->integrator;
    size_t n = 0;
    char *text = serve_read_file(j->scene, SERVE_MAX_FILE_BYTES, &n);
    json_t *doc = text ? json_loadb(text, n, JSON_REJECT_DUPLICATES, NULL) : NULL;
    free(text);
    json_t *render = json_object_get(doc, "render");
    json_t *name = json_object_get(render, "integrator");
    const char *out = NULL;
    if (json_is_object(doc) && (!render || (json_is_object(render) && !name))) {
        *from = "the default, the scene naming no render.integrator";
        out = "path";
    } else if (json_is_string(name) && thz_integrator_known(json_string_value(name))) {
        *from = "the scene's render.integrator";
        snprintf(buf, size, "%s", json_string_value(name));
        out = buf;
    }
    json_decref(doc);
    return out;
}

/* One key of "options"; false after replying 400. */
static bool serve_parse_option(serve_request *r, serve_job *j, const char *key, json_t *v,
                               enum MHD_Result *ret)
{
    char path[300];
    snprintf(path, sizeof path, "$.options.%s", key);
    uint64_t u = 0;
    bool scene = j->command == CMD_SIMULATE || j->command == CMD_RENDER;
    if (strcmp(key, "threads") == 0) {
        /* at most the machine's processors: more gain nothing, and where the system
         * refuses the threads OpenMP ends the process, and with it the server's every job
         * (1024 under `ulimit -u 512` did) */
        long procs = sysconf(_SC_NPROCESSORS_ONLN);
        if (!serve_opt_whole(r, v, path, 0, procs > 0 ? (uint64_t)procs : 1, &u, ret))
            return false;
        j->threads = (int)u;
        return true;
    }
    if (strcmp(key, "seed") == 0 && j->command != CMD_RENDER && j->command != CMD_BATCH) {
        j->has_seed = true;
        return serve_opt_whole(r, v, path, 0, INT64_MAX, &j->seed, ret);
    }
    if (scene && strcmp(key, "integrator") == 0) {
        /* a name too long for the buffer is no integrator either: the names are the limit */
        if (!json_is_string(v) || !thz_integrator_known(json_string_value(v)) ||
            json_string_length(v) >= sizeof j->integrator) {
            *ret = serve_reply_bad_json(r, path, "expected path, final-gather or photon-map");
            return false;
        }
        snprintf(j->integrator, sizeof j->integrator, "%s", json_string_value(v));
        return true;
    }
    if (scene && strcmp(key, "target_noise_k") == 0)
        return serve_opt_number(r, v, path, 1e6, &j->target_noise_k, ret);
    if (scene && strcmp(key, "max_seconds") == 0)
        return serve_opt_number(r, v, path, 1e9, &j->max_seconds, ret);
    if (j->command == CMD_SIMULATE && strcmp(key, "photons") == 0)
        return serve_opt_whole(r, v, path, 1, UINT64_C(1000000000000), &j->photons, ret);
    if (j->command == CMD_SIMULATE && strcmp(key, "save_photon_map") == 0)
        return serve_opt_bool(r, v, path, &j->save_photon_map, ret);
    if (j->command == CMD_RENDER && strcmp(key, "photon_map") == 0) {
        if (!serve_opt_path(r, v, path, false, j->photon_map, ret))
            return false;
        return serve_map_coming(r->s, j->photon_map) ||
               serve_opt_path(r, v, path, true, j->photon_map, ret);
    }
    if (j->command == CMD_RENDER && strcmp(key, "sensor") == 0)
        return serve_opt_string(r, v, path, j->sensor, sizeof j->sensor, ret);
    if (j->command == CMD_BATCH && strcmp(key, "no_movies") == 0)
        return serve_opt_bool(r, v, path, &j->no_movies, ret);
    if (j->command == CMD_BANDS) {
        if (strcmp(key, "count") == 0) {
            if (!serve_opt_whole(r, v, path, 1, THZ_BANDS_MAX_COUNT, &u, ret))
                return false;
            j->count = (size_t)u;
            return true;
        }
        if (strcmp(key, "from_thz") == 0)
            return serve_opt_number(r, v, path, 100.0, &j->from_thz, ret);
        if (strcmp(key, "to_thz") == 0)
            return serve_opt_number(r, v, path, 100.0, &j->to_thz, ret);
        if (strcmp(key, "step_ghz") == 0)
            return serve_opt_number(r, v, path, 1e5, &j->step_ghz, ret);
        if (strcmp(key, "netd_k") == 0)
            return serve_opt_number(r, v, path, 1e6, &j->netd_k, ret);
        if (strcmp(key, "targets") == 0) {
            size_t n = json_is_array(v) ? json_array_size(v) : 0;
            if (!n || !(j->targets = calloc(n, sizeof *j->targets))) {
                *ret = serve_reply_bad_json(r, path, "expected a non-empty array of object names");
                return false;
            }
            for (size_t i = 0; i < n; i++) {
                json_t *t = json_array_get(v, i);
                if (!json_is_string(t) || !(j->targets[i] = strdup(json_string_value(t)))) {
                    *ret = serve_reply_bad_json(r, path, "expected an array of object names");
                    return false;
                }
                j->n_targets = i + 1;
            }
            return true;
        }
    }
    *ret = serve_reply_bad_json(r, path, "unknown option for %s", serve_command_names[j->command]);
    return false;
}

/* The job a request body describes; NULL after replying 400 (or 403/404 for paths). */
static serve_job *serve_parse_job(serve_request *r, json_t *body, enum MHD_Result *ret)
{
    serve_job *j = calloc(1, sizeof *j);
    if (!j) {
        *ret = serve_reply_error(r, 500, "out of memory");
        return NULL;
    }
    const char *key;
    json_t *v;
    const char *cmd = json_string_value(json_object_get(body, "command"));
    size_t c = 0;
    while (c < 4 && (!cmd || strcmp(cmd, serve_command_names[c]) != 0))
        c++;
    if (c == 4) {
        *ret = serve_reply_bad_json(r, "$.command", "expected simulate, render, batch or bands");
        goto fail;
    }
    j->command = (serve_command)c;
    if (!serve_opt_path(r, json_object_get(body, "scene"), "$.scene", true, j->scene, ret) ||
        !serve_opt_path(r, json_object_get(body, "out"), "$.out", false, j->out, ret))
        goto fail;
    json_t *opts = json_object_get(body, "options");
    if (opts && !json_is_object(opts)) {
        *ret = serve_reply_bad_json(r, "$.options", "expected an object");
        goto fail;
    }
    json_object_foreach(opts, key, v)
    {
        if (!serve_parse_option(r, j, key, v, ret))
            goto fail;
    }
    /* as the CLI refuses them: a map to save that the integrator makes none of, a render
     * from a map without one */
    char name[64];
    const char *from = NULL;
    const char *integrator = j->command == CMD_SIMULATE || j->command == CMD_RENDER
                                 ? serve_job_integrator(j, name, sizeof name, &from)
                                 : NULL;
    if (integrator && j->command == CMD_SIMULATE && j->save_photon_map &&
        !thz_integrator_needs_photons(integrator)) {
        *ret = serve_reply_bad_json(r, "$.options.save_photon_map",
                                    "the %s integrator (%s) fires no photons: no photon map to "
                                    "save (give integrator final-gather or photon-map)",
                                    integrator, from);
        goto fail;
    }
    if (integrator && j->command == CMD_RENDER && !j->photon_map[0] &&
        thz_integrator_needs_photons(integrator)) {
        *ret = serve_reply_bad_json(r, "$.options.photon_map",
                                    "the %s integrator (%s) renders from a photon map: give "
                                    "photon_map (only integrator path renders without one)",
                                    integrator, from);
        goto fail;
    }
    if (j->command == CMD_BANDS && j->count == 0) {
        *ret = serve_reply_bad_json(r, "$.options.count", "bands needs a count");
        goto fail;
    }
    return j;
fail:
    serve_job_free(j);
    return NULL;
}

enum MHD_Result serve_runs_post(serve_request *r)
{
    serve *s = r->s;
    enum MHD_Result ret = MHD_NO;
    static const char *const keys[] = {"command", "scene", "out", "options", NULL};
    json_t *body = serve_body_object(r, keys, &ret);
    if (!body)
        return ret;
    serve_job *j = serve_parse_job(r, body, &ret);
    json_decref(body);
    if (!j)
        return ret;
    pthread_mutex_lock(&s->lock);
    size_t active = 0;
    for (size_t i = 0; i < s->n_jobs; i++)
        active += !serve_job_finished(s->jobs[i]);
    if (active >= SERVE_MAX_JOBS || s->stopping) {
        pthread_mutex_unlock(&s->lock);
        serve_job_free(j);
        return serve_reply_error(r, 409, "%d jobs are queued already", SERVE_MAX_JOBS);
    }
    /* the oldest finished jobs go beyond SERVE_KEPT_FINISHED: every job stayed until the
     * server stopped (3000 jobs: 58 MB, and GET /api/runs 0.7 MB a second while a run
     * went on). Event streams and lookups find jobs by id under the lock: one of a job
     * that went ends. */
    size_t finished = 0;
    for (size_t i = 0; i < s->n_jobs; i++)
        finished += serve_job_finished(s->jobs[i]);
    size_t kept = 0;
    for (size_t i = 0; i < s->n_jobs; i++) {
        if (finished > SERVE_KEPT_FINISHED && serve_job_finished(s->jobs[i])) {
            serve_job_free(s->jobs[i]);
            finished--;
        } else {
            s->jobs[kept++] = s->jobs[i];
        }
    }
    s->n_jobs = kept;
    if (s->n_jobs == s->cap_jobs) {
        size_t cap = s->cap_jobs ? 2 * s->cap_jobs : 16;
        serve_job **grown = realloc(s->jobs, cap * sizeof *grown);
        if (!grown) {
            pthread_mutex_unlock(&s->lock);
            serve_job_free(j);
            return serve_reply_error(r, 500, "out of memory");
        }
        s->jobs = grown;
        s->cap_jobs = cap;
    }
    j->id = s->next_id++;
    j->state = JOB_QUEUED;
    j->version = 1;
    snprintf(j->message, sizeof j->message, "queued");
    s->jobs[s->n_jobs++] = j;
    pthread_cond_broadcast(&s->changed);
    int id = j->id;
    pthread_mutex_unlock(&s->lock);
    return serve_reply_json(r, 202, json_pack("{s:i}", "id", id));
}
