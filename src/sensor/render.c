/* The renderer's pixel loop (render.h): sample placement, the integrator's estimates of
 * every sample (integrator.h), their merge into the pixel statistics (render_accum.h),
 * progress and cancelling. */
#include "sensor/render.h"

#include <math.h>
#include <stdatomic.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/threads.h"
#include "sensor/camera.h"
#include "sensor/integrator.h"
#include "sensor/render_tiles.h"

static int render_threads(const render_options *opt)
{
    int n = thz_threads_or_all(opt ? opt->threads : 0);
    return n > 0 ? n : 1;
}

/* Calls the progress callback (from the calling thread); true if it asks to stop. */
static bool render_report(const render_options *opt, const thz_scene *scene, size_t channel,
                          uint64_t done, uint64_t total)
{
    if (!opt || !opt->progress)
        return false;
    thz_progress p = {.stage = "render",
                      .channel = channel,
                      .n_channels = scene->n_channels,
                      .done = done,
                      .total = total};
    return opt->progress(opt->progress_user, &p) != 0;
}

bool render_poll_stop(render_poll *poll)
{
    if (atomic_load_explicit(&poll->stop, memory_order_relaxed))
        return true;
    if (omp_get_thread_num() != 0 || !poll->opt || !poll->opt->progress ||
        (poll->calls++ & 15) != 0) /* the clock costs as much as a cheap pixel */
        return false;
    double now = thz_now_s();
    if (now < poll->next_s)
        return false;
    poll->next_s = now + RENDER_POLL_S;
    uint64_t done = poll->done;
    if (poll->columns)
        done += atomic_load_explicit(&poll->pixels, memory_order_relaxed) / poll->columns;
    if (!render_report(poll->opt, poll->scene, poll->channel, done, poll->total))
        return false;
    atomic_store_explicit(&poll->stop, 1, memory_order_relaxed);
    return true;
}

void render_poll_pixel_done(render_poll *poll)
{
    atomic_fetch_add_explicit(&poll->pixels, 1, memory_order_relaxed);
}

/* The random-stream index of estimate 0 of sample `sample` (of `samples` per pass) of
 * sensor `sensor` in pass `pass`, with J estimates per sample: the fold of the four
 * indices (unique below 2^64 estimates in all). */
static uint64_t render_rng_index(const thz_scene *scene, size_t sensor, uint32_t pass,
                                 uint64_t samples, uint64_t sample, uint32_t j_count)
{
    uint64_t unit = (uint64_t)pass * scene->n_sensors + sensor;
    return (unit * samples + sample) * j_count;
}

