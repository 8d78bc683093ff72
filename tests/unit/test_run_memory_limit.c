/* The refusal of a scene whose images would not fit (run_check_scene_memory) names the
 * limit for what it is: under `ulimit -v` (RLIMIT_AS) it is the process's address space,
 * not the machine's memory. With `prlimit --as=4G` on a machine of 23.5 GiB the message
 * said "more than this machine's memory (4.0 GiB) allows". And a run refused for the
 * images of all its sensors together (run_check_memory) names the number of sensors
 * among what to lower: 120 sensors of 1024 x 1024 pixels (9.4 GiB) were told "lower
 * sensors[0].resolution", which alone would not have made them fit. The photon passes
 * of photon-map towards a noise target stop at half the memory the process may have, not
 * half the machine's: under `prlimit --as=1G` on 23.5 GiB they were allowed 11.7 GiB
 * ("memory 11.7 GiB of 1 GiB") and the run ended "out of memory" after 12 s of passes.
 * A render whose photon map file does not fit names that map's photons, not the scene's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

#include "run/run.h"
#include "scene/scene.h"
#include "sensor/images.h"

/* AddressSanitizer reserves terabytes of address space and maps more as it goes: under
 * an RLIMIT_AS of 1 GiB its own mmap fails ("Failed to mmap") and it ends the process. */
#if defined(__SANITIZE_ADDRESS__)
#define TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TEST_ASAN 1
#endif
#endif
#ifndef TEST_ASAN
#define TEST_ASAN 0
#endif

