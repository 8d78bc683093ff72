/* The context: threads, callbacks, the last error; and the helpers every API file
 * shares (settings into run options, overrides into a scene copy). */
#include <inttypes.h>
#include <stdint.h>
#include <stdlib.h>

#include "api/api.h"
#include "core/alloc.h"
#include "core/threads.h"
#include "sensor/render.h"

thz_context *thz_context_create(void)
{
    return thz_calloc(1, sizeof(thz_context));
}

void thz_context_destroy(thz_context *ctx)
{
    if (ctx)
        api_mpi_release(ctx);
    free(ctx);
}

void thz_context_set_threads(thz_context *ctx, int threads)
{
    if (ctx)
        ctx->threads = threads > 0 ? threads : 0;
}

thz_status api_check_threads(const thz_context *ctx, const char *what, thz_error *err)
{
    if (ctx && ctx->threads > THZ_MAX_THREADS)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: threads %d: expected 0 (all cores) to %d "
                             "(thz_context_set_threads)",
                             what, ctx->threads, THZ_MAX_THREADS);
    return THZ_OK;
}

int thz_threads_prepare(int threads)
{
    int t = threads < 0 ? 0 : threads > THZ_MAX_THREADS ? THZ_MAX_THREADS : threads;
    if (thz_address_space_limit_bytes() == 0)
        return threads;
    int want = thz_threads_or_all(t), n = thz_threads_start(t);
    return n < want ? n : threads;
}

uint64_t thz_omp_stack_bytes(void)
{
    return thz_thread_omp_stack_bytes();
}

int thz_context_threads(const thz_context *ctx)
{
    return ctx ? ctx->threads : 0;
}

void thz_context_set_progress(thz_context *ctx, thz_progress_fn fn, void *user)
{
    if (ctx) {
        ctx->progress = fn;
        ctx->progress_user = user;
    }
}

void thz_context_set_warning(thz_context *ctx, thz_warning_fn fn, void *user)
{
    if (ctx) {
        ctx->warning = fn;
        ctx->warning_user = user;
    }
}

thz_status thz_context_last_status(const thz_context *ctx)
{
    return ctx ? ctx->last.status : THZ_OK;
}

const char *thz_context_last_message(const thz_context *ctx)
{
    return ctx ? ctx->last.message : "";
}

thz_status api_done(thz_context *ctx, thz_status st, const thz_error *err)
{
    if (ctx && st != THZ_OK) {
        ctx->last = *err;
        ctx->last.status = st;
    }
    return st;
}

void thz_run_settings_init(thz_run_settings *settings)
{
    if (settings)
        *settings = (thz_run_settings){0};
}

thz_status api_effective_scene(const thz_scene *scene, const thz_run_settings *settings,
                               thz_scene *out, thz_error *err)
{
    *out = *scene;
    if (!settings)
        return THZ_OK;
    if (settings->has_seed && settings->seed > (uint64_t)INT64_MAX)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "seed: expected 0 to 9223372036854775807 (2^63 - 1, as photons.seed), "
                             "got %" PRIu64,
                             settings->seed);
    run_overrides ov = {.photons = settings->photons_per_channel,
                        .has_seed = settings->has_seed != 0,
                        .seed = settings->seed};
    if (settings->integrator && settings->integrator[0]) {
        if (!render_integrator_parse(settings->integrator, &ov.integrator))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "unknown integrator '%s' (expected photon-map, final-gather or "
                                 "path)",
                                 settings->integrator);
        ov.has_integrator = true;
    }
    run_apply_overrides(out, &ov);
    return THZ_OK;
}

/* run_plan to the caller's thz_plan_fn (plan_user: the settings, alive during the run). */
static void api_plan(void *user, const run_plan *plan)
{
    const thz_run_settings *settings = user;
    thz_run_plan p = {.seconds_photons = plan->seconds_photons,
                      .seconds_render = plan->seconds_render,
                      .passes = plan->passes,
                      .memory_bytes = plan->memory_bytes,
                      .available_bytes = plan->available_bytes,
                      .target_noise_k = plan->target_noise_k,
                      .target_source = plan->target_source,
                      .memory_stop = plan->memory_stop};
    settings->plan(settings->plan_user, &p);
}

void api_run_options(const thz_context *ctx, const thz_run_settings *settings, run_options *opt)
{
    *opt = (run_options){0};
    if (ctx) {
        opt->threads = ctx->threads;
        opt->progress = ctx->progress;
        opt->progress_user = ctx->progress_user;
        opt->warning = ctx->warning;
        opt->warning_user = ctx->warning_user;
        opt->team = api_mpi_phase_team(ctx);
        opt->render_team = api_mpi_render_team(ctx);
    }
    if (settings) {
        opt->keep_photon_maps = settings->keep_photons != 0;
        opt->target_noise_k = settings->target_noise_k;
        opt->max_seconds = settings->max_seconds;
        opt->seconds_load = settings->seconds_load;
        if (settings->plan) {
            opt->plan = api_plan;
            opt->plan_user = (void *)(uintptr_t)settings; /* read only */
        }
    }
}
