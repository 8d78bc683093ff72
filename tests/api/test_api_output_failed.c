/* An output whose run failed to write part way commits nothing: a file size limit
 * (RLIMIT_FSIZE, SIGXFSZ ignored: write fails with EFBIG, as on a full disk) stops
 * thz_output_add_run after its small files; thz_output_commit then refuses
 * (THZ_ERR_INPUT) and OUTDIR gets none of the run's files (before, the commit moved the
 * partial result in: headers without their cubes). argv: the thzmap binary (unused), the
 * repo (unused). */
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>

#include "api_test.h"

/* How many entries dir holds (-1 when it cannot be read). */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    char tmp[4096], outdir[4200];
    test_temp_dir(tmp, sizeof tmp);
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "failed.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.integrator = "path";
    thz_run *run = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &run, &err), &err);

    thz_output *out = NULL;
    REQUIRE_OK(thz_output_open(outdir, &out, &err), &err);
    /* files beyond 1 KiB fail (the cubes: 20 x 16 x 2 floats), the headers are written */
    struct rlimit old, small;
    CHECK(getrlimit(RLIMIT_FSIZE, &old) == 0, "getrlimit");
    small = old;
    small.rlim_cur = 1024;
    signal(SIGXFSZ, SIG_IGN);
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, "setrlimit");
    thz_status st = thz_output_add_run(ctx, out, run, NULL, &err);
    CHECK(setrlimit(RLIMIT_FSIZE, &old) == 0, "setrlimit back");
    CHECK(st == THZ_ERR_IO, "add_run under a 1 KiB file limit: %s: %s", thz_status_name(st),
          err.message);

    st = thz_output_commit(out, &err);
    CHECK(st == THZ_ERR_INPUT, "commit after a failed add_run: %s: %s", thz_status_name(st),
          err.message);
    CHECK(strstr(err.message, "thz_output_add_run failed") != NULL, "the message: %s", err.message);
    st = thz_output_add_file(out, "notes.txt", "x", 1, &err);
    CHECK(st == THZ_ERR_INPUT, "add_file after a failed add_run: %s", thz_status_name(st));
    thz_output_destroy(out);
    int n = count_entries(outdir);
    CHECK(n <= 0, "OUTDIR holds %d entries after a commit that must not have happened", n);

    /* the same run, without the limit, writes and commits */
    REQUIRE_OK(thz_output_open(outdir, &out, &err), &err);
    REQUIRE_OK(thz_output_add_run(ctx, out, run, NULL, &err), &err);
    REQUIRE_OK(thz_output_commit(out, &err), &err);
    thz_output_destroy(out);
    CHECK(count_entries(outdir) > 10, "OUTDIR after a good commit: %d entries",
          count_entries(outdir));

    thz_run_destroy(run);
    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    return test_finish("test_api_output_failed", tmp);
}
