/* thz_path_join: "dir/name" when it fits, an error naming the path and the limit when it
 * does not (never a silently cut path). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <string.h>

#include "core/path.h"

static void test_join(void **state)
{
    (void)state;
    char out[THZ_PATH_MAX];
    thz_error err = {0};
    assert_int_equal(thz_path_join(out, sizeof out, "out", "cam.radiance.hdr", &err), THZ_OK);
    assert_string_equal(out, "out/cam.radiance.hdr");
    assert_int_equal(thz_path_join(out, sizeof out, "/tmp/", "a", &err), THZ_OK);
    assert_string_equal(out, "/tmp/a"); /* no doubled '/' */
    assert_int_equal(thz_path_join(out, sizeof out, "/", "a", &err), THZ_OK);
    assert_string_equal(out, "/a");
    assert_int_equal(thz_path_join(out, sizeof out, "", "a", NULL), THZ_OK);
    assert_string_equal(out, "a");
}

/* Exactly size - 1 characters fit; one more is an error that names path and limit. */
static void test_limit(void **state)
{
    (void)state;
    char out[8];
    thz_error err = {0};
    assert_int_equal(thz_path_join(out, sizeof out, "abc", "def", &err), THZ_OK);
    assert_string_equal(out, "abc/def");
    assert_int_equal(thz_path_join(out, sizeof out, "abc", "defg", &err), THZ_ERR_INPUT);
    assert_string_equal(out, "");
    assert_int_equal(err.status, THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "abc/defg"));
    assert_non_null(strstr(err.message, "8 bytes"));     /* its length */
    assert_non_null(strstr(err.message, "limit of 7 ")); /* the longest that fits */
    assert_int_equal(thz_path_join(out, sizeof out, "abc", "defg", NULL), THZ_ERR_INPUT);
}

/* A long OUTDIR: the whole buffer, not a truncated prefix, decides. */
static void test_long_dir(void **state)
{
    (void)state;
    static char dir[THZ_PATH_MAX];
    memset(dir, 'd', sizeof dir - 8);
    dir[sizeof dir - 8] = '\0';
    char out[THZ_PATH_MAX];
    assert_int_equal(thz_path_join(out, sizeof out, dir, "a.img", NULL), THZ_OK);
    assert_int_equal(strlen(out), THZ_PATH_MAX - 2);
    thz_error err = {0};
    assert_int_equal(thz_path_join(out, sizeof out, dir, "abc.img", &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "limit of 4095 bytes"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_join),
        cmocka_unit_test(test_limit),
        cmocka_unit_test(test_long_dir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
