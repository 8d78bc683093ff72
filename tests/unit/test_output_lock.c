/* The lock on an OUTDIR (io/output_stage.c) when the run that took it is gone but a child
 * it forked still holds it: flock follows the descriptor across fork, and a plot child
 * (core/child.c) dies with its parent only a moment after. test_batch's resume after a
 * SIGKILL met that moment on a loaded machine: the resumed batch was told "another thzmap
 * run (process N) is writing" of a process already dead, and exited 1. A lock whose run
 * is gone is now waited for; one whose run lives is refused at once, as before. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io/output.h"

static void make_tmp_dir(char *dir, size_t size)
{
    const char *base = getenv("TMPDIR");
    snprintf(dir, size, "%s/thz-test-output-lock-XXXXXX", base && *base ? base : "/tmp");
    assert_non_null(mkdtemp(dir));
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A run that takes outdir's lock and ends without letting go, leaving a child of its own
 * (which shares the lock) alive for hold_s; returns once the run itself has ended. */
static void run_gone_child_holds(const char *outdir, double hold_s)
{
    pid_t run = fork();
    assert_true(run >= 0);
    if (run == 0) {
        output_stage *stage = NULL;
        thz_error err = {0};
        if (output_stage_create(outdir, &stage, &err) != THZ_OK)
            _exit(1);
        if (fork() == 0) {
            nanosleep(&(struct timespec){.tv_sec = (time_t)hold_s,
                                         .tv_nsec = (long)((hold_s - (long)hold_s) * 1e9)},
                      NULL);
            _exit(0);
        }
        _exit(0); /* killed, as it were: the stage is neither committed nor destroyed */
    }
    int status = 0;
    assert_int_equal(waitpid(run, &status, 0), run);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

static void test_gone_run_lock_waited_for(void **state)
{
    (void)state;
    char dir[512], outdir[600];
    make_tmp_dir(dir, sizeof dir);
    snprintf(outdir, sizeof outdir, "%s/out", dir);
    run_gone_child_holds(outdir, 0.3);
    double t0 = now_s();
    output_stage *stage = NULL;
    thz_error err = {0};
    thz_status st = output_stage_create(outdir, &stage, &err);
    if (st != THZ_OK)
        fail_msg("refused: %s", err.message);
    double waited = now_s() - t0;
    assert_true(waited < 5.0);
    assert_int_equal(output_stage_commit(stage, &err), THZ_OK);
    output_stage_destroy(stage);
    /* the gone run's stage was cleaned up: OUTDIR alone (its lock file removed) */
    char cmd[1300];
    snprintf(cmd, sizeof cmd, "test \"$(ls -A '%s')\" = out && rm -r '%s'", dir, dir);
    assert_int_equal(system(cmd), 0);
}

/* A live holder is refused at once, naming its process. */
static void test_live_run_refused(void **state)
{
    (void)state;
    char dir[512], outdir[600];
    make_tmp_dir(dir, sizeof dir);
    snprintf(outdir, sizeof outdir, "%s/out", dir);
    int ready[2];
    assert_int_equal(pipe(ready), 0);
    pid_t run = fork();
    assert_true(run >= 0);
    if (run == 0) {
        output_stage *stage = NULL;
        thz_error err = {0};
        char ok = output_stage_create(outdir, &stage, &err) == THZ_OK ? 'y' : 'n';
        if (write(ready[1], &ok, 1) != 1)
            _exit(1);
        pause(); /* until the test kills it */
        _exit(0);
    }
    char ok = 0;
    assert_int_equal(read(ready[0], &ok, 1), 1);
    assert_int_equal(ok, 'y');
    double t0 = now_s();
    output_stage *stage = NULL;
    thz_error err = {0};
    assert_int_equal(output_stage_create(outdir, &stage, &err), THZ_ERR_IO);
    assert_true(now_s() - t0 < 1.0);
    char expect[64];
    snprintf(expect, sizeof expect, "another thzmap run (process %ld)", (long)run);
    if (!strstr(err.message, expect))
        fail_msg("message '%s' lacks '%s'", err.message, expect);
    kill(run, SIGKILL);
    waitpid(run, NULL, 0);
    close(ready[0]);
    close(ready[1]);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -r '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gone_run_lock_waited_for),
        cmocka_unit_test(test_live_run_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
