/* The API's arguments out of range or NULL: _destroy(NULL) does nothing; a context's
 * threads beyond THZ_MAX_THREADS, sensor indices below -1, library indices past the end,
 * NULL out-handles, info structs and handles, a humidity kind the enum lacks and photon
 * numbers past 2^64 - 1 are refused (THZ_ERR_INPUT with a message) or give a neutral
 * value, never a crash or a store through NULL. test_api_contract.c has the calls' other
 * contracts. argv: the thzmap binary (unused), the repo (unused). */
#include <math.h>

#include "api_test.h"

/* A context with more threads than THZ_MAX_THREADS runs nothing (OpenMP would exit the
 * process or crash on such counts): every call that runs with it refuses, naming the
 * limit. The count itself is kept as given. */
static void check_thread_limit(thz_scene *scene, const thz_photons *photons)
{
    thz_error err = {0};
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, THZ_MAX_THREADS + 1);
    CHECK(thz_context_threads(ctx) == THZ_MAX_THREADS + 1, "threads %d", thz_context_threads(ctx));
    thz_run_settings settings = {.photons_per_channel = 1000};
    thz_run *run = (thz_run *)&err;
    expect_input_error(thz_simulate(ctx, scene, &settings, &run, &err), &err, "4096",
                       "simulate with 4097 threads");
    CHECK(run == NULL, "a run came back");
    expect_input_error(thz_render_run(ctx, scene, photons, -1, NULL, &run, &err), &err, "4096",
                       "render with 4097 threads");
    thz_photons *ph = (thz_photons *)&err;
    expect_input_error(thz_photons_fire(ctx, scene, &settings, &ph, &err), &err, "4096",
                       "photons with 4097 threads");
    CHECK(ph == NULL, "photons came back");
    expect_input_error(thz_photons_merge(ctx, &photons, 1, &ph, &err), &err, "4096",
                       "merge with 4097 threads");
    CHECK(thz_context_last_status(ctx) == THZ_ERR_INPUT, "last status %d",
          thz_context_last_status(ctx));
    thz_context_set_threads(ctx, THZ_MAX_THREADS);
    CHECK(thz_context_threads(ctx) == THZ_MAX_THREADS, "threads %d", thz_context_threads(ctx));
    /* a negative count means 0, all cores (thzmap.h), as read back */
    thz_context_set_threads(ctx, -3);
    CHECK(thz_context_threads(ctx) == 0, "threads after -3: %d", thz_context_threads(ctx));
    thz_context_destroy(ctx);
}

/* A sensor index below -1 is no sensor (only -1 means every sensor). */
static void check_sensor_index(thz_context *ctx, thz_scene *scene, const thz_photons *photons,
                               const char *map_path)
{
    thz_error err = {0};
    thz_run *run = (thz_run *)&err;
    expect_input_error(thz_render_run(ctx, scene, photons, -5, NULL, &run, &err), &err, "sensor -5",
                       "render_run sensor -5");
    CHECK(run == NULL, "a run came back");
    run = (thz_run *)&err;
    expect_input_error(thz_render_file(ctx, scene, map_path, -2, NULL, &run, &err), &err,
                       "sensor -2", "render_file sensor -2");
    CHECK(run == NULL, "a run came back");
    expect_input_error(thz_render_file(ctx, scene, map_path, 2, NULL, &run, &err), &err, "sensor 2",
                       "render_file sensor 2");
}

/* The material library: indices past the end give a zeroed info and an empty range, not
 * a read beyond its entries. */
static void check_library_bounds(void)
{
    thz_error err = {0};
    thz_library *lib = NULL;
    REQUIRE_OK(thz_library_load(&lib, &err), &err);
    size_t n = thz_library_count(lib);
    thz_library_material_info info;
    memset(&info, 0xff, sizeof info);
    thz_library_get_info(lib, n + 5, &info);
    CHECK(info.name == NULL && info.n_data_ranges == 0, "entry %zu past the end has a name", n + 5);
    double lo = -1, hi = -1;
    for (size_t i = 0; i < n; i++) {
        thz_library_get_range(lib, i, 1000, &lo, &hi);
        CHECK(lo == 0 && hi == 0, "entry %zu range 1000: %g to %g", i, lo, hi);
    }
    thz_library_get_range(lib, n, 0, &lo, &hi);
    CHECK(lo == 0 && hi == 0, "entry %zu: %g to %g", n, lo, hi);
    CHECK(!thz_library_in_range(lib, n, 1e12), "entry past the end in range");
    thz_library_destroy(lib);
}

/* Every NULL out-handle, info struct and handle in one table: the status functions give
 * THZ_ERR_INPUT (with a message when they take a thz_error), never a store through NULL.
 * Row i's call; -1 past the last row. */
