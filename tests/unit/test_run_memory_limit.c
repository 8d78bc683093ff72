/* The refusal of a scene whose images would not fit (run_check_scene_memory) names the
 * limit for what it is: under `ulimit -v` (RLIMIT_AS) it is the process's address space,
 * not the machine's memory. With `prlimit --as=4G` on a machine of 23.5 GiB the message
 * said "more than this machine's memory (4.0 GiB) allows". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

#include "run/run.h"
#include "scene/scene.h"

/* 1024 x 1024 pixels in 100 channels: about 2 GiB of images */
static thz_scene *load_large(void)
{
    char json[2048];
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
                 "   \"look_at_m\": [0, 1, 0], \"fov_deg\": 50, \"resolution\": [1024, 1024]}]}");
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
    thz_scene *s = load_large();
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refusal_under_address_space_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
