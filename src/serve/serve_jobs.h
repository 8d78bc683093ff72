/* A job of `thzmap serve` (serve_runs.c runs them, serve_runs_post.c makes them from
 * POST /api/runs). Every field after `targets` is guarded by the server's lock. */
#ifndef THZ_SERVE_SERVE_JOBS_H
#define THZ_SERVE_SERVE_JOBS_H

#include "serve_internal.h"

typedef enum serve_job_state {
    JOB_QUEUED,
    JOB_RUNNING,
    JOB_DONE,
    JOB_FAILED,
    JOB_CANCELLED
} serve_job_state;
extern const char *const serve_state_names[]; /* by serve_job_state */

typedef enum serve_command { CMD_SIMULATE, CMD_RENDER, CMD_BATCH, CMD_BANDS } serve_command;
extern const char *const serve_command_names[]; /* by serve_command */

struct serve_job {
    int id;
    serve_command command;
    char scene[PATH_MAX]; /* relative to the root (the working directory) */
    char out[PATH_MAX];
    char photon_map[PATH_MAX]; /* render */
    char sensor[256];          /* render; "" all */
    char integrator[32];       /* "" the scene's */
    uint64_t photons, seed;
    bool has_seed, save_photon_map, no_movies;
    int threads;
    double target_noise_k, max_seconds;
    /* bands */
    size_t count;
    double from_thz, to_thz, step_ghz, netd_k;
    char **targets;
    size_t n_targets;

    serve_job_state state;
    double progress; /* 0..1 */
    char message[256];
    char error[1024];
    double t_start, t_end;
    bool cancel;
    unsigned version; /* bumped on every change (event streams wait for it) */
    bool photons_seen;
    /* the warnings `thzmap simulate|render|batch|bands` would print: the scene's, an
     * option not used, the run's (JSON strings; at most SERVE_JOB_WARNINGS kept, the
     * others counted); NULL until the first */
    json_t *warnings;
    size_t warnings_dropped;
};

#define SERVE_JOB_WARNINGS 100

bool serve_job_finished(const serve_job *j);
void serve_job_free(serve_job *j);
/* POST /api/runs: queues the job the body describes. */
enum MHD_Result serve_runs_post(serve_request *r);

#endif