static int null_row(size_t i, thz_context *ctx, thz_scene *scene, thz_photons *ph, thz_atm *atm,
                    thz_library *lib, thz_error *err, const char **what)
{
    const thz_photons *parts[1] = {ph};
    thz_atm_options opt;
    thz_atm_options_init(&opt);
    size_t index;
    thz_bands_options bopt;
    thz_bands_options_init(&bopt);
    switch (i) {
#define ROW(n, call)                                                                               \
    case n:                                                                                        \
        *what = #call;                                                                             \
        return call
        ROW(0, thz_simulate(ctx, scene, NULL, NULL, err));
        ROW(1, thz_render_run(ctx, scene, ph, -1, NULL, NULL, err));
        ROW(2, thz_render_sensor(ctx, scene, ph, 0, NULL, NULL, err));
        ROW(3, thz_render_file(ctx, scene, "x.thzpm", -1, NULL, NULL, err));
        ROW(4, thz_photons_fire(ctx, scene, NULL, NULL, err));
        ROW(5, thz_photons_fire_channel(ctx, scene, NULL, 0, NULL, err));
        ROW(6, thz_photons_load(ctx, scene, "x.thzpm", NULL, err));
        ROW(7, thz_photons_merge(ctx, parts, 1, NULL, err));
        ROW(8, thz_output_open("never", NULL, err));
        ROW(9, thz_atm_create(&opt, NULL, NULL, err));
        ROW(10, thz_atm_from_scene(scene, NULL, err));
        ROW(11, thz_library_load(NULL, err));
        ROW(12, thz_atm_create(NULL, NULL, &atm, err));
        ROW(13, thz_library_find(NULL, "water", &index, err));
        ROW(14, thz_library_find(lib, NULL, &index, err));
        ROW(15, thz_library_find(lib, "water", NULL, err));
        ROW(16, thz_atm_check_range(NULL, 1e11, 2e11, "f", err));
        ROW(17, thz_atm_check_air(NULL, err));
        ROW(18, thz_atm_draw_plot(NULL, err));
        /* no thz_error: the status alone */
        ROW(19, thz_bands_select(ctx, "x.json", &bopt, NULL, err));
        ROW(20, thz_cube_read("d", "s", NULL, err));
        ROW(21, thz_classify_cube(NULL, NULL, NULL, NULL, err));
        ROW(22, thz_classify_run("d", "cam", NULL, NULL, err));
        ROW(23, thz_sequence_load("x.json", NULL, err));
        ROW(24, thz_sequence_frame_scene(NULL, 0, NULL, err));
        ROW(25, thz_scene_get_info(scene, NULL));
        ROW(26, thz_scene_channel(scene, 0, NULL));
        ROW(27, thz_scene_material(scene, 0, NULL));
        ROW(28, thz_scene_object(scene, 0, NULL));
        ROW(29, thz_scene_sensor(scene, 0, NULL));
        ROW(30, thz_scene_sensor_channel(scene, 0, 0, NULL));
        ROW(31, thz_scene_object_mesh(scene, 0, NULL));
        ROW(32, thz_scene_material_optics(scene, 0, 3e11, 0, NULL));
        ROW(33, thz_photons_stats(ph, 0, NULL));
        ROW(34, thz_sequence_frame(NULL, 0, NULL));
#undef ROW
    }
    return -1;
}

