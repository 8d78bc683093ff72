/* MPI runs through the public API (include/thzmap/mpi.h): the context's team of ranks.
 * Without MPI support (CMake found no MPI) the functions say so and do nothing else. */
#include "api/api.h"

#ifdef THZ_HAVE_MPI
#include "accel/accel.h"
#include "batch/batch_internal.h"
#include "mpi/mpi_team.h"
#endif

int thz_mpi_supported(void)
{
#ifdef THZ_HAVE_MPI
    return 1;
#else
    return 0;
#endif
}

void thz_mpi_interrupt(void)
{
#ifdef THZ_HAVE_MPI
    mpi_team_interrupt();
#endif
}

#ifdef THZ_HAVE_MPI

thz_status thz_context_set_mpi(thz_context *ctx, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!ctx)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_context_set_mpi: no context");
    if (ctx->team)
        return THZ_OK;
    thz_status st = mpi_team_create(&ctx->team, err);
    if (st == THZ_OK && mpi_team_rank(ctx->team) != 0) {
        mpi_team_destroy(ctx->team);
        ctx->team = NULL;
        st = thz_error_set(err, THZ_ERR_INTERNAL,
                           "thz_context_set_mpi is for rank 0; the other ranks call "
                           "thz_mpi_serve");
    }
    return api_done(ctx, st, err);
}

/* Serves the lead's requests on `scene` (with settings' overrides) until it stops the
 * team or, when next_scene is not NULL, names another scene. */
static thz_status api_mpi_serve_scene(mpi_team *team, const thz_context *ctx,
                                      const thz_scene *scene, const thz_run_settings *settings,
                                      uint64_t *next_scene, thz_error *err)
{
    accel *acc = NULL;
    thz_scene eff;
    thz_status st = api_effective_scene(scene, settings, &eff, err);
    if (st == THZ_OK) /* every integrator renders tiles on every rank */
        st = accel_create(&eff, &acc, err);
    if (st == THZ_OK)
        st = mpi_team_serve(team, &eff, acc, ctx ? ctx->threads : 0, next_scene, err);
    accel_destroy(acc);
    return st;
}

/* A member's team, created collectively with the lead's; not for rank 0. */
static thz_status api_mpi_member_team(mpi_team **team, thz_error *err)
{
    thz_status st = mpi_team_create(team, err);
    if (st == THZ_OK && mpi_team_rank(*team) == 0)
        st = thz_error_set(err, THZ_ERR_INTERNAL,
                           "thz_mpi_serve is for ranks other than 0, which leads the run");
    return st;
}

thz_status thz_mpi_serve(thz_context *ctx, const thz_scene *scene, const thz_run_settings *settings,
                         thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!scene)
        return api_done(ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_mpi_serve: no scene"), err);
    mpi_team *team = NULL;
    thz_status st = api_check_threads(ctx, "thz_mpi_serve", err);
    if (st == THZ_OK)
        st = api_mpi_member_team(&team, err);
    if (st == THZ_OK)
        st = api_mpi_serve_scene(team, ctx, scene, settings, NULL, err);
    if (ctx && st == THZ_OK)
        ctx->mpi_bytes = mpi_team_bytes(team);
    if (st == THZ_OK) /* a failed rank leaves the team to MPI_Abort */
        mpi_team_destroy(team);
    return api_done(ctx, st, err);
}

/* batch_deal_serve's way to rank 0: the team's result message. */
static thz_status api_mpi_send_frame(void *user, uint64_t frame, thz_status status,
                                     const void *data, size_t size, thz_error *err)
{
    return mpi_team_send_result(user, frame, status, data, size, err);
}

thz_status thz_mpi_serve_batch(thz_context *ctx, const thz_sequence *seq, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!seq)
        return api_done(ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_mpi_serve_batch: no sequence"),
                        err);
    mpi_team *team = NULL;
    thz_status st = api_check_threads(ctx, "thz_mpi_serve_batch", err);
    if (st == THZ_OK)
        st = api_mpi_member_team(&team, err);
    uint64_t frame = MPI_TEAM_STOPPED;
    if (st == THZ_OK) { /* until the first frame the lead runs: the lead may have none */
        st = mpi_team_serve(team, NULL, NULL, ctx ? ctx->threads : 0, &frame, err);
    }
    while (st == THZ_OK && frame != MPI_TEAM_STOPPED) {
        if (frame == MPI_TEAM_DEALT) { /* whole frames: this rank's, then wait for the lead */
            size_t n = 0;
            const uint64_t *frames = mpi_team_dealt(team, &n);
            st = batch_deal_serve(ctx, seq, frames, n, mpi_team_rank(team), mpi_team_size(team),
                                  api_mpi_send_frame, team, err);
            if (st == THZ_OK)
                st = mpi_team_serve(team, NULL, NULL, ctx ? ctx->threads : 0, &frame, err);
            continue;
        }
        thz_scene *scene = NULL;
        st = thz_sequence_frame_scene(seq, (size_t)frame, &scene, err);
        if (st == THZ_OK)
            st = api_mpi_serve_scene(team, ctx, scene, NULL, &frame, err);
        thz_scene_destroy(scene);
    }
    if (ctx && st == THZ_OK)
        ctx->mpi_bytes = mpi_team_bytes(team);
    if (st == THZ_OK)
        mpi_team_destroy(team);
    return api_done(ctx, st, err);
}

