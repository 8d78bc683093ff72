/* Atomic results: files written into the stage appear in OUTDIR only on commit, and a
 * destroyed stage leaves nothing behind (scene-format.md "A failed run leaves no
 * partial output files"). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/alloc.h"
#include "io/output.h"

static char *make_tmp_dir(void)
{
    const char *base = getenv("TMPDIR");
    char templ[512];
    snprintf(templ, sizeof templ, "%s/thz-test-stage-XXXXXX", base && *base ? base : "/tmp");
    char *d = mkdtemp(templ);
    assert_non_null(d);
    return thz_strdup(d);
}

/* Number of entries in dir other than . and .. (-1 if it cannot be read). */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    closedir(d);
    return n;
}

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void assert_file_text(const char *dir, const char *name, const char *text)
{
    char path[1024], buf[256] = {0};
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("missing %s", path);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    assert_string_equal(buf, text);
}

static void rm(const char *dir, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
}

static void test_commit_moves_files(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/a/b/out", tmp); /* parents are created too */
    output_stage *stage = NULL;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_OK);
    const char *sdir = output_stage_dir(stage);
    assert_non_null(strstr(sdir, "/.thzmap-staging-"));
    assert_int_equal(strncmp(sdir, outdir, strlen(outdir)), 0);

    write_file(outdir, "old.txt", "previous run");
    write_file(outdir, "x.hdr", "old");
    write_file(sdir, "x.hdr", "new");
    write_file(sdir, "x.img", "data");
    /* Before commit OUTDIR shows no new file: only the old ones and the stage. */
    assert_int_equal(count_entries(outdir), 3);
    assert_file_text(outdir, "x.hdr", "old");

    assert_int_equal(output_stage_commit(stage, &err), THZ_OK);
    assert_file_text(outdir, "x.hdr", "new"); /* replaced */
    assert_file_text(outdir, "x.img", "data");
    assert_file_text(outdir, "old.txt", "previous run");
    assert_int_equal(count_entries(outdir), 3); /* the stage is gone */
    output_stage_destroy(stage);                /* after commit: removes nothing */
    assert_int_equal(count_entries(outdir), 3);

    rm(outdir, "x.hdr");
    rm(outdir, "x.img");
    rm(outdir, "old.txt");
    rmdir(outdir);
    char p[1024];
    snprintf(p, sizeof p, "%s/a/b", tmp);
    rmdir(p);
    snprintf(p, sizeof p, "%s/a", tmp);
    rmdir(p);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

static void test_destroy_leaves_nothing(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    output_stage *stage = NULL;
    thz_error err = {0};
    assert_int_equal(output_stage_create(tmp, &stage, &err), THZ_OK);
    write_file(output_stage_dir(stage), "half.img", "partial");
    write_file(output_stage_dir(stage), "summary.json", "{}");
    assert_int_equal(count_entries(tmp), 1);
    output_stage_destroy(stage);
    assert_int_equal(count_entries(tmp), 0);
    output_stage_destroy(NULL);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* Two stages in one OUTDIR (one process) get different directories. */
static void test_two_stages(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    output_stage *a = NULL, *b = NULL;
    assert_int_equal(output_stage_create(tmp, &a, NULL), THZ_OK);
    assert_int_equal(output_stage_create(tmp, &b, NULL), THZ_OK);
    assert_string_not_equal(output_stage_dir(a), output_stage_dir(b));
    output_stage_destroy(a);
    output_stage_destroy(b);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* OUTDIR under a regular file cannot be made: an I/O error naming the path. */
static void test_bad_outdir(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    write_file(tmp, "file", "x");
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/file/out", tmp);
    output_stage *stage = (output_stage *)&stage;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_ERR_IO);
    assert_null(stage);
    assert_non_null(strstr(err.message, "/file"));
    rm(tmp, "file");
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_commit_moves_files),
        cmocka_unit_test(test_destroy_leaves_nothing),
        cmocka_unit_test(test_two_stages),
        cmocka_unit_test(test_bad_outdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