static void check_null_arguments(thz_context *ctx, thz_scene *scene, thz_photons *ph, thz_run *run)
{
    thz_error err = {0};
    thz_atm *atm = NULL;
    thz_library *lib = NULL;
    REQUIRE_OK(thz_atm_from_scene(scene, &atm, &err), &err);
    REQUIRE_OK(thz_library_load(&lib, &err), &err);
    const char *what = "";
    int st;
    for (size_t i = 0; (st = null_row(i, ctx, scene, ph, atm, lib, &err, &what)) >= 0; i++) {
        CHECK(st == THZ_ERR_INPUT, "%s: %s (%s)", what, thz_status_name((thz_status)st),
              err.message);
        CHECK((i >= 25 && i <= 34) || strstr(err.message, "no "), "%s: message '%s'", what,
              err.message);
        err = (thz_error){0};
    }
    /* the functions that return values give their neutral one */
    CHECK(thz_library_count(NULL) == 0, "count of no library");
    CHECK(isnan(thz_atm_attenuation_per_m(NULL, 3e11)), "alpha of no atmosphere");
    CHECK(isnan(thz_atm_attenuation_per_m(atm, -3e11)), "alpha at a negative frequency");
    thz_surface_optics so;
    CHECK(thz_scene_material_optics(scene, 0, INFINITY, 0, &so) == THZ_ERR_INPUT,
          "optics at an infinite frequency accepted");
    thz_atm_attenuation parts = {0};
    thz_atm_attenuation_parts(NULL, 3e11, &parts);
    CHECK(isnan(parts.total_per_m), "parts of no atmosphere: %g", parts.total_per_m);
    thz_atm_attenuation_parts(atm, 3e11, NULL);
    thz_atm_get_info(atm, NULL);
    thz_run_get_totals(run, NULL);
    CHECK(thz_photons_points(ph, 0, 0, 10, NULL) == 0, "points into NULL");
    thz_library_get_info(lib, 0, NULL);
    /* the analysis results' info of no handle into no struct (they wrote through NULL) */
    thz_classification_get_info(NULL, NULL);
    thz_bands_get_info(NULL, NULL);
    thz_library_get_range(lib, 0, 0, NULL, NULL);
    thz_library_optics_at(lib, 0, 1e12, NULL);
    thz_library_optics optics;
    thz_library_optics_at(NULL, 0, 1e12, &optics);
    CHECK(optics.n == 0 && optics.k == 0, "optics of no library: %g", optics.n);
    const double bad_hz[3] = {-1e12, 0.0, NAN};
    for (size_t i = 0; i < 3; i++) {
        thz_library_optics_at(lib, 0, bad_hz[i], &optics);
        CHECK(optics.n == 0 && optics.normal_reflectance == 0, "optics at %g Hz: n = %g", bad_hz[i],
              optics.n);
    }
    /* Planck's law and its inverse: NaN in, NaN out (not 0 K) */
    CHECK(isnan(thz_planck_radiance(NAN, 300.0)) && isnan(thz_planck_radiance(1e12, NAN)),
          "Planck of NaN");
    CHECK(isnan(thz_brightness_temperature(1e12, NAN)) &&
              isnan(thz_brightness_temperature_stderr(1e12, NAN, 1e-16)),
          "brightness temperature of NaN");
    /* the void functions that fill what they are given do nothing with NULL */
    thz_atm_options_init(NULL);
    thz_bands_options_init(NULL);
    thz_classify_options_init(NULL);
    thz_run_settings_init(NULL);
    const double t[2] = {0, 1}, v[6] = {0}, r[6] = {0};
    double x[3] = {7, 7, 7};
    thz_interp_linear(t, v, 2, 3, 0.5, NULL);
    thz_interp_linear(NULL, v, 2, 3, 0.5, x);
    thz_interp_linear(t, NULL, 2, 3, 0.5, x);
    thz_interp_rotation(t, NULL, 2, 0.5, x);
    thz_interp_rotation(t, r, 2, 0.5, NULL);
    thz_interp_rotation(NULL, r, 2, 0.5, x);
    CHECK(x[0] == 7 && x[1] == 7 && x[2] == 7, "interpolation of NULL arrays wrote %g", x[0]);
    /* a humidity kind the enum does not have, and photon numbers past 2^64 - 1 */
    thz_atm_options opt;
    thz_atm_options_init(&opt);
    opt.humidity_kind = (thz_humidity_kind)77;
    thz_atm *bad = NULL;
    expect_input_error(thz_atm_create(&opt, NULL, &bad, &err), &err, "humidity_kind 77",
                       "humidity kind 77");
    expect_input_error(thz_atm_check_air(&opt, &err), &err, "humidity_kind 77",
                       "humidity kind 77 (check)");
    thz_run_settings wrap = {
        .photons_per_channel = 2000, .first_photon = UINT64_MAX - 999, .integrator = "photon-map"};
    thz_photons *wrapped = NULL;
    expect_input_error(thz_photons_fire(ctx, scene, &wrap, &wrapped, &err), &err,
                       "lower first_photon", "photon numbers past 2^64 - 1");
    CHECK(wrapped == NULL, "a refused fire returned photons");
    thz_library_destroy(lib);
    thz_atm_destroy(atm);
}

int main(int argc, char **argv)
{
    (void)argc;
    thz_context_destroy(NULL);
    thz_scene_destroy(NULL);
    thz_photons_destroy(NULL);
    thz_image_destroy(NULL);
    thz_run_destroy(NULL);
    thz_output_destroy(NULL);
    thz_atm_destroy(NULL);
    CHECK(thz_image_plane(NULL, THZ_PLANE_RADIANCE, NULL) == NULL, "plane of NULL");
    CHECK(thz_run_image(NULL, 0) == NULL, "image of NULL");
    CHECK(thz_plane_name(THZ_PLANE_COUNT) == NULL, "plane name out of range");

    /* a scene, its photons (and their file) and a run for the calls to be given; the run
     * of sensor 1 alone (side's Gaussian PSF: cam's Airy one by FFT took most of the time) */
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "a.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_run_settings settings = {.photons_per_channel = 2000};
    thz_photons *photons = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &photons, &err), &err);
    char dir[4096], path[4200];
    test_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/a.thzpm", dir);
    REQUIRE_OK(thz_photons_save(photons, path, &err), &err);
    thz_run *run = NULL;
    REQUIRE_OK(thz_render_run(ctx, scene, photons, 1, NULL, &run, &err), &err);
    /* its one image (sensor 1's) is image 0; image 1 is out of range: NULL (run.h) */
    CHECK(thz_run_image_count(run) == 1 && thz_run_image(run, 0) != NULL &&
              thz_image_sensor(thz_run_image(run, 0)) == 1 && thz_run_image(run, 1) == NULL,
          "a run of sensor 1: %zu images", thz_run_image_count(run));

    check_thread_limit(scene, photons);
    check_sensor_index(ctx, scene, photons, path);
    check_library_bounds();
    check_null_arguments(ctx, scene, photons, run);

    thz_run_destroy(run);
    thz_photons_destroy(photons);
    thz_scene_destroy(scene);
    thz_context_destroy(ctx);
    return test_finish(argv[0], dir);
}
