/* Batch frames computed apart from their writing: the step that turns a frame into its
 * run (as `thzmap simulate`, or as `thzmap render` from its base frame's photons), the
 * rule that deals photon groups to MPI ranks, a member rank's side (compute its frames,
 * send each run to rank 0 as run_pack's bytes) and rank 0's receiving side. batch_run.c
 * writes every frame, its own and the received ones, in frame order (docs/mpi.md "Batch
 * frames").
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "run/run_pack.h"

/* What precedes run_pack's bytes in a frame sent to rank 0. */
typedef struct deal_header {
    uint64_t reused; /* rendered from its base frame's photons */
    uint64_t fired;  /* fired photons (its own or, resuming, its base's again) */
    double seconds;  /* wall time of computing the frame (its scene and its run, not the
                        packing) on the rank that computed it, s */
} deal_header;

static double deal_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Whether frame f's scene uses photons, so that the frames after it can reuse them. */
static int deal_uses_photons(const thz_scene *scene)
{
    thz_scene_info info;
    return thz_scene_get_info(scene, &info) == THZ_OK &&
           thz_integrator_needs_photons(info.integrator);
}

thz_status batch_frame_load(const thz_sequence *seq, const size_t *base, size_t f, batch_frame *fr,
                            thz_error *err)
{
    memset(fr, 0, sizeof *fr);
    thz_status st = thz_sequence_frame_scene(seq, f, &fr->scene, err);
    int photons = st == THZ_OK && deal_uses_photons(fr->scene);
    fr->reused = photons && base[f] != f;
    fr->keep = photons && f + 1 < seq->n_frames && base[f + 1] == f;
    fr->fired = photons && !fr->reused; /* path fires none */
    return st;
}

thz_status batch_frame_compute(thz_context *ctx, const thz_sequence *seq, const size_t *base,
                               batch_photon_cache *cache, size_t f, batch_frame *fr, thz_error *err)
{
    if (fr->reused)
        return batch_render_reused(ctx, seq, cache, base[f], fr->scene, &fr->run, &fr->reused,
                                   &fr->fired, err);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.keep_photons = fr->keep;
    return thz_simulate(ctx, fr->scene, &settings, &fr->run, err);
}

void batch_frame_fini(batch_frame *fr, batch_photon_cache *cache, size_t f, int ok)
{
    if (ok && fr->keep)
        batch_photon_cache_keep(cache, f, &fr->scene, &fr->run);
    thz_run_destroy(fr->run);
    thz_scene_destroy(fr->scene);
    memset(fr, 0, sizeof *fr);
}

size_t batch_deal_owners(const size_t *base, const uint64_t *frames, size_t n, size_t members,
                         size_t *owner)
{
    size_t groups = 0;
    for (size_t i = 0; i < n; i++) {
        if (i == 0 || base[frames[i]] != base[frames[i - 1]])
            groups++;
        if (owner)
            owner[i] = members ? (groups - 1) % members : 0;
    }
    return groups;
}

/* Frame f computed: its run's bytes after a deal_header, into *data (malloc'd). */
static thz_status deal_pack(const batch_frame *fr, double seconds, uint8_t **data, size_t *size,
                            thz_error *err)
{
    uint8_t *bytes = NULL;
    size_t n = 0;
    thz_status st = run_pack(&fr->run->rs, &bytes, &n, err);
    if (st != THZ_OK)
        return st;
    deal_header h = {
        .reused = (uint64_t)fr->reused, .fired = (uint64_t)fr->fired, .seconds = seconds};
    *data = n <= SIZE_MAX - sizeof h ? malloc(sizeof h + n) : NULL;
    if (!*data) {
        free(bytes);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a frame of %zu bytes", n);
    }
    memcpy(*data, &h, sizeof h);
    memcpy(*data + sizeof h, bytes, n);
    *size = sizeof h + n;
    free(bytes);
    return THZ_OK;
}

