/* What the scene loader's unit tests share (test_scene_load.c, test_scene_load_air.c,
 * test_channel_load.c): loading a scene from a JSON string that must load or must be refused with a
 * message, counting a scene's warnings, and the pieces of a small valid scene. Header-only (static
 * inline), as tests/physics/photon_scenes.h. */
#ifndef THZ_TESTS_SCENE_LOAD_HELPERS_H
#define THZ_TESTS_SCENE_LOAD_HELPERS_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "scene/scene.h"

#define SRC THZ_SOURCE_DIR

/* The scene of json, relative paths from tests/inputs/scenes, its file "test.json"; a
 * refusal fails the test. */
static inline thz_scene *load_ok(const char *json)
{
    thz_scene *s = NULL;
    thz_error err = {0};
    thz_status st = scene_load_string(json, SRC "/tests/inputs/scenes", "test.json", &s, &err);
    if (st != THZ_OK)
        fail_msg("refused: %s", err.message);
    return s;
}

/* json is refused as bad input, with expect in a message that starts with the file name. */
static inline void load_bad(const char *json, const char *expect)
{
    thz_scene *s = (thz_scene *)1;
    thz_error err = {0};
    assert_int_equal(scene_load_string(json, SRC "/tests/inputs/scenes", "test.json", &s, &err),
                     THZ_ERR_INPUT);
    assert_null(s);
    if (!strstr(err.message, expect))
        fail_msg("message '%s' lacks '%s'", err.message, expect);
    if (strncmp(err.message, "test.json", 9) != 0)
        fail_msg("message '%s' does not start with the file name", err.message);
}

/* The pieces of a small valid scene: one channel, material, box and camera. */
#define HEAD "{\"format\": \"thzmap-scene/1\", "
#define CHANNELS "\"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.01}], "
#define MATERIALS "\"materials\": {\"m\": {\"reflectivity\": 0.1}}, "
#define OBJECT(shape)                                                                              \
    "\"objects\": [{\"name\": \"o\", \"type\": \"solid\", \"material\": \"m\", "                   \
    "\"temperature_k\": 300, \"shape\": " shape "}], "
#define SENSORS                                                                                    \
    "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], \"look_at_m\": [0, 0, 0], "       \
    "\"fov_deg\": 40, \"resolution\": [16, 8]}]"
#define BOX "{\"type\": \"box\", \"size_m\": [1, 1, 1]}"

/* How many warnings of json's scene hold a (and b, unless NULL). */
static inline size_t load_count_warnings(const char *json, const char *a, const char *b)
{
    thz_scene *s = load_ok(json);
    size_t n = 0;
    for (size_t i = 0; i < s->n_warnings; i++)
        n += strstr(s->warnings[i], a) && (!b || strstr(s->warnings[i], b));
    thz_scene_destroy(s);
    return n;
}

#endif
