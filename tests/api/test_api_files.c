/* thz_file_identify tells thzmap's files apart without loading them: a scene (either
 * format name, even an invalid scene), a sequence, a photon-map file (one the library
 * saved, and a file of only its 8-byte magic), and everything else as "other" (a PLY
 * mesh, JSON of another format or none, an empty file); a directory, a missing file and
 * a FIFO are refused without blocking. And a scene loader given a file of another kind
 * says what the file is.
 * argv: the thzmap binary (unused), the repository. */
#include <sys/stat.h>

#include "api_test.h"

static void expect_kind(const char *dir, const char *name, const char *text, thz_file_kind expected)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (text)
        test_write_file(path, text);
    thz_error err = {0};
    thz_file_kind kind = (thz_file_kind)99;
    thz_status st = thz_file_identify(path, &kind, &err);
    CHECK(st == THZ_OK && kind == expected, "%s: status %d (%s), kind %d, expected kind %d", name,
          (int)st, err.message, (int)kind, (int)expected);
}

static void expect_refused(const char *path, const char *words)
{
    thz_error err = {0};
    thz_file_kind kind = THZ_FILE_SCENE;
    thz_status st = thz_file_identify(path, &kind, &err);
    CHECK(st == THZ_ERR_INPUT && kind == THZ_FILE_OTHER && strstr(err.message, words),
          "%s: status %d, kind %d, message \"%s\" (expected \"%s\")", path, (int)st, (int)kind,
          err.message, words);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    char dir[4096], path[4200];
    test_temp_dir(dir, sizeof dir);

    expect_kind(dir, "scene.json", test_scene_json, THZ_FILE_SCENE);
    expect_kind(dir, "scene11.json", "{\"format\": \"thzmap-scene/1.1\"}", THZ_FILE_SCENE);
    expect_kind(dir, "sequence.json",
                "{\"scene\": \"scene.json\", \"format\": \"thzmap-sequence/1\", \"frames\": 2}",
                THZ_FILE_SEQUENCE);
    expect_kind(dir, "batch.json", "{\"format\": \"thzmap-batch/1\"}", THZ_FILE_OTHER);
    expect_kind(dir, "format-number.json", "{\"format\": 1}", THZ_FILE_OTHER);
    expect_kind(dir, "array.json", "[\"thzmap-scene/1\"]", THZ_FILE_OTHER);
    expect_kind(dir, "broken.json", "{\"format\": \"thzmap-scene/1\",", THZ_FILE_OTHER);
    expect_kind(dir, "mesh.ply", "ply\nformat ascii 1.0\nend_header\n", THZ_FILE_OTHER);
    expect_kind(dir, "empty", "", THZ_FILE_OTHER);
    expect_kind(dir, "magic.thzpm", "THZPMAP\x1a", THZ_FILE_PHOTON_MAP);

    /* a photon map the library saved */
    thz_error err = {0};
    thz_scene *scene = NULL;
    thz_photons *photons = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, NULL, &scene, &err), &err);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.photons_per_channel = 200;
    thz_context *ctx = thz_context_create();
    snprintf(path, sizeof path, "%s/map.thzpm", dir);
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &photons, &err), &err);
    REQUIRE_OK(thz_photons_save(photons, path, &err), &err);
    expect_kind(dir, "map.thzpm", NULL, THZ_FILE_PHOTON_MAP);
    thz_photons_destroy(photons);
    thz_context_destroy(ctx);

    /* the scene loader given it says what it is */
    thz_scene *wrong = NULL;
    CHECK(thz_scene_load(path, &wrong, &err) == THZ_ERR_INPUT && !wrong &&
              strstr(err.message, "invalid JSON") &&
              strstr(err.message, "(the file is a photon-map file, which `thzmap render "
                                  "--photon-map` reads)"),
          "the scene loader given a photon map: %s", err.message);
    snprintf(path, sizeof path, "%s/mesh.ply", dir);
    CHECK(thz_scene_load(path, &wrong, &err) == THZ_ERR_INPUT &&
              strstr(err.message, "(the file is a PLY mesh, which a scene names in a "
                                  "shape's \"file\", {\"type\": \"mesh\", \"file\": ...})"),
          "the scene loader given a PLY mesh: %s", err.message);
    snprintf(path, sizeof path, "%s/broken.json", dir);
    CHECK(thz_scene_load(path, &wrong, &err) == THZ_ERR_INPUT &&
              !strstr(err.message, "the file is"),
          "the scene loader given broken JSON names a kind: %s", err.message);
    thz_scene_destroy(scene);

    /* refused, not blocked on */
    expect_refused(dir, "is a directory");
    snprintf(path, sizeof path, "%s/missing.json", dir);
    expect_refused(path, "cannot open");
    snprintf(path, sizeof path, "%s/fifo", dir);
    CHECK(mkfifo(path, 0600) == 0, "mkfifo %s", path);
    expect_refused(path, "FIFO");
    thz_file_kind kind;
    CHECK(thz_file_identify(NULL, &kind, &err) == THZ_ERR_INPUT && kind == THZ_FILE_OTHER,
          "a NULL path: not refused");
    CHECK(thz_file_identify(dir, NULL, &err) == THZ_ERR_INPUT, "a NULL kind: not refused");

    return test_finish(argv[0], dir);
}
