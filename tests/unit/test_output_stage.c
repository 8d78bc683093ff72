/* Run-level outputs. Atomic results: files written into the stage appear in OUTDIR only
 * on commit, and a destroyed stage leaves nothing behind (scene-format.md "A failed run
 * leaves no partial output files"). (summary.json: test_summary_json.c.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <errno.h>
#include <string.h>
#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <stdbool.h>
#include <unistd.h>

#include "core/alloc.h"
#include "io/output.h"
#include "scene/scene.h"

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
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void assert_file_text(const char *dir, const char *name, const char *text)
{
    char path[4096], buf[256] = {0};
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
    char path[4096];
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
    char parent[1024];
    snprintf(parent, sizeof parent, "%s/a/b/.thzmap-", tmp); /* beside OUTDIR */
    assert_int_equal(strncmp(sdir, parent, strlen(parent)), 0);
    assert_int_equal(mkdir(outdir, 0777), 0); /* an earlier run's OUTDIR */

    write_file(outdir, "old.txt", "previous run");
    write_file(outdir, "x.hdr", "old");
    write_file(sdir, "x.hdr", "new");
    write_file(sdir, "x.img", "data");
    /* Before commit OUTDIR shows no new file: only the old ones. */
    assert_int_equal(count_entries(outdir), 2);
    assert_file_text(outdir, "x.hdr", "old");

    assert_int_equal(output_stage_commit(stage, &err), THZ_OK);
    assert_file_text(outdir, "x.hdr", "new"); /* replaced */
    assert_file_text(outdir, "x.img", "data");
    assert_file_text(outdir, "old.txt", "previous run");
    assert_int_equal(count_entries(outdir), 3);
    output_stage_destroy(stage); /* after commit: removes nothing but the lock */
    assert_int_equal(count_entries(outdir), 3);
    snprintf(parent, sizeof parent, "%s/a/b", tmp);
    assert_int_equal(count_entries(parent), 1); /* OUTDIR alone: no stage, no lock */

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

/* A commit that fails half-way (the last file, in name order, meets a non-empty
 * directory of its name in OUTDIR, after three files were moved in, two of them
 * replacing old ones) is undone: OUTDIR holds exactly the old files again. Both ways of
 * committing: the directories exchanged, and file by file where OUTDIR is the working
 * directory (or a mount point), whose undoing no test reached before (a helper's mutant
 * left the new c.json in OUTDIR and passed). */
static void failed_commit_rolls_back(bool in_cwd)
{
    char *outdir = make_tmp_dir();
    char cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    if (in_cwd)
        assert_int_equal(chdir(outdir), 0);
    write_file(outdir, "a.hdr", "old a");
    write_file(outdir, "b.img", "old b");
    write_file(outdir, "keep.txt", "not ours");
    char sub[512];
    snprintf(sub, sizeof sub, "%s/z.png", outdir);
    assert_int_equal(mkdir(sub, 0777), 0);
    write_file(sub, "inner", "user data");

    output_stage *stage = NULL;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_OK);
    const char *sdir = output_stage_dir(stage);
    write_file(sdir, "a.hdr", "new a");
    write_file(sdir, "b.img", "new b");
    write_file(sdir, "c.json", "new c"); /* no old file of this name */
    write_file(sdir, "z.png", "new z");  /* last: OUTDIR/z.png is a directory */

    assert_int_equal(output_stage_commit(stage, &err), THZ_ERR_IO);
    assert_non_null(strstr(err.message, "z.png"));
    assert_non_null(strstr(err.message, "previous results stay"));
    output_stage_destroy(stage);
    if (in_cwd)
        assert_int_equal(chdir(cwd), 0);

    assert_int_equal(count_entries(outdir), 4); /* a.hdr b.img keep.txt z.png/, no stage */
    assert_file_text(outdir, "a.hdr", "old a");
    assert_file_text(outdir, "b.img", "old b");
    assert_file_text(outdir, "keep.txt", "not ours");
    assert_int_equal(count_entries(sub), 1);
    assert_file_text(sub, "inner", "user data");
    char path[1024];
    snprintf(path, sizeof path, "%s/c.json", outdir);
    assert_int_not_equal(access(path, F_OK), 0);

    rm(sub, "inner");
    assert_int_equal(rmdir(sub), 0);
    rm(outdir, "a.hdr");
    rm(outdir, "b.img");
    rm(outdir, "keep.txt");
    assert_int_equal(rmdir(outdir), 0);
    free(outdir);
}