/* 1024 x 1024 pixels in 100 channels: about 2 GiB of images; a second sensor if two */
static thz_scene *load_large(bool two)
{
    char json[2048];
    const char *second = two ? ", {\"name\": \"cam2\", \"position_m\": [0, 0, 0],"
                               " \"look_at_m\": [1, 0, 0], \"fov_deg\": 50,"
                               " \"resolution\": [64, 64]}"
                             : "";
    int n =
        snprintf(json, sizeof json,
                 "{\"format\": \"thzmap-scene/1\","
                 " \"channels\": {\"from_thz\": 0.2, \"to_thz\": 1.2, \"count\": 100,"
                 "   \"relative_width\": 0.01},"
                 " \"materials\": {\"wall\": {\"reflectivity\": 0.3}},"
                 " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": "
                 "\"wall\", \"temperature_k\": 300,"
                 "   \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}}],"
                 " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, 0, 0],"
                 "   \"look_at_m\": [0, 1, 0], \"fov_deg\": 50, \"resolution\": [1024, 1024]}%s]}",
                 second);
    assert_true(n > 0 && (size_t)n < sizeof json);
    thz_scene *s = NULL;
    thz_error err;
    if (scene_load_string(json, ".", "memory-limit-unit", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    return s;
}

static void test_refusal_under_address_space_limit(void **state)
{
    (void)state;
    if (TEST_ASAN)
        skip();
    thz_scene *s = load_large(false);
    struct rlimit before;
    assert_int_equal(getrlimit(RLIMIT_AS, &before), 0);
    struct rlimit one_gib = {.rlim_cur = (rlim_t)1 << 30, .rlim_max = before.rlim_max};
    if (before.rlim_max != RLIM_INFINITY && before.rlim_max < one_gib.rlim_cur)
        one_gib.rlim_cur = before.rlim_max;
    assert_int_equal(setrlimit(RLIMIT_AS, &one_gib), 0);
    thz_error err;
    thz_error_clear(&err);
    thz_status st = run_check_scene_memory(s, &err);
    assert_int_equal(setrlimit(RLIMIT_AS, &before), 0);
    assert_int_not_equal(st, THZ_OK);
    assert_non_null(strstr(err.message, "sensors[0].resolution"));
    assert_non_null(strstr(err.message, "ulimit -v"));
    assert_null(strstr(err.message, "this machine's memory"));
    scene_destroy(s);
}

/* What to lower, with one sensor and with two, when the images are what does not fit. */
static const char *refusal(bool two, char *buf, size_t size)
{
    thz_scene *s = load_large(two);
    run_memory need = {.image_bytes = (uint64_t)3 << 30, .held_bytes = (uint64_t)20 << 20};
    need.total_bytes = need.image_bytes + need.held_bytes;
    need.available_bytes = (uint64_t)1 << 30;
    thz_error err;
    thz_error_clear(&err);
    assert_int_not_equal(run_check_memory(s, &need, &err), THZ_OK);
    snprintf(buf, size, "%s", err.message);
    scene_destroy(s);
    return buf;
}

static void test_images_of_several_sensors(void **state)
{
    (void)state;
    char one[1024], two[1024];
    assert_non_null(strstr(refusal(false, one, sizeof one), "lower sensors[0].resolution"));
    assert_null(strstr(one, "number of sensors"));
    assert_non_null(strstr(refusal(true, two, sizeof two), "lower sensors[0].resolution"));
    assert_non_null(strstr(two, "number of sensors"));
}

/* The photon maps not fitting: the scene key to lower, with the count that fits, and no
 * CLI option (it said "or --photons", which neither batch nor Python has; simulate adds
 * it to the message itself). */
static void test_photons_refusal_names_the_scene_key(void **state)
{
    (void)state;
    thz_scene *s = load_large(false);
    s->photons.per_channel = 1000000000;
    run_memory need = {.photon_bytes = (uint64_t)64 << 30,
                       .image_bytes = (uint64_t)1 << 20,
                       .held_bytes = (uint64_t)20 << 20};
    need.total_bytes = need.photon_bytes + need.image_bytes + need.held_bytes;
    need.available_bytes = (uint64_t)4 << 30;
    thz_error err;
    thz_error_clear(&err);
    assert_int_equal(run_check_memory(s, &need, &err), THZ_ERR_LIMIT);
    assert_non_null(strstr(err.message, "; lower photons.per_channel (now 1000000000; at most "
                                        "about "));
    assert_true(err.message[strlen(err.message) - 1] == ')');
    assert_null(strstr(err.message, "--photons"));
    scene_destroy(s);
}

/* A render's map read from a file not fitting: the scene's photons.per_channel did not
 * make that map, the map's own count did. `thzmap render --photon-map` of a map of 2e7
 * photons a channel, under ulimit -v 400000, was told "lower photons.per_channel (now
 * 300000; at most about 150000 fit)": the scene's key, and a count scaled from it. */
static void test_read_map_refusal_names_the_map(void **state)
{
    (void)state;
    thz_scene *s = load_large(false);
    s->photons.per_channel = 300000;
    run_memory need = {.photon_bytes = (uint64_t)64 << 30,
                       .image_bytes = (uint64_t)1 << 20,
                       .held_bytes = (uint64_t)20 << 20,
                       .map_photons = 1000000000};
    need.total_bytes = need.photon_bytes + need.image_bytes + need.held_bytes;
    need.available_bytes = (uint64_t)4 << 30;
    thz_error err;
    thz_error_clear(&err);
    assert_int_equal(run_check_memory(s, &need, &err), THZ_ERR_LIMIT);
    /* room 0.9 x 4096 - 21 MiB for 65536 MiB of 1e9 photons, less 3 %: 5.43e7, rounded
     * down to two digits */
    assert_non_null(strstr(err.message, "; render from a map of fewer photons (this one has "
                                        "1000000000 per channel, read a channel at a time; "
                                        "at most about 54000000 fit)"));
    assert_null(strstr(err.message, "photons.per_channel"));
    scene_destroy(s);
}

/* Under ulimit -v the address space mapped counts, not the resident set: a render of a
 * 10^6-photon map under ulimit -v 250000 had 18 MB resident and 291 MB mapped (Embree's
 * pool, thread stacks, arenas) at the check, passed it and failed reading the map. The
 * figures of that render: 35 MiB of map, 1 MiB of images, 220 MiB mapped, 244 MiB limit.
 * Refused naming the limit in KiB and the limit that would do: (220 + 36) / 0.9 MiB and
 * 16 MiB to spare, in 4 MiB steps (311296 KiB). */
static void test_address_space_mapped_counts(void **state)
{
    (void)state;
    thz_scene *s = load_large(false);
    const uint64_t mib = (uint64_t)1 << 20;
    run_memory need = {.photon_bytes = 35 * mib,
                       .image_bytes = 1 * mib,
                       .held_bytes = 18 * mib,
                       .map_photons = 1000000,
                       .mapped_bytes = 220 * mib,
                       .available_bytes = 250000u * 1024u};
    need.total_bytes = need.photon_bytes + need.image_bytes + need.held_bytes;
    thz_error err;
    thz_error_clear(&err);
    /* the resident set alone fits: the check as it was let it run */
    assert_int_equal(run_check_memory(s, &need, &err), THZ_OK);
    need.address_limit_bytes = 250000u * 1024u;
    assert_int_equal(run_check_memory(s, &need, &err), THZ_ERR_LIMIT);
    assert_non_null(strstr(err.message, "the run would need 256 MiB of address space"));
    assert_non_null(strstr(err.message, "ulimit -v limits this process to 250000 KiB (244 MiB)"));
    assert_non_null(strstr(err.message, "(ulimit -v 311296 or more would do)"));
    assert_non_null(strstr(err.message, "render from a map of fewer photons"));
    /* under the limit it names, it passes */
    need.address_limit_bytes = need.available_bytes = 311296u * 1024u;
    assert_int_equal(run_check_memory(s, &need, &err), THZ_OK);
    scene_destroy(s);
}

static void test_passes_limit_under_address_space_limit(void **state)
{
    (void)state;
    if (TEST_ASAN)
        skip();
    struct rlimit before;
    assert_int_equal(getrlimit(RLIMIT_AS, &before), 0);
    struct rlimit one_gib = {.rlim_cur = (rlim_t)1 << 30, .rlim_max = before.rlim_max};
    if (before.rlim_max != RLIM_INFINITY && before.rlim_max < one_gib.rlim_cur)
        one_gib.rlim_cur = before.rlim_max;
    assert_int_equal(setrlimit(RLIMIT_AS, &one_gib), 0);
    double limit = run_passes_memory_limit_bytes();
    assert_int_equal(setrlimit(RLIMIT_AS, &before), 0);
    assert_true(limit > 0.0 && limit <= 0.5 * (double)one_gib.rlim_cur);
}

/* The images' bytes the memory checks count (sensor_images_bytes) are those a run's
 * images hold: every plane sensor_images_alloc gives, the standard error's cube with them
 * (a run always has it). Counted as 4 cubes a channel instead of 5, the check and the
 * estimate's "images and tables" were a sixth short of what the cubes then took. */
static void test_image_bytes_are_the_planes(void **state)
{
    (void)state;
    const uint32_t columns = 7, rows = 5;
    const size_t channels = 3;
    sensor_images img;
    thz_error err;
    assert_int_equal(sensor_images_alloc(&img, columns, rows, channels, 1, &err), THZ_OK);
    uint64_t px = (uint64_t)columns * rows, cube = px * channels, held = 0;
    const void *cubes[] = {img.radiance, img.radiance_stderr, img.power, img.brightness_temperature,
                           img.normalized};
    for (size_t k = 0; k < sizeof cubes / sizeof *cubes; k++) {
        assert_non_null(cubes[k]);
        held += cube * sizeof(float);
    }
    assert_non_null(img.temperature_k);
    assert_non_null(img.distance_m);
    assert_non_null(img.object_id);
    assert_non_null(img.visual_rgb);
    held += px * (sizeof *img.temperature_k + sizeof *img.distance_m + sizeof *img.object_id +
                  3 * sizeof *img.visual_rgb);
    assert_int_equal(sensor_images_bytes(columns, rows, channels), held);
    sensor_images_fini(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refusal_under_address_space_limit),
        cmocka_unit_test(test_images_of_several_sensors),
        cmocka_unit_test(test_photons_refusal_names_the_scene_key),
        cmocka_unit_test(test_read_map_refusal_names_the_map),
        cmocka_unit_test(test_address_space_mapped_counts),
        cmocka_unit_test(test_passes_limit_under_address_space_limit),
        cmocka_unit_test(test_image_bytes_are_the_planes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
