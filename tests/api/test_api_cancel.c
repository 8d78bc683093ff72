/* Cancelling from the progress callback: a run stopped in its photon phase, in its
 * rendering, or while it is written returns THZ_ERR_CANCELLED, hands nothing back, and
 * leaves no output directory contents (the output directory it created is removed); a
 * cancelled write says so. argv: the thzmap binary (unused), the repository. */
#include <dirent.h>
#include <sys/stat.h>

#include "api_test.h"

typedef struct cancel_at {
    const char *stage; /* cancel at the first report of this stage */
    int reports;       /* reports seen before cancelling */
    int cancelled;
} cancel_at;

static int cancel_progress(void *user, const thz_progress *p)
{
    cancel_at *c = user;
    c->reports++;
    if (strcmp(p->stage, c->stage) == 0) {
        c->cancelled = 1;
        return 1;
    }
    return 0;
}

/* Which stages a run reported, in what order. */
typedef struct stage_log {
    int prepare_done;          /* "prepare" reports with done == total */
    int prepare_after_photons; /* "prepare" reports after a "photons" one */
    int photons_seen;
    uint64_t prepare_total;
} stage_log;

static int log_progress(void *user, const thz_progress *p)
{
    stage_log *l = user;
    if (strcmp(p->stage, "photons") == 0)
        l->photons_seen = 1;
    if (strcmp(p->stage, "prepare") == 0) {
        l->prepare_after_photons += l->photons_seen;
        l->prepare_done += p->done == p->total;
        l->prepare_total = p->total;
    }
    return 0;
}

/* 1 when path does not exist or is an empty directory. */
static int empty_or_missing(const char *path)
{
    DIR *d = opendir(path);
    if (!d)
        return 1;
    int entries = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            entries++;
    closedir(d);
    return entries == 0;
}

