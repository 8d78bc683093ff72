/* A run's claims on OUTDIR (io/output.h output_stage_claim): an earlier run's file of a
 * name the new run claims but did not write is gone after the commit (a sensor's
 * measured cubes once its noise is gone, a channel's figure it no longer has, an old
 * photon map), in both commit modes; every other file stays. And the names a sensor's
 * files may have. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/output.h"

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* The file's text, "" when missing. */
static const char *file_text(const char *dir, const char *name)
{
    static char buf[256];
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    if (f) {
        buf[fread(buf, 1, sizeof buf - 1, f)] = '\0';
        fclose(f);
    }
    return buf;
}

static void test_sensor_file_names(void **state)
{
    (void)state;
    const char *ours[] = {"cam.radiance.hdr",
                          "cam.radiance.img",
                          "cam.radiance_stderr.img",
                          "cam.power.hdr",
                          "cam.brightness_temperature.img",
                          "cam.normalized.hdr",
                          "cam.temperature.img",
                          "cam.distance.hdr",
                          "cam.object_id.img",
                          "cam.measured_radiance.hdr",
                          "cam.measured_brightness_temperature.img",
                          "cam.visual.png",
                          "cam.spectra.png",
                          "cam.band-01.png",
                          "cam.band-123.png",
                          "cam.measured-band-07.png"};
    for (size_t i = 0; i < sizeof ours / sizeof *ours; i++)
        if (!output_sensor_file("cam.", ours[i]))
            fail_msg("%s is a file of sensor cam", ours[i]);
    /* a user's files beside them, another sensor's (also one whose name begins with
     * "cam."), classify's, and near misses */
    const char *not_ours[] = {"cam.notes.txt", "cam.radiance.txt", "cam.radiance", "cam.band-.png",
                              "cam.band-01.jpg", "cam.band-1a.png", "camera.radiance.hdr",
                              "cam.wide.radiance.hdr", "cam.class.hdr", "cam.visual.png.bak",
                              "summary.json", "cam.", "other.radiance.hdr", "cam.radiance.hdr.img",
                              /* numbers thzmap never writes (band-%02zu): a user's */
                              "cam.band-1.png", "cam.band-007.png", "cam.measured-band-3.png",
                              /* S.visual is a PNG: no cube of that name is thzmap's */
                              "cam.visual.hdr", "cam.visual.img"};
    for (size_t i = 0; i < sizeof not_ours / sizeof *not_ours; i++)
        if (output_sensor_file("cam.", not_ours[i]))
            fail_msg("%s is not a file of sensor cam", not_ours[i]);
    /* sensor "cam.wide"'s own files are its, not cam's */
    assert_true(output_sensor_file("cam.wide.", "cam.wide.radiance.hdr"));
}

/* OUTDIR as an earlier run with a noisy sensor "cam" of two channels, a saved photon map
 * and a second sensor left it, with the user's notes beside; the new run writes cam's
 * radiance alone and claims cam's files and the photon map. */
static void commit_with_claims(const char *outdir, const char *check_dir)
{
    const char *old[] = {
        "cam.radiance.hdr", "cam.measured_radiance.hdr", "cam.band-02.png", "photon-map.thzpm",
        "photon-map.ply",   "other.radiance.hdr",        "notes.txt",       "cam.notes.txt"};
    for (size_t i = 0; i < sizeof old / sizeof *old; i++)
        write_file(check_dir, old[i], "old");
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(outdir, &stage, NULL), THZ_OK);
    assert_int_equal(output_stage_claim_sensor(stage, "cam", NULL), THZ_OK);
    assert_int_equal(output_stage_claim(stage, "photon-map.thzpm", NULL), THZ_OK);
    assert_int_equal(output_stage_claim(stage, "photon-map.ply", NULL), THZ_OK);
    write_file(output_stage_dir(stage), "cam.radiance.hdr", "new");
    assert_int_equal(output_stage_commit(stage, NULL), THZ_OK);
    output_stage_destroy(stage);
    assert_string_equal(file_text(check_dir, "cam.radiance.hdr"), "new");
    const char *gone[] = {"cam.measured_radiance.hdr", "cam.band-02.png", "photon-map.thzpm",
                          "photon-map.ply"};
    for (size_t i = 0; i < sizeof gone / sizeof *gone; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", check_dir, gone[i]);
        if (access(path, F_OK) == 0)
            fail_msg("%s: the earlier run's, kept beside the new run's", gone[i]);
    }
    for (size_t i = 5; i < sizeof old / sizeof *old; i++)
        assert_string_equal(file_text(check_dir, old[i]), "old");
    for (size_t i = 0; i < sizeof old / sizeof *old; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", check_dir, old[i]);
        unlink(path);
    }
}

static void test_claims_swap(void **state)
{
    (void)state;
    char tmp[] = "/tmp/thz-test-claims-XXXXXX", outdir[64];
    assert_non_null(mkdtemp(tmp));
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    assert_int_equal(mkdir(outdir, 0777), 0);
    commit_with_claims(outdir, outdir);
    assert_int_equal(rmdir(outdir), 0);
    assert_int_equal(rmdir(tmp), 0); /* no stage or old run left beside */
}

/* OUTDIR the working directory: the file-by-file commit. */
static void test_claims_files(void **state)
{
    (void)state;
    char tmp[] = "/tmp/thz-test-claims-XXXXXX", cwd[4096];
    assert_non_null(mkdtemp(tmp));
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(tmp), 0);
    commit_with_claims(".", ".");
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(rmdir(tmp), 0); /* nothing else left inside */
}

/* Without claims every file of OUTDIR the run does not write stays. */
static void test_no_claims_keeps_all(void **state)
{
    (void)state;
    char tmp[] = "/tmp/thz-test-claims-XXXXXX";
    assert_non_null(mkdtemp(tmp));
    write_file(tmp, "cam.measured_radiance.hdr", "old");
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(tmp, &stage, NULL), THZ_OK);
    write_file(output_stage_dir(stage), "cam.radiance.hdr", "new");
    assert_int_equal(output_stage_commit(stage, NULL), THZ_OK);
    output_stage_destroy(stage);
    assert_string_equal(file_text(tmp, "cam.measured_radiance.hdr"), "old");
    char path[4096];
    snprintf(path, sizeof path, "%s/cam.measured_radiance.hdr", tmp);
    unlink(path);
    snprintf(path, sizeof path, "%s/cam.radiance.hdr", tmp);
    unlink(path);
    assert_int_equal(rmdir(tmp), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sensor_file_names),
        cmocka_unit_test(test_claims_swap),
        cmocka_unit_test(test_claims_files),
        cmocka_unit_test(test_no_claims_keeps_all),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