static void test_failed_commit_rolls_back(void **state)
{
    (void)state;
    failed_commit_rolls_back(false);
    failed_commit_rolls_back(true);
}

/* The commit leaves no hidden directory behind when it replaced files. */
static void test_commit_leaves_no_aside(void **state)
{
    (void)state;
    char *outdir = make_tmp_dir();
    write_file(outdir, "x.img", "old");
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(outdir, &stage, NULL), THZ_OK);
    write_file(output_stage_dir(stage), "x.img", "new");
    assert_int_equal(output_stage_commit(stage, NULL), THZ_OK);
    output_stage_destroy(stage);
    assert_int_equal(count_entries(outdir), 1);
    assert_file_text(outdir, "x.img", "new");
    rm(outdir, "x.img");
    assert_int_equal(rmdir(outdir), 0);
    free(outdir);
}

static void test_destroy_leaves_nothing(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    assert_int_equal(mkdir(outdir, 0777), 0);
    write_file(outdir, "x.img", "previous");
    output_stage *stage = NULL;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_OK);
    write_file(output_stage_dir(stage), "half.img", "partial");
    write_file(output_stage_dir(stage), "summary.json", "{}");
    assert_int_equal(count_entries(tmp), 3); /* OUTDIR, the stage, the lock */
    output_stage_destroy(stage);
    assert_int_equal(count_entries(tmp), 1);
    assert_int_equal(count_entries(outdir), 1);
    assert_file_text(outdir, "x.img", "previous");
    output_stage_destroy(NULL);
    rm(outdir, "x.img");
    assert_int_equal(rmdir(outdir), 0);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A failed run into a new OUTDIR leaves nothing: OUTDIR appears only on commit, and
 * the parents it created go again (not those that existed). */
static void test_destroy_removes_created_outdir(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[4096];
    snprintf(outdir, sizeof outdir, "%s/new/deeper/out", tmp);
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(outdir, &stage, NULL), THZ_OK);
    write_file(output_stage_dir(stage), "half.img", "partial");
    assert_int_equal(count_entries(tmp), 1);
    output_stage_destroy(stage);
    assert_int_equal(count_entries(tmp), 0); /* new/ gone, tmp kept */
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A second output into an OUTDIR in use is refused, saying why; once the first is done the
 * OUTDIR is free again (another process's run: tests/cli/test_commit_kill.sh). */
static void test_two_stages(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    output_stage *a = NULL, *b = (output_stage *)&b;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &a, NULL), THZ_OK);
    assert_int_equal(output_stage_create(outdir, &b, &err), THZ_ERR_IO);
    assert_null(b);
    /* both are this process's: it says so (it named its own pid as "another run"'s) */
    assert_non_null(strstr(err.message, "this process has an output open there already "
                                        "(another thread writing its results there, or an "
                                        "output not yet committed or destroyed)"));
    output_stage_destroy(a);
    assert_int_equal(output_stage_create(outdir, &b, NULL), THZ_OK);
    output_stage_destroy(b);
    assert_int_equal(count_entries(tmp), 0);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* What a killed run left beside OUTDIR is cleaned up by the next run: a stage never
 * committed (removed), and the old run of a swap whose user directory had not been
 * moved back yet (moved back, the rest removed); OUTDIR's own files are untouched. */
