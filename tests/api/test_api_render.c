/* The API against the CLI: a scene from a JSON string, photons fired, saved and read
 * back, two sensors rendered in memory (and by thz_render_file from the saved file);
 * every plane must equal, bit for bit, the ENVI
 * image `thzmap simulate` writes for the same scene and seed (and the saved map the
 * CLI's photon-map.thzpm), whatever the thread counts (1 here, 2 for the CLI). And
 * photon-map's photon passes towards a noise target render the photons of one phase of
 * as many (check_photon_passes).
 * argv: the thzmap binary, the repository. */
#include <math.h>

#include "api_test.h"

/* photon-map towards a noise target fires photon passes (pass p: photons p K .. (p + 1) K - 1)
 * and renders their merge: two passes of K must give the image of one phase of 2 K photons
 * (the same photons; run.h), not of K photons twice over, whose standard error would fall
 * as 1 / sqrt(passes) while the image kept the noise of K. */
static const char passes_scene_json[] =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"passes\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"
    " \"materials\": {\"wall\": {\"reflectivity\": 0.3}, \"grey\": {\"reflectivity\": 0.5}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
    "    \"temperature_k\": 295,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"
    "   {\"name\": \"box\", \"type\": \"solid\", \"material\": \"grey\","
    "    \"temperature_k\": 330,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.5, 0.5, 0.5]}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0],"
    "   \"direction\": [0, 1, 0], \"fov_deg\": 60, \"resolution\": [8, 6]}],"
    " \"photons\": {\"per_channel\": 100000, \"seed\": 5},"
    " \"render\": {\"integrator\": \"photon-map\"}}";

/* A photon-map run of `photons` a channel towards `target_k` (0: one pass). */
static thz_run *passes_run(thz_context *ctx, const thz_scene *scene, uint64_t photons,
                           double target_k)
{
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.photons_per_channel = photons;
    settings.target_noise_k = target_k;
    thz_run *run = NULL;
    thz_error err = {0};
    if (thz_simulate(ctx, scene, &settings, &run, &err) != THZ_OK) {
        CHECK(0, "photon passes: %s", err.message);
        return NULL;
    }
    return run;
}

static void check_photon_passes(thz_context *ctx)
{
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(passes_scene_json, NULL, "passes.json", &scene, &err), &err);
    const uint64_t k = 100000;
    thz_run *one = passes_run(ctx, scene, k, 0.0), *whole = passes_run(ctx, scene, 2 * k, 0.0);
    if (!one || !whole) {
        thz_run_destroy(one);
        thz_run_destroy(whole);
        thz_scene_destroy(scene);
        return;
    }
    thz_run_totals t1, tw;
    thz_run_get_totals(one, &t1);
    thz_run_get_totals(whole, &tw);
    /* a target between the noise of K photons and of 2 K (1 / sqrt 2 of it): the check
     * after pass 1 goes on, the one after pass 2 stops */
    double target = 0.85 * t1.worst_p95_stderr_k;
    CHECK(t1.max_passes == 1 && tw.worst_p95_stderr_k < 0.8 * t1.worst_p95_stderr_k,
          "K photons: %u passes, %.4g K; 2 K: %.4g K", t1.max_passes, t1.worst_p95_stderr_k,
          tw.worst_p95_stderr_k);
    thz_run *passes = passes_run(ctx, scene, k, target);
    if (passes) {
        thz_run_totals tp;
        thz_run_get_totals(passes, &tp);
        CHECK(tp.max_passes == 2 && tp.photons_fired == 2 * k,
              "towards %.4g K: %u passes, %llu photons", target, tp.max_passes,
              (unsigned long long)tp.photons_fired);
        size_t na = 0, nb = 0;
        const float *a = thz_image_plane(thz_run_image(passes, 0), THZ_PLANE_RADIANCE, &na);
        const float *b = thz_image_plane(thz_run_image(whole, 0), THZ_PLANE_RADIANCE, &nb);
        size_t pixels = 8 * 6, off = 0;
        double worst = 0.0;
        for (size_t i = 0; a && b && na == 1 && nb == 1 && i < pixels; i++) {
            double rel = fabs((double)a[i] - (double)b[i]) / fabs((double)b[i]);
            off += !(rel <= 1e-5); /* the merge's order of equal keys: rounding only */
            worst = rel > worst ? rel : worst;
        }
        CHECK(a && b && off == 0,
              "2 passes of %llu photons against one of %llu: %zu of %zu "
              "pixels differ (worst by %.3g)",
              (unsigned long long)k, (unsigned long long)(2 * k), off, pixels, worst);
        CHECK(fabs(tp.worst_p95_stderr_k - tw.worst_p95_stderr_k) <= 1e-4 * tw.worst_p95_stderr_k,
              "standard error after 2 passes %.5g K, of one phase of 2 K photons %.5g K",
              tp.worst_p95_stderr_k, tw.worst_p95_stderr_k);
    }
    thz_run_destroy(passes);
    thz_run_destroy(one);
    thz_run_destroy(whole);
    thz_scene_destroy(scene);
}