thz_status render_context_pass(const render_context *ctx, size_t sensor, uint32_t pass,
                               render_accum *acc, const render_options *opt, render_stats *stats,
                               thz_error *err)
{
    double t0 = thz_now_s();
    if (stats)
        memset(stats, 0, sizeof *stats);
    const thz_scene *scene = ctx->scene;
    size_t channel = ctx->channel_index;
    if (sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: sensor %zu out of range", sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (acc->pixels != (size_t)sn->columns * sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: statistics do not match sensor '%s'",
                             sn->name);
    const render_integrator *integ = ctx->integrator;
    if (integ->purpose == 0 && pass > 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "render: integrator '%s' is deterministic given its photon map; "
                             "more passes cannot lower its noise (more photons do)",
                             render_integrator_name(integ->id));
    if (pass != acc->passes)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: pass %u out of order (expected %u)",
                             pass, acc->passes);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    uint32_t n_est = integ->purpose ? render_estimates_per_pass(scene) : 1;
    int threads = render_threads(opt);
    /* final-gather with a batched map: the map's own noise per pixel (render_accum) */
    bool batched = scene->render.integrator == INTEGRATOR_FINAL_GATHER &&
                   photon_map_batches(ctx->map) == PHOTON_MAP_BATCHES;
    if (batched && pass == 0) {
        st = render_accum_want_batches(acc, err);
        if (st != THZ_OK)
            return st;
    }
    batched = batched && acc->batch;
    /* per thread: the current pixel's n_est estimates, then its batch sums and Poisson
     * variance; each thread's share on cache lines of its own (8 doubles), since they
     * are written for every sample */
    size_t per_thread = (n_est + PHOTON_MAP_BATCHES + 1 + 7) / 8 * 8;
    double *scratch_mem = thz_malloc_array((size_t)threads * per_thread + 7, sizeof *scratch_mem);
    double *scratch = scratch_mem ? scratch_mem + (8 - (uintptr_t)scratch_mem / 8 % 8) % 8 : NULL;
    /* per thread: the strata sets of its current pixel's estimates (render_stratum) */
    render_strata *strata = thz_malloc_array((size_t)threads * n_est, sizeof *strata);
    if (!scratch || !strata) {
        free(scratch_mem);
        free(strata);
        return thz_error_set(err, THZ_ERR_NOMEM,
                             "render: out of memory for %u estimates x %d "
                             "threads",
                             n_est, threads);
    }
    for (size_t k = 0; k < (size_t)threads * n_est; k++)
        strata[k].key = RENDER_STRATA_NONE;

    uint32_t n = cam.oversampling, cols = cam.columns, rows = cam.rows;
    double n2 = (double)n * (double)n;
    uint64_t samples_per_pass = (uint64_t)cols * rows * n * n;
    size_t members = opt ? opt->members : 0, member = opt ? opt->member : 0;
    uint64_t n_samples = 0, n_escaped = 0, n_back = 0, n_widened = 0, n_starved = 0,
             n_truncated = 0, n_paths = 0;
    uint64_t back_lo = UINT64_MAX, back_hi = 0; /* the objects seen from the back */

    if (render_report(opt, scene, channel, 0, rows)) {
        st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
        goto cleanup;
    }
    /* One parallel region for the whole frame, its progress and cancelling polled inside
     * (render_poll): with a region per block of rows, the thread that finished its last
     * chunk first waited at every block's end (path, 160 paths a sample: a region per row;
     * 3 % less time with one region, within the VM's noise). */
    render_poll poll = {.opt = opt,
                        .scene = scene,
                        .channel = channel,
                        .total = rows,
                        .columns = cols,
                        .next_s = thz_now_s() + RENDER_POLL_S};
    const int64_t n_px = (int64_t)rows * cols;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) \
    reduction(+ : n_samples, n_escaped, n_back, n_widened, n_starved, n_truncated, n_paths) \
    reduction(min : back_lo) reduction(max : back_hi)
    for (int64_t px = 0; px < n_px; px++) {
        uint32_t row = (uint32_t)(px / cols), col = (uint32_t)(px % cols);
        if (render_tile_owner(col, row, members) != member) {
            render_poll_pixel_done(&poll); /* another member's */
            continue;
        }
        if (render_poll_stop(&poll))
            continue;
        double *est = &scratch[(size_t)omp_get_thread_num() * per_thread];
        for (size_t j = 0; j < per_thread; j++)
            est[j] = 0.0;
        double *pixel_batch = batched ? est + n_est : NULL;
        double *pixel_disk_var = batched ? est + n_est + PHOTON_MAP_BATCHES : NULL;
        double omega_sr = camera_pixel_solid_angle(&cam, col, row);
        double sample_sr = omega_sr / n2;
        /* Poisson variance of the pixel's mean: the samples' own footprints are
         * disjoint, so their variances add; a footprint widened to the k-th nearest
         * photon overlaps its neighbours' and shares their photons, so for a pixel
         * with one, the bound of perfect correlation (the sum of standard errors,
         * squared) instead: never less than the truth (tests/cli/
         * test_deviation_maps.sh measured the sum of variances 2x short in sd). Within
         * a sample, the estimates on a straight shell and behind it share the photons
         * that crossed it: their covariance takes the same bound (test_integrators.c,
         * the tight cover: 1.32x short with the variances summed). */
        double var_sum = 0.0, sd_sum = 0.0;
        bool pixel_widened = false, pixel_starved = false;
        for (uint32_t j = 0; j < n; j++)
            for (uint32_t i = 0; i < n; i++) {
                render_sample s = {.variance = 0.0};
                vec3 dir = camera_sample_dir(&cam, col, row, i, j);
                uint64_t sample = (uint64_t)px * n * n + (uint64_t)j * n + i;
                render_target t = {
                    .est = est,
                    .n_est = n_est,
                    .batch = pixel_batch,
                    .disk_var = pixel_disk_var,
                    .weight = 1.0 / n2,
                    .rng_index =
                        render_rng_index(scene, sensor, pass, samples_per_pass, sample, n_est),
                    .stratum = j * n + i,
                    .n_strata = n * n,
                    .strata = &strata[(size_t)omp_get_thread_num() * n_est],
                };
                integ->sample(ctx, cam.position_m, dir, sample_sr, &t, &s);
                double var = s.variance + s.covariance_bound;
                var_sum += var;
                sd_sum += sqrt(var);
                pixel_widened = pixel_widened || s.widened;
                pixel_starved = pixel_starved || s.starved;
                n_samples++;
                n_escaped += s.escaped;
                n_back += s.back_face;
                if (s.back_face) {
                    back_lo = s.back_object < back_lo ? s.back_object : back_lo;
                    back_hi = s.back_object > back_hi ? s.back_object : back_hi;
                }
                n_widened += s.widened;
                n_starved += s.starved;
                n_truncated += s.truncated;
                n_paths += s.paths;
            }
        size_t p = (size_t)px;
        /* a sample short of photons took its reflected radiance as 0 and added no
         * variance: the pixel's error is unknown, not its samples' variance (NaN) */
        if (!integ->purpose)
            render_accum_set_poisson_pixel(
                acc, p, est[0],
                pixel_starved ? NAN : (pixel_widened ? sd_sum * sd_sum : var_sum) / (n2 * n2));
        else
            render_accum_add_pixel(acc, p, est, n_est, pixel_batch, pixel_disk_var);
        render_poll_pixel_done(&poll);
    }
    if (atomic_load(&poll.stop) || render_report(opt, scene, channel, rows, rows)) {
        st = thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
        goto cleanup;
    }
    render_accum_end_pass(acc, n_est, integ->purpose == 0);