size_t api_mpi_ranks(const thz_context *ctx)
{
    return ctx && ctx->team ? mpi_team_size(ctx->team) : 1;
}

thz_status api_mpi_deal(thz_context *ctx, const uint64_t *frames, size_t n, thz_error *err)
{
    if (!ctx || !ctx->team)
        return THZ_OK;
    thz_status st = mpi_team_deal(ctx->team, frames, n, err);
    ctx->mpi_alone = st == THZ_OK;
    return st;
}

void api_mpi_deal_end(thz_context *ctx)
{
    if (ctx)
        ctx->mpi_alone = false;
}

thz_status api_mpi_receive(thz_context *ctx, size_t rank, uint64_t *frame, thz_status *status,
                           void **data, size_t *size, thz_error *err)
{
    if (!ctx || !ctx->team || rank == 0 || rank >= mpi_team_size(ctx->team))
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: no rank %zu to receive from", rank);
    return mpi_team_receive_result(ctx->team, rank, frame, status, data, size, err);
}

thz_status api_mpi_next_scene(thz_context *ctx, size_t scene, thz_error *err)
{
    return ctx && ctx->team && !ctx->mpi_alone ? mpi_team_next_scene(ctx->team, scene, err)
                                               : THZ_OK;
}

uint64_t thz_context_mpi_bytes(const thz_context *ctx)
{
    if (!ctx)
        return 0;
    return ctx->team ? mpi_team_bytes(ctx->team) : ctx->mpi_bytes;
}

const struct photon_phase_team *api_mpi_phase_team(const thz_context *ctx)
{
    return ctx && ctx->team && !ctx->mpi_alone ? mpi_team_phase(ctx->team) : NULL;
}

const struct render_team *api_mpi_render_team(const thz_context *ctx)
{
    return ctx && ctx->team && !ctx->mpi_alone ? mpi_team_render(ctx->team) : NULL;
}

void api_mpi_release(thz_context *ctx)
{
    mpi_team_destroy(ctx->team);
    ctx->team = NULL;
}

#else

thz_status thz_context_set_mpi(thz_context *ctx, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    return api_done(
        ctx, thz_error_set(err, THZ_ERR_INPUT, "this thzmap was built without MPI support"), err);
}

thz_status thz_mpi_serve(thz_context *ctx, const thz_scene *scene, const thz_run_settings *settings,
                         thz_error *err)
{
    (void)scene;
    (void)settings;
    return thz_context_set_mpi(ctx, err);
}

thz_status thz_mpi_serve_batch(thz_context *ctx, const thz_sequence *seq, thz_error *err)
{
    (void)seq;
    return thz_context_set_mpi(ctx, err);
}

thz_status api_mpi_next_scene(thz_context *ctx, size_t scene, thz_error *err)
{
    (void)ctx;
    (void)scene;
    (void)err;
    return THZ_OK;
}

uint64_t thz_context_mpi_bytes(const thz_context *ctx)
{
    (void)ctx;
    return 0;
}

size_t api_mpi_ranks(const thz_context *ctx)
{
    (void)ctx;
    return 1;
}

thz_status api_mpi_deal(thz_context *ctx, const uint64_t *frames, size_t n, thz_error *err)
{
    (void)ctx;
    (void)frames;
    (void)n;
    (void)err;
    return THZ_OK;
}

void api_mpi_deal_end(thz_context *ctx)
{
    (void)ctx;
}

thz_status api_mpi_receive(thz_context *ctx, size_t rank, uint64_t *frame, thz_status *status,
                           void **data, size_t *size, thz_error *err)
{
    (void)ctx;
    (void)frame;
    (void)status;
    (void)data;
    (void)size;
    return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: no rank %zu to receive from", rank);
}

const struct photon_phase_team *api_mpi_phase_team(const thz_context *ctx)
{
    (void)ctx;
    return NULL;
}

const struct render_team *api_mpi_render_team(const thz_context *ctx)
{
    (void)ctx;
    return NULL;
}

void api_mpi_release(thz_context *ctx)
{
    (void)ctx;
}

#endif
