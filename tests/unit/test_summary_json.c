/* summary.json (io/summary.c through summary_write): the run's numbers under their
 * documented keys and units, fractions with their documented denominators, non-finite
 * values as null, scene and run warnings merged. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "io/output.h"
#include "scene/scene.h"

/* A fresh directory under $TMPDIR (or /tmp); the caller frees its name. */
static char *make_tmp_dir(void)
{
    const char *base = getenv("TMPDIR");
    char templ[512];
    snprintf(templ, sizeof templ, "%s/thz-test-summary-XXXXXX", base && *base ? base : "/tmp");
    char *d = mkdtemp(templ);
    assert_non_null(d);
    return thz_strdup(d);
}

/* summary.json: the run's numbers under their documented keys, fractions with their
 * documented denominators, non-finite values as null, scene and run warnings merged. */
static void test_summary_json(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    thz_scene *scene = scene_create();
    assert_non_null(scene);
    scene->name = thz_strdup("s");
    scene->path = thz_strdup("/x/s.json");
    scene->n_channels = 2;
    scene->channels = thz_calloc(2, sizeof *scene->channels);
    snprintf(scene->channels[0].name, sizeof scene->channels[0].name, "a");
    scene->channels[0].center_hz = 0.35e12;
    scene->channels[0].relative_width = 0.01;
    snprintf(scene->channels[1].name, sizeof scene->channels[1].name, "b");
    scene->channels[1].center_hz = 1.2e12;
    scene->channels[1].relative_width = 0.02;
    scene->n_sensors = 1;
    scene->sensors = thz_calloc(1, sizeof *scene->sensors);
    scene->sensors[0].name = thz_strdup("cam");
    scene->sensors[0].columns = 7;
    scene->sensors[0].rows = 5;
    scene->sensors[0].fov_deg = 40.0;
    scene->sensors[0].oversampling = 3;
    scene->sensors[0].aperture_m2 = 0.02;
    scene->sensors[0].normalize_to_k = 300.0;
    scene->n_objects = 1;
    scene->objects = thz_calloc(1, sizeof *scene->objects);
    scene->objects[0].name = thz_strdup("wall");
    assert_true(scene_add_warning(scene, "scene warning"));

    photon_stats st[2] = {{0}};
    st[0].fired = 1000;
    st[0].stored = 1500;
    st[0].hits = 1500;
    st[0].reflected = 300;
    st[0].transmitted = 200;
    st[0].absorbed = 900;
    st[0].escaped = 60;
    st[0].terminated = 40;
    st[0].emitted_power_w_per_hz = 2e-12;
    st[0].absorbed_power_w_per_hz = 1.5e-12;
    st[0].escaped_power_w_per_hz = 0.4e-12;
    st[0].atmosphere_power_w_per_hz = 0.08e-12;
    st[0].terminated_power_w_per_hz = 0.01e-12;
    st[0].fired_power_w_per_hz = 1.99e-12;
    st[0].mean_bounces = 1.5;
    st[1].fired = 10;
    st[1].emitted_power_w_per_hz = NAN;
    run_noise noise[2] = {{.median_k = 0.5, .p95_k = 0.9, .pixels = 35},
                          {.median_k = 0.25, .p95_k = 0.4, .pixels = 35}};
    run_noise object_noise[2] = {{.median_k = 0.6, .p95_k = 1.1, .pixels = 20},
                                 {.median_k = 0.0, .p95_k = 0.0, .pixels = 0}};
    uint64_t back[1] = {3};
    const char *run_warnings[] = {"run warning"};
    run_summary rs = {.command = "simulate",
                      .integrator = "photon-map",
                      .seed = 42,
                      .photons_per_channel = 1000,
                      .threads = 2,
                      .channel_stats = st,
                      .noise = noise,
                      .object_noise = object_noise,
                      .target_noise_k = 0.1,
                      .target_source = "default",
                      .back_face_samples = back,
                      .seconds_photons = 1.25,
                      .n_run_warnings = 1,
                      .run_warnings = run_warnings};
    thz_error err = {0};
    assert_int_equal(summary_write(tmp, scene, &rs, &err), THZ_OK);

    char path[1024];
    snprintf(path, sizeof path, "%s/summary.json", tmp);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    if (!root)
        fail_msg("summary.json does not parse: %s", jerr.text);
    assert_string_equal(json_string_value(json_object_get(root, "thzmap_version")),
                        THZ_VERSION_STRING);
    assert_string_equal(json_string_value(json_object_get(root, "thzmap_revision")),
                        thz_revision());
    assert_string_equal(json_string_value(json_object_get(root, "command")), "simulate");
    assert_int_equal(json_integer_value(json_object_get(root, "seed")), 42);
    assert_int_equal(json_integer_value(json_object_get(root, "threads")), 2);
    json_t *sc = json_object_get(root, "scene");
    assert_string_equal(json_string_value(json_object_get(sc, "path")), "/x/s.json");

    json_t *chs = json_object_get(root, "channels");
    assert_int_equal(json_array_size(chs), 2);
    json_t *c0 = json_array_get(chs, 0);
    assert_string_equal(json_string_value(json_object_get(c0, "name")), "a");
    assert_true(fabs(json_number_value(json_object_get(c0, "frequency_thz")) - 0.35) < 1e-12);
    /* physics.md: a Gaussian's B_c = sqrt(pi / (4 ln 2)) FWHM = 1.0645 FWHM and B_n =
     * sqrt(pi / (2 ln 2)) FWHM = 1.5054 FWHM, FWHM = 0.01 * 350 GHz (the two swapped
     * passed every unit test) */
    const double fwhm_ghz = 3.5;
    assert_true(fabs(json_number_value(json_object_get(c0, "bandwidth_ghz")) -
                     sqrt(M_PI / (4.0 * log(2.0))) * fwhm_ghz) < 1e-9);
    assert_true(fabs(json_number_value(json_object_get(c0, "noise_bandwidth_ghz")) -
                     sqrt(M_PI / (2.0 * log(2.0))) * fwhm_ghz) < 1e-9);
    assert_int_equal(json_integer_value(json_object_get(c0, "photons_fired")), 1000);
    assert_int_equal(json_integer_value(json_object_get(c0, "photons_stored")), 1500);
    /* per photon fired: 0.9 + 0.06 + 0.04 = 1; per hit: 0.2 and 0.1333 */
    assert_true(fabs(json_number_value(json_object_get(c0, "fraction_absorbed")) - 0.9) < 1e-12);
    assert_true(fabs(json_number_value(json_object_get(c0, "fraction_escaped")) - 0.06) < 1e-12);
    assert_true(fabs(json_number_value(json_object_get(c0, "fraction_reflected")) - 0.2) < 1e-12);
    assert_true(fabs(json_number_value(json_object_get(c0, "fraction_transmitted")) - 0.2 / 1.5) <
                1e-12);
    json_t *eb = json_object_get(c0, "energy_balance");
    /* (2 - 1.5 - 0.4 - 0.08 - 0.01) / 2: the terminated power counts in the balance */
    assert_true(fabs(json_number_value(json_object_get(eb, "relative_difference")) - 0.005) < 1e-9);
    assert_true(fabs(json_number_value(json_object_get(eb, "fired_w_per_hz")) - 1.99e-12) < 1e-24);
    assert_true(fabs(json_number_value(json_object_get(eb, "terminated_w_per_hz")) - 0.01e-12) <
                1e-24);
    assert_true(fabs(json_number_value(json_object_get(c0, "median_stderr_k")) - 0.5) < 1e-12);
    assert_true(fabs(json_number_value(json_object_get(c0, "p95_stderr_k")) - 0.9) < 1e-12);
    json_t *o0 = json_array_get(json_object_get(c0, "objects"), 0);
    assert_string_equal(json_string_value(json_object_get(o0, "name")), "wall");
    assert_int_equal(json_integer_value(json_object_get(o0, "pixels")), 20);
    assert_true(fabs(json_number_value(json_object_get(o0, "median_stderr_k")) - 0.6) < 1e-12);
    assert_true(fabs(json_number_value(json_object_get(o0, "p95_stderr_k")) - 1.1) < 1e-12);
    assert_string_equal(json_string_value(json_object_get(root, "target_noise_source")), "default");
    json_t *c1 = json_array_get(chs, 1);
    json_t *o1 = json_array_get(json_object_get(c1, "objects"), 0);
    assert_int_equal(json_integer_value(json_object_get(o1, "pixels")), 0);
    assert_true(json_is_null(json_object_get(o1, "p95_stderr_k"))); /* no pixels: no figure */
    /* a figure that is not a number is written as null */
    assert_true(
        json_is_null(json_object_get(json_object_get(c1, "energy_balance"), "emitted_w_per_hz")));
    /* P_A is the surfaces' (physics.md), from the scene, not the photon phase's total */
    assert_true(json_is_number(json_object_get(c1, "emitted_power_w_per_hz")));
    assert_true(fabs(json_number_value(json_object_get(c0, "emitted_power_w_per_hz")) -
                     scene_band_emitted_power_w_per_hz(scene, 0)) <=
                1e-12 * scene_band_emitted_power_w_per_hz(scene, 0));
    assert_true(json_is_null(
        json_object_get(json_object_get(c1, "energy_balance"), "relative_difference")));

    json_t *s0 = json_array_get(json_object_get(root, "sensors"), 0);
    assert_string_equal(json_string_value(json_object_get(s0, "name")), "cam");
    assert_int_equal(json_integer_value(json_object_get(s0, "columns")), 7);
    assert_int_equal(json_integer_value(json_object_get(s0, "rows")), 5);
    assert_int_equal(json_integer_value(json_object_get(s0, "back_face_samples")), 3);
    /* the sensor's keys in the scene's units (an aperture in cm^2, 200, passed unseen) */
    assert_true(json_number_value(json_object_get(s0, "fov_deg")) == 40.0);
    assert_int_equal(json_integer_value(json_object_get(s0, "oversampling")), 3);
    assert_true(json_number_value(json_object_get(s0, "aperture_m2")) == 0.02);
    assert_true(json_number_value(json_object_get(s0, "normalize_to_k")) == 300.0);
    json_t *t = json_object_get(root, "timings_s");
    assert_true(fabs(json_number_value(json_object_get(t, "photons")) - 1.25) < 1e-12);
    json_t *w = json_object_get(root, "warnings");
    assert_int_equal(json_array_size(w), 2);
    assert_string_equal(json_string_value(json_array_get(w, 0)), "scene warning");
    assert_string_equal(json_string_value(json_array_get(w, 1)), "run warning");
    json_decref(root);

    /* path: no photon phase, so no photon statistics but the counts (0) and P_A the
     * spec lists; no stderr, no back-face counts */
    run_summary render = {.command = "render", .integrator = "path"};
    assert_int_equal(summary_write(tmp, scene, &render, &err), THZ_OK);
    root = json_load_file(path, 0, &jerr);
    assert_non_null(root);
    c0 = json_array_get(json_object_get(root, "channels"), 0);
    assert_int_equal(json_integer_value(json_object_get(c0, "photons_fired")), 0);
    assert_int_equal(json_integer_value(json_object_get(c0, "photons_stored")), 0);
    assert_true(json_is_number(json_object_get(c0, "emitted_power_w_per_hz")));
    assert_null(json_object_get(c0, "energy_balance"));
    assert_null(json_object_get(c0, "median_stderr_k"));
    assert_string_equal(json_string_value(json_object_get(c0, "name")), "a");
    json_decref(root);

    char path_json[4200];
    snprintf(path_json, sizeof path_json, "%s/summary.json", tmp);
    assert_int_equal(unlink(path_json), 0);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
    scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_summary_json),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