cleanup:
    if (stats) {
        stats->samples = n_samples;
        stats->escaped_samples = n_escaped;
        stats->back_face_samples = n_back;
        stats->back_face_object_lo = n_back ? back_lo : 0;
        stats->back_face_object_hi = n_back ? back_hi : 0;
        stats->widened_gathers = n_widened;
        stats->starved_gathers = n_starved;
        stats->truncated_paths = n_truncated;
        stats->paths = n_paths;
        stats->seconds = thz_now_s() - t0;
    }
    free(scratch_mem);
    free(strata);
    return st;
}

thz_status render_sensor_channel_pass(const thz_scene *scene, const accel *a, const photon_map *map,
                                      size_t channel, size_t sensor, uint32_t pass,
                                      render_accum *acc, const render_options *opt,
                                      render_stats *stats, thz_error *err)
{
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (channel >= scene->n_channels || sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "render: channel %zu or sensor %zu out of range", channel, sensor);
    render_context *ctx;
    thz_status st = render_context_create(scene, a, map, channel, opt, &ctx, err);
    if (st != THZ_OK)
        return st;
    st = render_context_pass(ctx, sensor, pass, acc, opt, stats, err);
    render_context_destroy(ctx);
    return st;
}

thz_status render_sensor_channel(const thz_scene *scene, const accel *a, const photon_map *map,
                                 size_t channel, size_t sensor, sensor_images *images,
                                 const render_options *opt, render_stats *stats, thz_error *err)
{
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (channel >= scene->n_channels || sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "render: channel %zu or sensor %zu out of range", channel, sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows ||
        images->n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    render_accum acc;
    thz_status st = render_accum_init(&acc, (size_t)sn->columns * sn->rows, err);
    if (st != THZ_OK)
        return st;
    st = render_sensor_channel_pass(scene, a, map, channel, sensor, 0, &acc, opt, stats, err);
    if (st == THZ_OK)
        st = render_accum_write(scene, channel, sensor, &acc, images, err);
    render_accum_fini(&acc);
    return st;
}
