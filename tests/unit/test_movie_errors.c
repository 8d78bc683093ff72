/* A movie that cannot be written is reported under its own name (OUTDIR/S.band-NN.mp4),
 * as every other write failure is (docs/reliability.md), not under the hidden temporary
 * file it is encoded into (.S.band-NN.mp4.part), which is deleted by then. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <string.h>

#include "batch/batch_internal.h"

static void test_cannot_create_names_the_movie(void **state)
{
    (void)state;
    movie_spec spec = {.path = "/nonexistent-thzmap-dir/cam.band-01.mp4",
                       .columns = 16,
                       .rows = 12,
                       .fps = 4.0,
                       .tb_min_k = 290.0,
                       .tb_max_k = 310.0};
    movie_writer *m = NULL;
    thz_error err = {0};
    thz_status st = movie_open(&spec, &m, &err);
    movie_destroy(m);
    assert_int_not_equal(st, THZ_OK);
    assert_non_null(strstr(err.message, "/nonexistent-thzmap-dir/cam.band-01.mp4: "));
    assert_null(strstr(err.message, ".part"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cannot_create_names_the_movie),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