static void test_leftovers_cleaned(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024], p[1200];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    output_stage *a = NULL;
    assert_int_equal(output_stage_create(outdir, &a, NULL), THZ_OK);
    char first[1024];
    snprintf(first, sizeof first, "%s", output_stage_dir(a));
    output_stage_destroy(a);
    /* fake a killed run: its stage, holding a result file and a user's directory */
    assert_int_equal(mkdir(outdir, 0777), 0);
    write_file(outdir, "x.img", "current");
    assert_int_equal(mkdir(first, 0777), 0);
    write_file(first, "x.img", "stale");
    snprintf(p, sizeof p, "%s/subrun", first);
    assert_int_equal(mkdir(p, 0777), 0);
    write_file(p, "inner", "user data");
    assert_int_equal(count_entries(tmp), 2);

    assert_int_equal(output_stage_create(outdir, &a, NULL), THZ_OK);
    /* the leftover is gone (the new stage may reuse its name, empty) */
    assert_true(access(first, F_OK) != 0 || count_entries(first) == 0);
    output_stage_destroy(a);
    assert_int_equal(count_entries(tmp), 1);
    assert_file_text(outdir, "x.img", "current");
    snprintf(p, sizeof p, "%s/subrun", outdir);
    assert_file_text(p, "inner", "user data");
    rm(p, "inner");
    rmdir(p);
    rm(outdir, "x.img");
    rmdir(outdir);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A run killed between the two renames of the fallback for file systems that cannot
 * exchange (output_commit.c) left OUTDIR missing and the old run parked beside it as
 * PREFIX-old-PID-0: the next run puts it back as OUTDIR, whole. Not putting it back
 * (a mutant) passed every test: the user's results and files were gone from OUTDIR. */
static void test_parked_run_restored(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024], parked[1200];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    output_stage *a = NULL;
    assert_int_equal(output_stage_create(outdir, &a, NULL), THZ_OK);
    const char *stage = output_stage_dir(a);
    const char *at = NULL; /* the last "-stage-": the temporary directory's name has one */
    for (const char *q = strstr(stage, "-stage-"); q; q = strstr(q + 1, "-stage-"))
        at = q;
    assert_non_null(at);
    snprintf(parked, sizeof parked, "%.*s-old-99999-0", (int)(at - stage), stage);
    output_stage_destroy(a);
    if (mkdir(parked, 0777) != 0)
        fail_msg("%s: %s", parked, strerror(errno));
    write_file(parked, "cam.radiance.img", "previous run");
    write_file(parked, "notes.txt", "user data");
    assert_int_equal(access(outdir, F_OK), -1);

    assert_int_equal(output_stage_create(outdir, &a, NULL), THZ_OK);
    output_stage_destroy(a);
    assert_int_equal(access(parked, F_OK), -1);
    assert_file_text(outdir, "cam.radiance.img", "previous run");
    assert_file_text(outdir, "notes.txt", "user data");
    assert_int_equal(count_entries(tmp), 1);
    rm(outdir, "cam.radiance.img");
    rm(outdir, "notes.txt");
    rmdir(outdir);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* OUTDIR = the working directory is not swapped (a shell there would be left in a
 * deleted directory): the stage is inside it and the files move one by one. */
static void test_commit_into_working_directory(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char cwd[4096];
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(tmp), 0);
    write_file(".", "x.img", "old");
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(".", &stage, NULL), THZ_OK);
    assert_non_null(strstr(output_stage_dir(stage), "/.thzmap-staging-"));
    write_file(output_stage_dir(stage), "x.img", "new");
    assert_int_equal(output_stage_commit(stage, NULL), THZ_OK);
    output_stage_destroy(stage);
    assert_file_text(".", "x.img", "new");
    assert_int_equal(count_entries("."), 1);
    rm(".", "x.img");
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A run from inside OUTDIR (-o ., committed file by file) and a run from its parent (-o
 * out, swapped) take the same lock: the one that came second is refused. They took a
 * lock each (inside OUTDIR, and beside it), both ran, and each removed the other's stage
 * as a dead run's ("cannot create: No such file or directory"). */
