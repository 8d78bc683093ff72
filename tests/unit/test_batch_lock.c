/* A batch's lock on its OUTDIR (batch/batch_outdir.c): a second batch into the same
 * directory is refused whether it runs in another process or in another thread of the
 * same one (two thzmap.batch() calls from Python threads both ran, mixing their frames),
 * and the lock holds until its own descriptor is closed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "batch/batch_run_state.h"
#include "core/error.h"

static void make_tmp_dir(char *dir, size_t size)
{
    const char *base = getenv("TMPDIR");
    snprintf(dir, size, "%s/thz-test-batch-lock-XXXXXX", base && *base ? base : "/tmp");
    assert_non_null(mkdtemp(dir));
}

/* Whether another process can take the lock now (1), or is refused (0). */
static int other_process_locks(const char *dir)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = -1;
        thz_error err;
        _exit(batch_lock(dir, &fd, &err) == THZ_OK ? 1 : 0);
    }
    int ws = 0;
    assert_int_equal(waitpid(pid, &ws, 0), pid);
    assert_true(WIFEXITED(ws));
    return WEXITSTATUS(ws);
}

static void test_second_batch_same_process_refused(void **state)
{
    (void)state;
    char dir[512], path[600];
    make_tmp_dir(dir, sizeof dir);
    int a = -1, b = -1;
    thz_error err;
    memset(&err, 0, sizeof err);
    assert_int_equal(batch_lock(dir, &a, &err), THZ_OK);
    assert_int_equal(batch_lock(dir, &b, &err), THZ_ERR_IO);
    assert_int_equal(b, -1);
    assert_non_null(strstr(err.message, "another thzmap batch is running into this directory"));
    assert_int_equal(other_process_locks(dir), 0);

    /* another descriptor of the file, opened and closed, does not let the lock go */
    snprintf(path, sizeof path, "%s/.thzmap-batch-lock", dir);
    int other = open(path, O_RDONLY);
    assert_true(other >= 0);
    close(other);
    assert_int_equal(other_process_locks(dir), 0);
    assert_int_equal(batch_lock(dir, &b, &err), THZ_ERR_IO);

    /* released with its own descriptor: the next batch takes it */
    close(a);
    assert_int_equal(batch_lock(dir, &b, &err), THZ_OK);
    close(b);
    assert_int_equal(other_process_locks(dir), 1);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_second_batch_same_process_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