int main(int argc, char **argv)
{
    (void)argc;
    char dir[4096], out[4200];
    test_temp_dir(dir, sizeof dir);
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, dir, "cancel.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();

    /* in the photon phase and in rendering, with the output opened first (as the CLI) */
    const char *stages[] = {"photons", "render"};
    for (size_t k = 0; k < 2; k++) {
        cancel_at c = {.stage = stages[k]};
        thz_context_set_progress(ctx, cancel_progress, &c);
        snprintf(out, sizeof out, "%s/out-%s", dir, stages[k]);
        thz_output *output = NULL;
        REQUIRE_OK(thz_output_open(out, &output, &err), &err);
        thz_run *run = (thz_run *)&c; /* must be reset to NULL */
        thz_status st = thz_simulate(ctx, scene, NULL, &run, &err);
        CHECK(st == THZ_ERR_CANCELLED, "%s: %s (%s)", stages[k], thz_status_name(st), err.message);
        CHECK(c.cancelled, "%s: the callback never saw the stage", stages[k]);
        CHECK(run == NULL, "%s: a run came back", stages[k]);
        CHECK(thz_context_last_status(ctx) == THZ_ERR_CANCELLED, "last status %s",
              thz_status_name(thz_context_last_status(ctx)));
        thz_output_destroy(output);
        CHECK(empty_or_missing(out), "%s holds files after cancelling", out);
    }

    /* final-gather's deviation map: the one-sided solids' back-side sources are set up once
     * for the run (stage "prepare", before the first channel's photons and the estimates'
     * pilots), not once per channel; a stop there cancels the run */
    thz_run_settings gather = {.integrator = "final-gather", .photons_per_channel = 20000};
    stage_log log = {0};
    thz_context_set_progress(ctx, log_progress, &log);
    thz_run *gathered = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &gather, &gathered, &err), &err);
    CHECK(log.prepare_done == 1, "the back-side sources were set up %d times", log.prepare_done);
    CHECK(log.prepare_after_photons == 0, "a prepare report came after the photons began");
    CHECK(log.prepare_total == 2, "prepare counted %llu objects, not the room and the plate",
          (unsigned long long)log.prepare_total);
    thz_run_destroy(gathered);
    cancel_at in_prepare = {.stage = "prepare"};
    thz_context_set_progress(ctx, cancel_progress, &in_prepare);
    gathered = (thz_run *)&in_prepare;
    thz_status stopped = thz_simulate(ctx, scene, &gather, &gathered, &err);
    CHECK(stopped == THZ_ERR_CANCELLED && in_prepare.cancelled && gathered == NULL,
          "cancelled in prepare: %s (%s)", thz_status_name(stopped), err.message);

    /* while writing: OUTDIR, created by the write, is gone again */
    thz_context_set_progress(ctx, NULL, NULL);
    thz_run_settings settings = {.integrator = "path"}; /* quick: no photons */
    thz_run *run = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &run, &err), &err);
    cancel_at c = {.stage = "output"};
    thz_context_set_progress(ctx, cancel_progress, &c);
    snprintf(out, sizeof out, "%s/out-write", dir);
    thz_status st = thz_run_write(ctx, run, out, NULL, &err);
    CHECK(st == THZ_ERR_CANCELLED, "write: %s (%s)", thz_status_name(st), err.message);
    /* the message names the write, not the run that was over ("simulate: cancelled") */
    CHECK(strstr(err.message, "writing the simulate results: cancelled") != NULL,
          "write cancelled: '%s'", err.message);
    struct stat info;
    CHECK(stat(out, &info) != 0, "%s exists after a cancelled write", out);
    /* and without cancelling, it is written */
    thz_context_set_progress(ctx, NULL, NULL);
    REQUIRE_OK(thz_run_write(ctx, run, out, NULL, &err), &err);
    CHECK(!empty_or_missing(out), "%s empty after a write", out);
    /* an image's write alike (it wrote whatever the callback said) */
    const thz_image *image = thz_run_image(run, 0);
    CHECK(image != NULL, "the run has no image");
    cancel_at ci = {.stage = "output"};
    thz_context_set_progress(ctx, cancel_progress, &ci);
    snprintf(out, sizeof out, "%s/out-image", dir);
    st = thz_image_write(ctx, image, out, &err);
    CHECK(st == THZ_ERR_CANCELLED && ci.cancelled && strstr(err.message, "writing the image"),
          "image write: %s (%s)", thz_status_name(st), err.message);
    CHECK(stat(out, &info) != 0, "%s exists after a cancelled image write", out);
    thz_context_set_progress(ctx, NULL, NULL);
    REQUIRE_OK(thz_image_write(ctx, image, out, &err), &err);
    CHECK(!empty_or_missing(out), "%s empty after an image write", out);
    thz_run_destroy(run);

    /* photon counts whose memory estimate overflows 64 bits are refused at once (they
     * once wrapped to a small estimate and started firing 2^60 photons) */
    thz_context_set_progress(ctx, NULL, NULL);
    const uint64_t huge[] = {(uint64_t)1 << 60, UINT64_MAX};
    for (size_t k = 0; k < sizeof huge / sizeof huge[0]; k++) {
        thz_run_settings big = {.photons_per_channel = huge[k]};
        run = NULL;
        st = thz_simulate(ctx, scene, &big, &run, &err);
        CHECK(st == THZ_ERR_LIMIT, "%llu photons: %s (%s)", (unsigned long long)huge[k],
              thz_status_name(st), err.message);
        CHECK(run == NULL, "%llu photons: a run came back", (unsigned long long)huge[k]);
        thz_run_destroy(run);
    }
    /* and so is a photon phase alone whose maps would not fit (it once allocated until
     * the kernel killed the process) */
    thz_run_settings fire = {.photons_per_channel = (uint64_t)1 << 50, .integrator = "photon-map"};
    thz_photons *ph = (thz_photons *)&fire;
    st = thz_photons_fire(ctx, scene, &fire, &ph, &err);
    CHECK(st == THZ_ERR_LIMIT && strstr(err.message, "GiB of memory"),
          "firing 2^50 photons a channel: %s (%s)", thz_status_name(st), err.message);
    CHECK(ph == NULL, "firing 2^50 photons a channel: photons came back");

    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    return test_finish(argv[0], dir);
}
