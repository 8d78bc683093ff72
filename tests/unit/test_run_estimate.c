/* The up-front estimate's pilot (run_estimate.c) does no more work than the run it
 * estimates: its copy of the sensor has at most RUN_PILOT_SIDE pixels a side and no more
 * than the sensor's, one sample a pixel, and it fires at most RUN_PILOT_PHOTONS photons,
 * casts at most RUN_PILOT_ESTIMATES paths or gather rays a sample, and no more than the
 * run's (but at least 2, whose spread tells the noise). A 2 x 2 camera's pilot once rendered 32 x
 * 32 pixels: 1.4 s before a render of 5 ms; a 32 x 24 camera's pilot at the run's 30 000 paths a
 * sample took 12 s before a render of 21 s. The copy is otherwise the sensor (its position and
 * field). Then the estimate itself, on a small scene with a noise target, with a pilot of the run's
 * size, and a path run's passes from a pilot of fewer paths than the run's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accel/accel.h"
#include "run/run.h"
#include "run/run_estimate.h"
#include "scene/scene.h"

/* A closed box (at 300 K; with a ball at 330 K in it when INTEGRATOR is "path", whose
 * noise in a room of one temperature is 0) and one sensor of COLUMNS x ROWS, oversampling
 * OVERSAMPLING, PHOTONS a channel, rendered by INTEGRATOR with J paths or gather rays a
 * sample. */
