/* A photon map reused from another scene handle: photons fired for one scene, and the
 * same photons loaded from their file, render a second scene that differs in a sensor
 * alone (another viewpoint) to the very bytes of `thzmap render scene2.json --photon-map
 * map.thzpm`; the run outlives the photons and the first scene. Photons of another
 * geometry, channel set or optics are refused saying which, as the file is. argv: the
 * thzmap binary, the repository. */
#include "api_test.h"

/* The part of the refusal that says what differs, in the message of a render from photons
 * in memory and in that of a render from their file. */
static void expect_refused(thz_context *ctx, const char *from, const char *to,
                           const thz_photons *photons, const char *map, const char *what)
{
    thz_error err = {0};
    char *text = test_scene_with(from, to);
    thz_scene *other = NULL;
    REQUIRE_OK(thz_scene_load_string(text, NULL, "other.json", &other, &err), &err);
    thz_run *run = (thz_run *)&err;
    expect_input_error(thz_render_run(ctx, other, photons, -1, NULL, &run, &err), &err, what,
                       "photons in memory");
    CHECK(run == NULL, "%s: a run came back", what);
    CHECK(strstr(err.message, "other.json"), "the scene is not named: %s", err.message);
    expect_input_error(thz_render_file(ctx, other, map, -1, NULL, &run, &err), &err, what,
                       "the photon-map file");
    CHECK(run == NULL, "%s: a run came back from the file", what);
    thz_scene_destroy(other);
    free(text);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s THZMAP_BINARY [REPO]\n", argv[0]);
        return 2;
    }
    /* the second viewpoint: camera "cam" moved and turned, in the same room */
    char *text2 = test_scene_with("\"position_m\": [0, -0.9, 0], \"look_at_m\": [0, 0.5, 0]",
                                  "\"position_m\": [0.5, -0.7, 0.3], \"look_at_m\": [0, 0.5, 0]");
    char dir[4096], map[4200], scene2_path[4200], cli[4200], cmd[13000];
    test_temp_dir(dir, sizeof dir);
    snprintf(map, sizeof map, "%s/map.thzpm", dir);
    snprintf(scene2_path, sizeof scene2_path, "%s/scene2.json", dir);
    snprintf(cli, sizeof cli, "%s/cli", dir);
    test_write_file(scene2_path, text2);

    thz_error err = {0};
    thz_scene *scene1 = NULL, *scene2 = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "scene1.json", &scene1, &err), &err);
    REQUIRE_OK(thz_scene_load_string(text2, NULL, "scene2.json", &scene2, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
    thz_run_settings settings = {.photons_per_channel = 6000};
    thz_photons *fired = NULL, *loaded = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene1, &settings, &fired, &err), &err);
    REQUIRE_OK(thz_photons_save(fired, map, &err), &err);
    REQUIRE_OK(thz_photons_load(ctx, scene1, map, &loaded, &err), &err);

    /* the CLI's render of the second scene from the first one's map (2 threads) */
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --photon-map '%s' -o '%s' --threads 2 --quiet",
             argv[1], scene2_path, map, cli);
    CHECK(system(cmd) == 0, "%s failed", cmd);

    thz_run *from_fired = NULL, *from_loaded = NULL;
    REQUIRE_OK(thz_render_run(ctx, scene2, fired, -1, NULL, &from_fired, &err), &err);
    REQUIRE_OK(thz_render_run(ctx, scene2, loaded, -1, NULL, &from_loaded, &err), &err);
    thz_image *side = NULL;
    REQUIRE_OK(thz_render_sensor(ctx, scene2, loaded, 1, NULL, &side, &err), &err);

    expect_refused(ctx, "\"size_m\": [0.6, 0.05, 0.5]", "\"size_m\": [0.7, 0.05, 0.5]", fired, map,
                   "another scene geometry (objects or meshes differ from other.json)");
    expect_refused(ctx, "\"frequency_thz\": 0.9", "\"frequency_thz\": 0.8", loaded, map,
                   "another channel set (frequencies, widths or responses differ");
    expect_refused(ctx, "\"temperature_k\": 310", "\"temperature_k\": 320", fired, map,
                   "another scene (materials, temperatures or atmosphere differ");

    /* The runs hold nothing of the photons or of the scene they were made for: both gone
     * (photons first: they borrow their scene), the images are still whole. */
    thz_photons_destroy(fired);
    thz_photons_destroy(loaded);
    thz_scene_destroy(scene1);
    CHECK(thz_run_image_count(from_fired) == 2 && thz_run_image_count(from_loaded) == 2,
          "%zu and %zu images", thz_run_image_count(from_fired), thz_run_image_count(from_loaded));
    for (size_t i = 0; i < thz_run_image_count(from_fired); i++) {
        test_compare_image_files(thz_run_image(from_fired, i), cli);
        test_compare_image_files(thz_run_image(from_loaded, i), cli);
    }
    test_compare_image_files(side, cli);
    CHECK(!strcmp(thz_image_sensor_name(side), "side"), "sensor %s", thz_image_sensor_name(side));
    thz_run_totals t;
    thz_run_get_totals(from_loaded, &t);
    CHECK(t.photons_fired == 0 && t.n_sensors == 2, "%llu photons fired, %zu sensors",
          (unsigned long long)t.photons_fired, t.n_sensors);
    const char *summary = thz_run_summary_json(from_fired);
    CHECK(summary && strstr(summary, "\"photons_per_channel\": 6000,"), "summary: %.200s",
          summary ? strstr(summary, "photons_per_channel") : "(none)");

    thz_image_destroy(side);
    thz_run_destroy(from_fired);
    thz_run_destroy(from_loaded);
    thz_scene_destroy(scene2);
    thz_context_destroy(ctx);
    free(text2);
    return test_finish(argv[0], dir);
}
