/* Band selection's progress: bands_progress.h. */
#include "analysis/bands_progress.h"

#include <string.h>

#include "api/api.h"

static int bands_progress_report(void *user, const thz_progress *pr)
{
    bands_progress *b = user;
    if (strcmp(pr->stage, "render") != 0)
        return b->fn(b->user, pr);
    /* a render's channels report from 0 again: the next render */
    if (b->started && (pr->channel < b->last_channel ||
                       (pr->channel == b->last_channel && pr->done < b->last_done)))
        b->render++;
    b->started = true;
    b->last_channel = pr->channel;
    b->last_done = pr->done;
    if (b->renders && b->render >= b->renders)
        b->renders = b->render + 1;
    thz_progress out = {.stage = "bands",
                        .channel = b->render,
                        .n_channels = b->renders,
                        .done = pr->channel + (pr->total && pr->done >= pr->total ? 1 : 0),
                        .total = pr->n_channels};
    return b->fn(b->user, &out);
}

void bands_progress_begin(bands_progress *b, thz_context *ctx, size_t renders)
{
    memset(b, 0, sizeof *b);
    b->renders = renders;
    if (!ctx || !ctx->progress)
        return;
    b->ctx = ctx;
    b->fn = ctx->progress;
    b->user = ctx->progress_user;
    ctx->progress = bands_progress_report;
    ctx->progress_user = b;
}

void bands_progress_renders(bands_progress *b, size_t renders)
{
    b->renders = renders > b->render ? renders : b->render + 1;
}

void bands_progress_end(bands_progress *b)
{
    if (!b->ctx)
        return;
    b->ctx->progress = b->fn;
    b->ctx->progress_user = b->user;
    b->ctx = NULL;
}
