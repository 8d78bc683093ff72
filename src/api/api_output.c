/* Writing results: an atomic output directory (io/output.h's staging) that runs and
 * images are added to, and the one-call writers built on it. */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api/api.h"
#include "core/alloc.h"
#include "core/cancel.h"
#include "core/path.h"
#include "io/output.h"

struct thz_output {
    output_stage *stage;
    bool committed; /* the staging directory is gone: nothing more can be added */
    /* a run's or image's files failed part way (a full disk): those written stay in the
     * staging directory, so the output neither takes more nor commits */
    const char *failed;
};

/* THZ_ERR_INPUT when output is NULL, already committed or failed; `what` names the
 * call. */
static thz_status api_output_check(const thz_output *output, const char *what, thz_error *err)
{
    if (!output)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: no output", what);
    if (output->committed)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: the output is already committed (open another to write more)",
                             what);
    if (output->failed)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: an earlier %s failed and left its files partial: this output "
                             "commits nothing (destroy it, which removes them, and open another)",
                             what, output->failed);
    return THZ_OK;
}

thz_status thz_output_open(const char *outdir, thz_output **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_output_open: no place for the output");
    *out = NULL;
    if (!outdir || !outdir[0])
        return thz_error_set(err, THZ_ERR_INPUT, "no output directory given");
    thz_output *o = thz_calloc(1, sizeof *o);
    if (!o)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_status st = output_stage_create(outdir, &o->stage, err);
    if (st != THZ_OK) {
        free(o);
        return st;
    }
    *out = o;
    return THZ_OK;
}

void thz_output_destroy(thz_output *output)
{
    if (!output)
        return;
    output_stage_destroy(output->stage); /* removes what was not committed */
    free(output);
}

thz_status thz_output_commit(thz_output *output, thz_error *err)
{
    thz_status st = api_output_check(output, "thz_output_commit", err);
    if (st != THZ_OK)
        return st;
    st = output_stage_commit(output->stage, err);
    output->committed = st == THZ_OK;
    return st;
}

