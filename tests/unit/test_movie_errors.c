/* A movie that cannot be written is reported under its own name (OUTDIR/S.band-NN.mp4),
 * as every other write failure is (docs/reliability.md), not under the hidden temporary
 * file it is encoded into (.S.band-NN.mp4.part), which is deleted by then; so is the
 * temporary file of a movie abandoned half-way (a batch cancelled while it encodes). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

/* A movie in a fresh directory of the temporary one: its path and its temporary file's. */
static void movie_paths(char *dir, size_t dir_size, char *path, char *part, size_t size)
{
    const char *base = getenv("TMPDIR");
    snprintf(dir, dir_size, "%s/thz-test-movie-XXXXXX", base && *base ? base : "/tmp");
    assert_non_null(mkdtemp(dir));
    snprintf(path, size, "%s/cam.band-01.mp4", dir);
    snprintf(part, size, "%s/.cam.band-01.mp4.part", dir);
}

static thz_status movie_two_frames(const char *path, movie_writer **m, thz_error *err)
{
    static float tb[16 * 12];
    for (size_t i = 0; i < sizeof tb / sizeof tb[0]; i++)
        tb[i] = 290.0f + (float)(i % 20);
    movie_spec spec = {
        .path = path, .columns = 16, .rows = 12, .fps = 4.0, .tb_min_k = 290.0, .tb_max_k = 310.0};
    thz_status st = movie_open(&spec, m, err);
    for (int f = 0; st == THZ_OK && f < 2; f++)
        st = movie_add_frame(*m, tb, 0.25 * f, err);
    return st;
}

/* Abandoned after two frames: no temporary file, no movie. */
static void test_abandoned_movie_leaves_nothing(void **state)
{
    (void)state;
    char dir[512], path[600], part[600];
    movie_paths(dir, sizeof dir, path, part, sizeof path);
    movie_writer *m = NULL;
    thz_error err = {0};
    assert_int_equal(movie_two_frames(path, &m, &err), THZ_OK);
    assert_int_equal(access(part, F_OK), 0); /* (encoding into it) */
    movie_destroy(m);
    assert_int_not_equal(access(part, F_OK), 0);
    assert_int_not_equal(access(path, F_OK), 0);
    assert_int_equal(rmdir(dir), 0); /* empty */
}

/* Its name taken by a directory that is not empty: the rename fails, said under the
 * movie's name, and the temporary file goes. */
static void test_rename_failure_leaves_no_part(void **state)
{
    (void)state;
    char dir[512], path[600], part[600], inside[700];
    movie_paths(dir, sizeof dir, path, part, sizeof path);
    assert_int_equal(mkdir(path, 0755), 0);
    snprintf(inside, sizeof inside, "%s/keep", path);
    FILE *f = fopen(inside, "w");
    assert_non_null(f);
    fclose(f);
    movie_writer *m = NULL;
    thz_error err = {0};
    assert_int_equal(movie_two_frames(path, &m, &err), THZ_OK);
    thz_status st = movie_finish(m, &err);
    movie_destroy(m);
    assert_int_equal(st, THZ_ERR_IO);
    assert_non_null(strstr(err.message, "cam.band-01.mp4: cannot rename into place"));
    assert_int_not_equal(access(part, F_OK), 0);
    assert_int_equal(unlink(inside), 0);
    assert_int_equal(rmdir(path), 0);
    assert_int_equal(rmdir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cannot_create_names_the_movie),
        cmocka_unit_test(test_abandoned_movie_leaves_nothing),
        cmocka_unit_test(test_rename_failure_leaves_no_part),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