static void test_working_directory_shares_the_lock(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char cwd[4096], outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    assert_int_equal(mkdir(outdir, 0777), 0);
    assert_non_null(getcwd(cwd, sizeof cwd));
    for (int first_inside = 0; first_inside < 2; first_inside++) {
        output_stage *a = NULL, *b = NULL;
        thz_error err = {0};
        assert_int_equal(chdir(first_inside ? outdir : tmp), 0);
        assert_int_equal(output_stage_create(first_inside ? "." : "out", &a, NULL), THZ_OK);
        assert_int_equal(chdir(first_inside ? tmp : outdir), 0);
        assert_int_equal(output_stage_create(first_inside ? "out" : ".", &b, &err), THZ_ERR_IO);
        assert_null(b);
        assert_non_null(strstr(err.message, "has an output open there already"));
        assert_int_equal(chdir(first_inside ? outdir : tmp), 0); /* a's paths are relative */
        assert_int_equal(access(output_stage_dir(a), F_OK), 0);  /* its stage is still there */
        output_stage_destroy(a);
        assert_int_equal(chdir(cwd), 0);
        assert_int_equal(count_entries(tmp), 1);
        assert_int_equal(count_entries(outdir), 0);
    }
    assert_int_equal(rmdir(outdir), 0);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* OUTDIR's subdirectories (another run's OUTDIR), foreign files and permissions survive a
 * commit. */
static void test_commit_keeps_subdirectories(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024], sub[1200];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    snprintf(sub, sizeof sub, "%s/path", outdir);
    assert_int_equal(mkdir(outdir, 0777), 0);
    assert_int_equal(mkdir(sub, 0777), 0);
    write_file(sub, "cam.img", "nested run");
    write_file(outdir, "notes.txt", "mine");
    /* a private OUTDIR stays private: the stage swapped in takes OUTDIR's permissions,
     * not the umask's (0710: a mode no umask gives) */
    assert_int_equal(chmod(outdir, 0710), 0);
    output_stage *stage = NULL;
    assert_int_equal(output_stage_create(outdir, &stage, NULL), THZ_OK);
    write_file(output_stage_dir(stage), "cam.img", "new");
    assert_int_equal(output_stage_commit(stage, NULL), THZ_OK);
    output_stage_destroy(stage);
    assert_int_equal(count_entries(tmp), 1);
    assert_int_equal(count_entries(outdir), 3);
    assert_file_text(outdir, "cam.img", "new");
    assert_file_text(outdir, "notes.txt", "mine");
    assert_file_text(sub, "cam.img", "nested run");
    struct stat st;
    assert_int_equal(stat(outdir, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0710);
    rm(sub, "cam.img");
    rmdir(sub);
    rm(outdir, "cam.img");
    rm(outdir, "notes.txt");
    rmdir(outdir);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* OUTDIR a symbolic link to a directory: the results go into that directory, the link
 * stays a link, and nothing is left beside either. */
static void test_commit_through_symlink(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char real[1024], link_path[1024], outdir[1100];
    snprintf(real, sizeof real, "%s/real", tmp);
    snprintf(link_path, sizeof link_path, "%s/link", tmp);
    assert_int_equal(mkdir(real, 0777), 0);
    assert_int_equal(symlink("real", link_path), 0);
    for (int slash = 0; slash < 2; slash++) {
        snprintf(outdir, sizeof outdir, "%s%s", link_path, slash ? "/" : "");
        output_stage *stage = NULL;
        thz_error err = {0};
        assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_OK);
        write_file(output_stage_dir(stage), "cam.img", slash ? "second" : "first");
        assert_int_equal(output_stage_commit(stage, &err), THZ_OK);
        output_stage_destroy(stage);
        struct stat st;
        assert_int_equal(lstat(link_path, &st), 0);
        assert_true(S_ISLNK(st.st_mode));
        assert_file_text(real, "cam.img", slash ? "second" : "first");
        assert_int_equal(count_entries(tmp), 2); /* real and link: no stage, no lock */
    }
    rm(real, "cam.img");
    rmdir(real);
    unlink(link_path);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A writer's failure names OUTDIR's file, not the staging directory's (a name the user
 * never sees: "/tmp/.thzmap-3d3c...-stage-549-0/cam.radiance.img: write failed: File too
 * large" under ulimit -f); other messages stay as they were. */
static void test_error_names_outdir(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    output_stage *stage = NULL;
    thz_error err = {0};
    if (output_stage_create(outdir, &stage, &err) != THZ_OK)
        fail_msg("%s", err.message);
    const char *dir = output_stage_dir(stage);
    thz_error_set(&err, THZ_ERR_IO, "writing: %s/cam.radiance.img: write failed: File too large",
                  dir);
    output_stage_error_names_outdir(stage, &err);
    char want[2048];
    snprintf(want, sizeof want, "writing: %s/cam.radiance.img: write failed: File too large",
             outdir);
    assert_string_equal(err.message, want);
    assert_int_equal(err.status, THZ_ERR_IO);
    /* the directory's name alone, or another file's: unchanged */
    thz_error_set(&err, THZ_ERR_IO, "%s: cannot remove", dir);
    snprintf(want, sizeof want, "%s: cannot remove", dir);
    output_stage_error_names_outdir(stage, &err);
    assert_string_equal(err.message, want);
    thz_error_set(&err, THZ_ERR_IO, "/elsewhere/x.img: write failed");
    output_stage_error_names_outdir(stage, &err);
    assert_string_equal(err.message, "/elsewhere/x.img: write failed");
    output_stage_destroy(stage);
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* OUTDIR under a regular file cannot be made: bad input (exit 2) naming the path. */
static void test_bad_outdir(void **state)
{
    (void)state;
    char *tmp = make_tmp_dir();
    write_file(tmp, "file", "x");
    char outdir[1024];
    snprintf(outdir, sizeof outdir, "%s/file/out", tmp);
    output_stage *stage = (output_stage *)&stage;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_ERR_INPUT);
    assert_null(stage);
    assert_non_null(strstr(err.message, "/file"));
    /* and OUTDIR itself a regular file */
    snprintf(outdir, sizeof outdir, "%s/file", tmp);
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_ERR_INPUT);
    assert_null(stage);
    assert_non_null(strstr(err.message, "exists and is not a directory"));
    rm(tmp, "file");
    assert_int_equal(rmdir(tmp), 0);
    free(tmp);
}