static thz_scene *load_with(unsigned columns, unsigned rows, unsigned oversampling, double photons,
                            const char *integrator, unsigned j)
{
    const char *ball =
        strcmp(integrator, "path") != 0
            ? ""
            : ", {\"name\": \"ball\", \"type\": \"solid\", \"material\": \"wall\","
              "   \"temperature_k\": 330, \"shape\": {\"type\": \"sphere\","
              "   \"radius_m\": 0.3}, \"transform\": {\"translate_m\": [0, 0.5, 0]}}";
    char json[1280];
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\","
             " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"
             " \"materials\": {\"wall\": {\"reflectivity\": 0.3}},"
             " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
             "   \"temperature_k\": 300,"
             "   \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}}%s],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0.1, -0.5, 0.2],"
             "   \"look_at_m\": [0, 0.5, 0], \"fov_deg\": 50, \"resolution\": [%u, %u],"
             "   \"oversampling\": %u}],"
             " \"photons\": {\"per_channel\": %.0f, \"seed\": 5},"
             " \"render\": {\"integrator\": \"%s\", \"paths_per_sample\": %u,"
             "   \"gather_rays\": %u}}",
             ball, columns, rows, oversampling, photons, integrator, j, j);
    thz_scene *s = NULL;
    thz_error err;
    if (scene_load_string(json, ".", "estimate-unit", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    return s;
}

static thz_scene *load(unsigned columns, unsigned rows, unsigned oversampling, double photons)
{
    return load_with(columns, rows, oversampling, photons, "photon-map", 32);
}

static void check_pilot(unsigned columns, unsigned rows, double photons, unsigned want_columns,
                        unsigned want_rows, uint64_t want_photons)
{
    thz_scene *s = load(columns, rows, 3, photons);
    thz_scene pilot;
    thz_sensor cam;
    run_estimate_pilot(s, &s->sensors[0], &pilot, &cam);
    assert_int_equal(cam.columns, want_columns);
    assert_int_equal(cam.rows, want_rows);
    assert_int_equal(cam.oversampling, 1);
    assert_int_equal(pilot.photons.per_channel, want_photons);
    assert_ptr_equal(pilot.sensors, &cam);
    assert_int_equal(pilot.n_sensors, 1);
    /* the same camera otherwise */
    assert_memory_equal(cam.position_m, s->sensors[0].position_m, sizeof cam.position_m);
    assert_true(cam.fov_deg == s->sensors[0].fov_deg);
    scene_destroy(s);
}

/* Paths and gather rays a pilot's sample casts: the run's, at most RUN_PILOT_ESTIMATES
 * and at least 2. */
static void check_pilot_estimates(const char *integrator, unsigned j, unsigned want)
{
    thz_scene *s = load_with(8, 8, 1, 1000, integrator, j);
    thz_scene pilot;
    thz_sensor cam;
    run_estimate_pilot(s, &s->sensors[0], &pilot, &cam);
    assert_int_equal(pilot.render.integrator, s->render.integrator);
    assert_int_equal(pilot.render.paths_per_sample, want);
    assert_int_equal(pilot.render.gather_rays, want);
    scene_destroy(s);
}

static void test_pilot_no_larger_than_the_run(void **state)
{
    (void)state;
    check_pilot(2, 2, 500, 2, 2, 500);         /* both smaller than the pilot's */
    check_pilot(640, 20, 1e6, 32, 20, 20000);  /* one side smaller */
    check_pilot(32, 33, 20000, 32, 32, 20000); /* at the limits */
    check_pilot(1, 1000, 19999, 1, 32, 19999); /* a column */
    check_pilot(4096, 4096, 1e9, 32, 32, RUN_PILOT_PHOTONS);
    check_pilot_estimates("path", 30000, RUN_PILOT_ESTIMATES);
    check_pilot_estimates("path", 3, 3);
    check_pilot_estimates("path", 1, 2); /* one estimate a pixel tells no noise */
    check_pilot_estimates("final-gather", 1, 2);
    check_pilot_estimates("final-gather", 1000000, RUN_PILOT_ESTIMATES);
    check_pilot_estimates("final-gather", RUN_PILOT_ESTIMATES, RUN_PILOT_ESTIMATES);
}

/* The estimate of the run of load_with(columns, rows, 1, photons, integrator, j) towards
 * target_k. */
static run_estimate estimate_run(unsigned columns, unsigned rows, double photons,
                                 const char *integrator, unsigned j, double target_k)
{
    thz_scene *s = load_with(columns, rows, 1, photons, integrator, j);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    size_t selected = 0;
    run_estimate_input in = {.scene = s,
                             .accel = acc,
                             .selected = &selected,
                             .n_selected = 1,
                             .target_noise_k = target_k,
                             .threads = 1};
    run_estimate e;
    assert_int_equal(run_estimate_time(&in, &e, &err), THZ_OK);
    accel_destroy(acc);
    scene_destroy(s);
    return e;
}

/* The same for the photon-map run of load(columns, rows, 1, photons). */
static run_estimate estimate_of(unsigned columns, unsigned rows, double photons, double target_k)
{
    return estimate_run(columns, rows, photons, "photon-map", 32, target_k);
}

static run_estimate estimate(double photons, double target_k)
{
    return estimate_of(3, 2, photons, target_k);
}

/* The estimate of a small photon-map run with a noise target: its pilot fires the run's
 * 300 photons and renders its 3 x 2 pixels. */
static void test_estimate_small_run(void **state)
{
    (void)state;
    run_estimate e = estimate(300, 0.01);
    assert_true(e.seconds_photons > 0.0 && e.seconds_render > 0.0);
    /* 300 photons cannot reach 0.01 K in a 300 K room: several passes of 300, holding
     * their maps, which fit */
    assert_true(e.passes > 1);
    assert_true(e.passes_bytes > 0 && !e.memory_stop);
}

/* Passes of 3 x 10^7 photons towards 0.0001 K: their maps, held until the channel ends,
 * would pass the memory the passes may hold long before the target; the estimate says so
 * and counts the passes that fit (the pilot still fires its RUN_PILOT_PHOTONS alone). */
static void test_estimate_passes_stop_at_memory(void **state)
{
    (void)state;
    run_estimate e = estimate(3e7, 1e-4);
    double limit = run_passes_memory_limit_bytes();
    if (limit > 0.0) {
        assert_true(e.memory_stop);
        /* (a single pass is never refused here: the run's memory check is before) */
        assert_true((double)e.passes_bytes <= limit || e.passes == 1);
        /* one pass more would not have fitted */
        assert_true((double)e.passes_bytes / e.passes * (e.passes + 1) > limit);
    }
}

/* The noise falls as 1/sqrt(photons): half the target asks 4 x the passes (each count a
 * ceiling, so 4 x less up to 3); a sensor of twice the pilot's pixel pitch (64 x 32
 * against the pilot's 32 x 32, the same field) has each disk hold a quarter of the
 * pilot's photons, so twice its noise: 4 x the passes of a 32 x 32 sensor. */
static void test_estimate_passes_law(void **state)
{
    (void)state;
    run_estimate a = estimate_of(32, 32, 300, 2.0), b = estimate_of(32, 32, 300, 1.0);
    run_estimate c = estimate_of(64, 32, 300, 2.0);
    assert_true(a.passes >= 10 && !b.memory_stop && !c.memory_stop);
    assert_true(b.passes <= 4 * a.passes && b.passes + 3 >= 4 * a.passes);
    assert_true(c.passes <= 4 * a.passes && c.passes + 3 >= 4 * a.passes);
}

/* path's noise falls as 1/sqrt(paths): a run of 16 x RUN_PILOT_ESTIMATES paths a sample
 * needs a sixteenth of the passes of one at RUN_PILOT_ESTIMATES (each count a ceiling),
 * though both pilots cast RUN_PILOT_ESTIMATES. */
static void test_estimate_path_pilot_paths(void **state)
{
    (void)state;
    const double target_k = 0.02;
    run_estimate a = estimate_run(8, 8, 1000, "path", RUN_PILOT_ESTIMATES, target_k);
    run_estimate b = estimate_run(8, 8, 1000, "path", 16 * RUN_PILOT_ESTIMATES, target_k);
    print_message("passes %u and %u\n", a.passes, b.passes);
    assert_true(a.passes >= 64 && a.passes < 100000);
    assert_true(b.passes * 16 >= a.passes && b.passes * 16 <= a.passes + 15);
    assert_true(a.seconds_photons == 0.0 && b.seconds_photons == 0.0);
    /* one path a sample: the pilot casts 2 (one tells no noise: it said 1 pass, at the
     * pilot's "0 K"), and the run needs twice the passes of one of 2 paths */
    run_estimate one = estimate_run(8, 8, 1000, "path", 1, target_k);
    run_estimate two = estimate_run(8, 8, 1000, "path", 2, target_k);
    print_message("1 path: %u passes, 2 paths: %u\n", one.passes, two.passes);
    assert_true(two.passes >= 64);
    assert_true(one.passes >= 2 * two.passes - 1 && one.passes <= 2 * two.passes);
}

/* A check at most a quarter more passes than so far and at least one more, at the passes
 * the noise asks when fewer (run.h). */
static void test_next_check(void **state)
{
    (void)state;
    assert_int_equal(run_photon_next_check(100, INFINITY), 125);
    assert_int_equal(run_photon_next_check(100, 110), 110);
    assert_int_equal(run_photon_next_check(100, 50), 101);
    assert_int_equal(run_photon_next_check(3, INFINITY), 4);
    assert_int_equal(run_photon_next_check(1, INFINITY), 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pilot_no_larger_than_the_run),
        cmocka_unit_test(test_estimate_small_run),
        cmocka_unit_test(test_estimate_passes_stop_at_memory),
        cmocka_unit_test(test_estimate_passes_law),
        cmocka_unit_test(test_estimate_path_pilot_paths),
        cmocka_unit_test(test_next_check),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