thz_status batch_deal_serve(thz_context *ctx, const thz_sequence *seq, const uint64_t *frames,
                            size_t n, size_t member, size_t members, batch_send_fn send_frame,
                            void *send_user, thz_error *err)
{
    size_t *base = thz_calloc(seq->n_frames ? seq->n_frames : 1, sizeof *base);
    size_t *owner = thz_calloc(n ? n : 1, sizeof *owner);
    thz_status st = base && owner ? batch_photon_bases(seq, base, err)
                                  : thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; st == THZ_OK && i < n; i++)
        if (frames[i] >= seq->n_frames || (i > 0 && frames[i] <= frames[i - 1]))
            st = thz_error_set(err, THZ_ERR_INTERNAL, "MPI: rank 0 dealt frame %llu of %zu",
                               (unsigned long long)frames[i], seq->n_frames);
    if (st == THZ_OK)
        batch_deal_owners(base, frames, n, members, owner);
    batch_photon_cache cache = {.base = SIZE_MAX};
    for (size_t i = 0; st == THZ_OK && i < n; i++) {
        if (owner[i] != member)
            continue;
        size_t f = (size_t)frames[i];
        double t0 = deal_now_s();
        batch_frame fr;
        thz_error ferr;
        thz_error_clear(&ferr);
        uint8_t *data = NULL;
        size_t size = 0;
        thz_status fst = batch_frame_load(seq, base, f, &fr, &ferr);
        if (fst == THZ_OK)
            fst = batch_frame_compute(ctx, seq, base, &cache, f, &fr, &ferr);
        double seconds = deal_now_s() - t0;
        if (fst == THZ_OK)
            fst = deal_pack(&fr, seconds, &data, &size, &ferr);
        if (fst == THZ_OK)
            st = send_frame(send_user, f, THZ_OK, data, size, err);
        else /* rank 0 reports it and ends the job; this rank computes no more */
            st = send_frame(send_user, f, fst, ferr.message, strlen(ferr.message), err);
        free(data);
        batch_frame_fini(&fr, &cache, f, fst == THZ_OK);
        if (fst != THZ_OK)
            break;
    }
    batch_photon_cache_clear(&cache);
    free(owner);
    free(base);
    return st;
}

thz_status batch_deal_receive(thz_context *ctx, const thz_sequence *seq, size_t f, size_t rank,
                              batch_frame *fr, double *seconds, bool *theirs, thz_error *err)
{
    memset(fr, 0, sizeof *fr);
    *theirs = false;
    uint64_t item = 0;
    thz_status status = THZ_OK;
    void *data = NULL;
    size_t size = 0;
    thz_status st = api_mpi_receive(ctx, rank, &item, &status, &data, &size, err);
    if (st == THZ_OK && item != f)
        st = thz_error_set(err, THZ_ERR_INTERNAL, "MPI: rank %zu sent frame %llu, not %zu", rank,
                           (unsigned long long)item, f);
    else if (st == THZ_OK && status != THZ_OK) {
        st = thz_error_set(err, status, "%s", (const char *)data);
        *theirs = true;
    }
    deal_header h;
    if (st == THZ_OK && size < sizeof h)
        st = thz_error_set(err, THZ_ERR_INTERNAL, "MPI: rank %zu sent %zu bytes", rank, size);
    if (st == THZ_OK)
        st = thz_sequence_frame_scene(seq, f, &fr->scene, err);
    if (st == THZ_OK) {
        memcpy(&h, data, sizeof h);
        fr->reused = h.reused != 0;
        fr->fired = h.fired != 0;
        *seconds = h.seconds;
        st = api_run_unpack(fr->scene, (const uint8_t *)data + sizeof h, size - sizeof h, &fr->run,
                            err);
    }
    /* the scene's and the run's warnings went to no one where it ran: said here, in the
     * order one process says them */
    for (size_t i = 0;
         st == THZ_OK && ctx && ctx->warning && i < thz_scene_warning_count(fr->scene); i++)
        ctx->warning(ctx->warning_user, thz_scene_warning(fr->scene, i));
    for (size_t i = 0; st == THZ_OK && ctx && ctx->warning && i < fr->run->rs.n_warnings; i++)
        ctx->warning(ctx->warning_user, fr->run->rs.warnings[i]);
    free(data);
    return st;
}