/* A directory that access() calls writable but that refuses a new file (root in /sys, a
 * file system that is sysfs, or in /proc, where the refusal is ENOENT): bad input like any
 * unwritable OUTDIR, not an I/O failure (exit 1 before). Only where the test runs as root
 * and the directory is that file system. */
static void test_outdir_refusing_files(void **state)
{
    (void)state;
    const struct {
        const char *dir, *outdir;
        long magic;
    } refusing[] = {{"/sys", "/sys/thz-test-outdir", SYSFS_MAGIC},
                    {"/proc", "/proc/thz-test-outdir", PROC_SUPER_MAGIC}};
    int tried = 0;
    for (size_t i = 0; i < sizeof refusing / sizeof refusing[0]; i++) {
        struct statfs fs;
        if (geteuid() != 0 || statfs(refusing[i].dir, &fs) != 0 || fs.f_type != refusing[i].magic ||
            access(refusing[i].dir, W_OK | X_OK) != 0)
            continue;
        tried++;
        output_stage *stage = (output_stage *)&stage;
        thz_error err = {0};
        assert_int_equal(output_stage_create(refusing[i].outdir, &stage, &err), THZ_ERR_INPUT);
        assert_null(stage);
        assert_non_null(strstr(err.message, "choose another output directory"));
    }
    if (!tried)
        skip();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_commit_moves_files),
        cmocka_unit_test(test_failed_commit_rolls_back),
        cmocka_unit_test(test_commit_leaves_no_aside),
        cmocka_unit_test(test_destroy_leaves_nothing),
        cmocka_unit_test(test_destroy_removes_created_outdir),
        cmocka_unit_test(test_two_stages),
        cmocka_unit_test(test_leftovers_cleaned),
        cmocka_unit_test(test_parked_run_restored),
        cmocka_unit_test(test_commit_keeps_subdirectories),
        cmocka_unit_test(test_commit_into_working_directory),
        cmocka_unit_test(test_working_directory_shares_the_lock),
        cmocka_unit_test(test_commit_through_symlink),
        cmocka_unit_test(test_bad_outdir),
        cmocka_unit_test(test_error_names_outdir),
        cmocka_unit_test(test_outdir_refusing_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