thz_status thz_output_add_run(thz_context *ctx, thz_output *output, thz_run *run,
                              const thz_write_options *opt, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (output && !run)
        return api_done(ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_output_add_run: no run"), err);
    thz_status st = api_output_check(output, "thz_output_add_run", err);
    if (st != THZ_OK)
        return api_done(ctx, st, err);
    run_write_options wo = {0};
    if (opt) {
        wo.photon_map = opt->photon_map != 0;
        wo.ply_max_points = opt->ply_max_points;
    }
    if (ctx) {
        wo.progress = ctx->progress;
        wo.progress_user = ctx->progress_user;
    }
    if (wo.photon_map && !run->has_photons)
        return api_done(ctx,
                        thz_error_set(err, THZ_ERR_INPUT,
                                      "the run kept no photon maps to write (keep_photons, and "
                                      "an integrator that fires photons)"),
                        err);
    /* What OUTDIR holds of the run's sensors is this run's (an earlier run's measured
     * cubes do not stay beside a sensor without noise), and a simulation's photon map:
     * an earlier one does not stay beside it (a render's stays: it may be its input). */
    for (size_t i = 0; i < run->rs.n_selected && st == THZ_OK; i++)
        st = output_stage_claim_sensor(output->stage,
                                       run->rs.scene->sensors[run->rs.selected[i]].name, err);
    if (st == THZ_OK && !strcmp(run->rs.command, "simulate"))
        st = output_stage_claim(output->stage, RUN_PHOTON_MAP_FILE, err);
    if (st == THZ_OK && !strcmp(run->rs.command, "simulate"))
        st = output_stage_claim(output->stage, RUN_PHOTON_PLY_FILE, err);
    if (st == THZ_OK) {
        st = run_write(&run->rs, output_stage_dir(output->stage), &wo, err);
        if (st != THZ_OK)
            output->failed = "thz_output_add_run";
    }
    if (st != THZ_OK)
        output_stage_error_names_outdir(output->stage, err);
    return api_done(ctx, st, err);
}

thz_status thz_output_add_image(thz_output *output, const thz_image *image, thz_error *err)
{
    if (output && !image)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_output_add_image: no image");
    thz_status st = api_output_check(output, "thz_output_add_image", err);
    if (st != THZ_OK)
        return st;
    st = output_stage_claim_sensor(output->stage, image->scene->sensors[image->sensor].name, err);
    if (st == THZ_OK) {
        st = output_write_sensor(output_stage_dir(output->stage), image->scene, image->sensor,
                                 image->img, 0, NULL, err);
        if (st != THZ_OK)
            output->failed = "thz_output_add_image";
    }
    if (st != THZ_OK)
        output_stage_error_names_outdir(output->stage, err);
    return st;
}

thz_status thz_run_write(thz_context *ctx, thz_run *run, const char *outdir,
                         const thz_write_options *opt, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    thz_output *o = NULL;
    thz_status st = thz_output_open(outdir, &o, err);
    if (st == THZ_OK)
        st = thz_output_add_run(ctx, o, run, opt, err);
    if (st == THZ_OK)
        st = thz_output_commit(o, err);
    thz_output_destroy(o);
    return api_done(ctx, st, err);
}

/* The "output" stage of an image's write, told to ctx's progress callback (done 0 or 1
 * of 1); non-zero: cancel. Also cancel_check's question while the figures are drawn. */
static int api_image_write_report(const thz_context *ctx, const thz_image *image, uint64_t done)
{
    if (!ctx || !ctx->progress)
        return 0;
    thz_progress p = {.stage = "output",
                      .n_channels = image ? image->scene->n_channels : 0,
                      .done = done,
                      .total = 1};
    return ctx->progress(ctx->progress_user, &p);
}

typedef struct api_image_asking {
    const thz_context *ctx;
    const thz_image *image;
} api_image_asking;

static int api_image_write_cancelled(void *user)
{
    const api_image_asking *a = user;
    return api_image_write_report(a->ctx, a->image, 0);
}

thz_status thz_image_write(thz_context *ctx, const thz_image *image, const char *dir,
                           thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    thz_output *o = NULL;
    thz_status st = thz_output_open(dir, &o, err);
    if (st == THZ_OK && !image)
        st = thz_error_set(err, THZ_ERR_INPUT, "thz_image_write: no image");
    /* as a run's write: the context's threads bound the figure processes, its progress
     * callback hears the stage and may cancel it (nothing is then committed) */
    api_image_asking asking = {ctx, image};
    cancel_check cancel = {api_image_write_cancelled, &asking};
    if (st == THZ_OK && api_image_write_report(ctx, image, 0))
        st = thz_error_set(err, THZ_ERR_CANCELLED, "writing the image: cancelled");
    if (st == THZ_OK)
        st = output_write_sensor(output_stage_dir(o->stage), image->scene, image->sensor,
                                 image->img, ctx ? ctx->threads : 0, &cancel, err);
    if (st != THZ_OK && o)
        output_stage_error_names_outdir(o->stage, err);
    if (st == THZ_OK && api_image_write_report(ctx, image, 1))
        st = thz_error_set(err, THZ_ERR_CANCELLED, "writing the image: cancelled");
    if (st == THZ_OK)
        st = thz_output_commit(o, err);
    thz_output_destroy(o);
    return api_done(ctx, st, err);
}

thz_status thz_output_add_file(thz_output *output, const char *name, const void *data, size_t size,
                               thz_error *err)
{
    thz_status st = api_output_check(output, "thz_output_add_file", err);
    if (st != THZ_OK)
        return st;
    if (!name || !name[0] || strchr(name, '/') || !strcmp(name, ".") || !strcmp(name, "..") ||
        (size && !data))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_output_add_file: expected a plain file name and data");
    char path[THZ_PATH_MAX];
    st = thz_path_join(path, sizeof path, output_stage_dir(output->stage), name, err);
    if (st != THZ_OK)
        return st;
    FILE *f = fopen(path, "wbx"); /* a name already in the output is not replaced */
    if (!f && errno == EEXIST)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_output_add_file: %s is in this output already (added before, "
                             "or a file of its run)",
                             name);
    if (!f) {
        thz_error_set(err, THZ_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
        output_stage_error_names_outdir(output->stage, err);
        return THZ_ERR_IO;
    }
    int why = 0; /* the first failure's errno: a full disk says so */
    errno = 0;
    if (size > 0 && fwrite(data, 1, size, f) != size) /* data may be NULL for 0 bytes */
        why = errno ? errno : EIO;
    if (fclose(f) != 0 && !why)
        why = errno ? errno : EIO;
    if (!why)
        return THZ_OK;
    unlink(path); /* a retry may add it again */
    thz_error_set(err, THZ_ERR_IO, "%s: cannot write: %s", path, strerror(why));
    output_stage_error_names_outdir(output->stage, err);
    return THZ_ERR_IO;
}