/* A room, two channels and two cameras: "cam" inside, "out" outside it, whose every
 * sample sees the back of the room's inward faces. summary.json's back-face counts are
 * each sensor's over both channels (0 and 2 x 20), of the whole run and of "out" rendered
 * alone (not given to the first sensor of the scene). */
static const char outside_scene_json[] =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"outside\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05},"
    "   {\"frequency_thz\": 0.8, \"relative_width\": 0.05}],"
    " \"materials\": {\"wall\": {\"reflectivity\": 0.3}},"
    " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
    "   \"temperature_k\": 295,"
    "   \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0],"
    "   \"direction\": [0, 1, 0], \"fov_deg\": 60, \"resolution\": [4, 3]},"
    "  {\"name\": \"out\", \"position_m\": [0, -3, 0], \"direction\": [0, 1, 0],"
    "   \"fov_deg\": 20, \"resolution\": [5, 4]}],"
    " \"photons\": {\"per_channel\": 5000, \"seed\": 3},"
    " \"render\": {\"integrator\": \"photon-map\"}}";

/* The value of the n-th (from 0) "back_face_samples" of a summary's text, or -1. */
static long long nth_back_face_count(const char *json, int n)
{
    const char *key = "\"back_face_samples\":";
    const char *at = json;
    for (int k = 0; at && k <= n; k++) {
        at = strstr(at, key);
        if (at && k < n)
            at += strlen(key);
    }
    long long v = -1;
    if (!at || sscanf(at + strlen(key), " %lld", &v) != 1)
        return -1;
    return v;
}

