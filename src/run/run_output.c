/* The output files of a finished run (scene-format.md "Outputs"): every rendered
 * sensor's files, the photon map when asked, and summary.json, written into a directory
 * the caller stages (io/output.h) so that OUTDIR only ever holds complete results. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/path.h"
#include "core/threads.h"
#include "io/output.h"
#include "io/photon_map_file.h"
#include "io/ply.h"
#include "photon/phase.h"
#include "run/run.h"
#include "sensor/render_tiles.h"

/* What summary.json says of the run beyond the scene. */
static run_summary run_summary_of(const run_state *rs)
{
    return (run_summary){
        .command = rs->command,
        .integrator = render_integrator_name(rs->scene->render.integrator),
        .seed = rs->seed,
        .photons_per_channel = rs->photons_per_channel,
        .threads = thz_threads_or_all(rs->opt->threads),
        /* the processes that shared the run: its photon phases and render passes */
        .mpi_ranks = rs->opt->render_team ? (int)rs->opt->render_team->members : 1,
        /* render: the statistics of the photon phase that made the map it read */
        .channel_stats =
            render_integrator_needs_photons(rs->scene->render.integrator) ? rs->stats : NULL,
        .noise = rs->noise,
        .object_noise = rs->object_noise,
        .target_source = rs->target_source,
        .passes = rs->passes,
        .seconds_render_channel = rs->seconds_channel,
        .target_noise_k = rs->target_noise_k,
        .back_face_samples = rs->back_face,
        .seconds_load = rs->opt->seconds_load,
        .seconds_accel = rs->seconds_accel,
        .seconds_photons = rs->seconds_photons,
        .seconds_render = rs->seconds_render,
        .seconds_output = rs->seconds_output,
        .n_run_warnings = rs->n_warnings,
        .run_warnings = (const char *const *)rs->warnings,
    };
}

char *run_summary_text(const run_state *rs, thz_error *err)
{
    run_summary sum = run_summary_of(rs);
    return summary_text(rs->scene, &sum, err);
}

static thz_status run_save_photon_map(const run_state *rs, const char *dir, uint64_t ply_max_points,
                                      thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status st = thz_path_join(path, sizeof path, dir, RUN_PHOTON_MAP_FILE, err);
    const photon_map *const *maps = (const photon_map *const *)rs->maps;
    if (st == THZ_OK)
        st = photon_map_file_write(path, rs->scene, maps, rs->stats, rs->opt->threads, err);
    if (st == THZ_OK)
        st = thz_path_join(path, sizeof path, dir, RUN_PHOTON_PLY_FILE, err);
    if (st != THZ_OK)
        return st;
    uint64_t cap = ply_max_points ? ply_max_points : PLY_DEFAULT_MAX_POINTS;
    return ply_write_photons(path, maps, rs->scene->n_channels, cap, err);
}

static bool run_write_report(const run_state *rs, const run_write_options *wo, uint64_t done)
{
    if (!wo->progress)
        return false;
    thz_progress p = {.stage = "output",
                      .channel = 0,
                      .n_channels = rs->scene->n_channels,
                      .done = done,
                      .total = 1};
    return wo->progress(wo->progress_user, &p) != 0;
}

/* cancel_check's question while the figures are drawn: the progress callback's. */
typedef struct run_write_asking {
    const run_state *rs;
    const run_write_options *wo;
} run_write_asking;

static int run_write_cancelled(void *user)
{
    const run_write_asking *a = user;
    return run_write_report(a->rs, a->wo, 0);
}

thz_status run_write(run_state *rs, const char *dir, const run_write_options *wo, thz_error *err)
{
    if (run_write_report(rs, wo, 0))
        return thz_error_set(err, THZ_ERR_CANCELLED, "writing the %s results: cancelled",
                             rs->command);
    double t0 = thz_now_s();
    thz_status st = THZ_OK;
    run_write_asking asking = {rs, wo};
    cancel_check cancel = {run_write_cancelled, &asking};
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++)
        st = output_write_sensor(dir, rs->scene, rs->selected[i], &rs->images[i], rs->opt->threads,
                                 &cancel, err);
    if (st == THZ_OK && wo->photon_map)
        st = run_save_photon_map(rs, dir, wo->ply_max_points, err);
    if (st != THZ_OK)
        return st;
    rs->seconds_output = thz_now_s() - t0;
    /* One estimate per sample in one pass has no spread: the stderr cubes and the noise
     * figures read 0 K, which must not pass for exact pixels. Said where the files are
     * written (thzmap bands renders its variants so, and estimates their noise itself). */
    if (!rs->told_unestimated && render_integrator_has_passes(rs->scene->render.integrator) &&
        render_estimates_per_pass(rs->scene) < 2 && !(rs->target_noise_k > 0.0)) {
        bool path = rs->scene->render.integrator == INTEGRATOR_PATH;
        const char *key = path ? "paths_per_sample" : "gather_rays";
        st = run_add_warning(rs, err,
                             "the standard errors are not estimated: %s 1 in one pass gives "
                             "one estimate per sample, whose spread is unknown, so the "
                             "radiance_stderr cubes and the noise figures read 0 K (give %s 2 "
                             "or more, or a noise target)",
                             key, key);
        if (st != THZ_OK)
            return st;
        rs->told_unestimated = true;
    }
    run_summary sum = run_summary_of(rs);
    st = summary_write(dir, rs->scene, &sum, err);
    if (st != THZ_OK)
        return st;
    if (run_write_report(rs, wo, 1))
        return thz_error_set(err, THZ_ERR_CANCELLED, "writing the %s results: cancelled",
                             rs->command);
    return THZ_OK;
}