static void check_one_sensor_back_faces(thz_context *ctx)
{
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(outside_scene_json, NULL, "outside.json", &scene, &err), &err);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.keep_photons = 1;
    thz_run *sim = NULL, *one = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &sim, &err), &err);
    REQUIRE_OK(thz_render_run(ctx, scene, thz_run_photons(sim), 1, NULL, &one, &err), &err);
    for (int r = 0; r < 2; r++) {
        const char *sj = thz_run_summary_json(r ? one : sim);
        long long cam = sj ? nth_back_face_count(sj, 0) : -1;
        long long out = sj ? nth_back_face_count(sj, 1) : -1;
        CHECK(cam == 0 && out == 40,
              "%s: back_face_samples %lld (cam), %lld (out; its 20 samples in 2 channels)",
              r ? "'out' rendered alone" : "both simulated", cam, out);
    }
    thz_run_destroy(one);
    thz_run_destroy(sim);
    thz_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s THZMAP_BINARY [REPO]\n", argv[0]);
        return 2;
    }
    char dir[4096], path[4200], cmd[9000];
    test_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/scene.json", dir);
    test_write_file(path, test_scene_json);
    snprintf(cmd, sizeof cmd,
             "'%s' simulate '%s' -o '%s/cli' --threads 2 --save-photon-map --quiet", argv[1], path,
             dir);
    CHECK(system(cmd) == 0, "%s failed", cmd);

    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, dir, "api-test.json", &scene, &err), &err);
    CHECK(thz_scene_sensor_count(scene) == 2, "%zu sensors", thz_scene_sensor_count(scene));
    CHECK(thz_scene_channel_count(scene) == 2, "%zu channels", thz_scene_channel_count(scene));
    CHECK(thz_scene_sensor_index(scene, "side") == 1, "index of 'side'");
    thz_sensor_info sn;
    REQUIRE_OK(thz_scene_sensor(scene, 0, &sn), &err);
    CHECK(sn.columns == 20 && sn.rows == 16 && sn.channels == 2, "cam is %ux%u", sn.columns,
          sn.rows);

    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
    thz_photons *fired = NULL, *photons = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene, NULL, &fired, &err), &err);
    thz_photon_stats ps;
    REQUIRE_OK(thz_photons_stats(fired, 1, &ps), &err);
    CHECK(ps.fired == 20000 && ps.stored > 0, "channel 1: %llu fired, %llu stored",
          (unsigned long long)ps.fired, (unsigned long long)ps.stored);
    CHECK(ps.emitted_power_w_per_hz > 0.0, "emitted power %g W/Hz", ps.emitted_power_w_per_hz);
    snprintf(path, sizeof path, "%s/api.thzpm", dir);
    REQUIRE_OK(thz_photons_save(fired, path, &err), &err);
    thz_photons_destroy(fired);
    REQUIRE_OK(thz_photons_load(ctx, scene, path, &photons, &err), &err);
    CHECK(thz_photons_seed(photons) == 4 && thz_photons_per_channel(photons) == 20000,
          "seed %llu, %llu photons", (unsigned long long)thz_photons_seed(photons),
          (unsigned long long)thz_photons_per_channel(photons));

    /* the saved map is the CLI's, byte for byte */
    size_t n_api = 0, n_cli = 0;
    unsigned char *api_map = test_read_file(path, &n_api);
    snprintf(path, sizeof path, "%s/cli/photon-map.thzpm", dir);
    unsigned char *cli_map = test_read_file(path, &n_cli);
    CHECK(api_map && cli_map && n_api == n_cli && memcmp(api_map, cli_map, n_api) == 0,
          "the saved photon map differs from %s (%zu and %zu bytes)", path, n_api, n_cli);
    free(api_map);
    free(cli_map);

    snprintf(path, sizeof path, "%s/cli", dir);
    for (size_t s = 0; s < 2; s++) {
        thz_image *image = NULL;
        REQUIRE_OK(thz_render_sensor(ctx, scene, photons, s, NULL, &image, &err), &err);
        CHECK(thz_image_sensor(image) == s, "sensor %zu", thz_image_sensor(image));
        size_t bands = 0;
        CHECK(thz_image_plane(image, THZ_PLANE_RADIANCE, &bands) && bands == 2, "radiance bands");
        CHECK(thz_image_plane(image, THZ_PLANE_VISUAL_RGB, &bands) && bands == 3, "visual bands");
        test_compare_image_files(image, path);
        if (s == 0) { /* written alone: the same files, its figures, nothing of a run */
            char one[4200], file[4300];
            snprintf(one, sizeof one, "%s/image-only", dir);
            REQUIRE_OK(thz_image_write(ctx, image, one, &err), &err);
            test_compare_image_files(image, one);
            const char *want[] = {"cam.band-01.png", "cam.band-02.png", "cam.spectra.png",
                                  "cam.visual.png", "cam.radiance.hdr"};
            for (size_t k = 0; k < sizeof want / sizeof *want; k++) {
                snprintf(file, sizeof file, "%s/%s", one, want[k]);
                CHECK(access(file, F_OK) == 0, "thz_image_write did not write %s", file);
            }
            snprintf(file, sizeof file, "%s/summary.json", one);
            CHECK(access(file, F_OK) != 0, "thz_image_write wrote a run's %s", file);
            snprintf(file, sizeof file, "%s/side.radiance.img", one);
            CHECK(access(file, F_OK) != 0, "thz_image_write wrote the other sensor's %s", file);
        }
        thz_image_destroy(image);
    }

    /* thz_render_file, which reads the file a channel at a time: the same images, the
     * file's seed and photons; a missing file or a sensor out of range refused */
    {
        thz_run *from_file = NULL;
        char map_path[4200];
        snprintf(map_path, sizeof map_path, "%s/api.thzpm", dir);
        REQUIRE_OK(thz_render_file(ctx, scene, map_path, -1, NULL, &from_file, &err), &err);
        CHECK(thz_run_image_count(from_file) == 2, "%zu images from the file",
              thz_run_image_count(from_file));
        for (size_t i = 0; i < thz_run_image_count(from_file); i++)
            test_compare_image_files(thz_run_image(from_file, i), path);
        const char *sj = thz_run_summary_json(from_file);
        CHECK(sj && strstr(sj, "\"seed\": 4") && strstr(sj, "\"photons_fired\": 20000"),
              "render_file summary: %.300s", sj ? sj : "(null)");
        /* the summary describes the map read; the totals count what this run fired: none
         * (thzmap render's last line said "40000 photons fired" when they took the map's) */
        thz_run_totals rt;
        thz_run_get_totals(from_file, &rt);
        CHECK(rt.photons_fired == 0 && rt.photons_stored == 0 && rt.n_sensors == 2,
              "a render run's totals: %llu photons fired, %llu stored, %zu sensors",
              (unsigned long long)rt.photons_fired, (unsigned long long)rt.photons_stored,
              rt.n_sensors);
        thz_run_destroy(from_file);
        snprintf(map_path, sizeof map_path, "%s/missing.thzpm", dir);
        thz_run *none = NULL;
        CHECK(thz_render_file(ctx, scene, map_path, -1, NULL, &none, &err) == THZ_ERR_INPUT &&
                  !none && strstr(err.message, "missing.thzpm"),
              "a missing file: %s", err.message);
        snprintf(map_path, sizeof map_path, "%s/api.thzpm", dir);
        CHECK(thz_render_file(ctx, scene, map_path, 7, NULL, &none, &err) == THZ_ERR_INPUT && !none,
              "sensor 7: %s", err.message);
    }

    /* a whole run in memory gives the same images, a summary, and kept photons */
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.keep_photons = 1;
    thz_run *run = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &run, &err), &err);
    CHECK(thz_run_image_count(run) == 2, "%zu images", thz_run_image_count(run));
    for (size_t i = 0; i < thz_run_image_count(run); i++)
        test_compare_image_files(thz_run_image(run, i), path);
    const char *summary = thz_run_summary_json(run);
    CHECK(summary && strstr(summary, "\"photons_fired\": 20000"), "summary: %.200s",
          summary ? summary : "(null)");
    CHECK(thz_run_photons(run) != NULL, "photons kept");
    thz_run_totals totals;
    thz_run_get_totals(run, &totals);
    CHECK(totals.photons_fired == 40000 && totals.n_sensors == 2, "%llu photons, %zu sensors",
          (unsigned long long)totals.photons_fired, totals.n_sensors);
    /* written, it is the CLI's output again */
    snprintf(path, sizeof path, "%s/written", dir);
    thz_write_options wo = {.photon_map = 1};
    REQUIRE_OK(thz_run_write(ctx, run, path, &wo, &err), &err);
    for (size_t i = 0; i < thz_run_image_count(run); i++)
        test_compare_image_files(thz_run_image(run, i), path);
    thz_run_destroy(run);
    /* photon maps to keep from the path integrator, which fires none: refused (the run came
     * back without a map, and a write of it then said keep_photons had not been given) */
    settings.integrator = "path";
    run = NULL;
    CHECK(thz_simulate(ctx, scene, &settings, &run, &err) == THZ_ERR_INPUT && !run &&
              strstr(err.message, "keep_photons: the path integrator fires no photons"),
          "keep_photons with path: %s", err.message);
    CHECK(thz_simulate_check(ctx, scene, &settings, &err) == THZ_ERR_INPUT,
          "thz_simulate_check, keep_photons with path: %s", err.message);

    check_photon_passes(ctx);
    check_one_sensor_back_faces(ctx);

    thz_photons_destroy(photons);
    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    return test_finish(argv[0], dir);
}
