/* Work in child processes (core/child.c): a child's time limit leaves out the time the
 * caller spent stopped (Ctrl-Z, a scheduler's suspend: a job suspended for a minute while
 * drawing failed on resuming), still stops a child that runs too long, and a cancel
 * ends a group's children at once. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/child.h"
#include "core/clock.h"

static thz_status sleeper(void *arg, thz_error *err)
{
    (void)err;
    double s = *(const double *)arg;
    struct timespec t = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&t, &t) != 0 && errno == EINTR) {
    }
    return THZ_OK;
}

/* Stops this process after `after` s for `stopped` s, from a process of its own. */
static pid_t stop_me(double after, double stopped)
{
    pid_t me = getpid(), pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        usleep((useconds_t)(after * 1e6));
        kill(me, SIGSTOP);
        usleep((useconds_t)(stopped * 1e6));
        kill(me, SIGCONT);
        _exit(0);
    }
    return pid;
}

static void test_stopped_time_is_not_the_childs(void **state)
{
    (void)state;
    double work = 0.4;
    pid_t stopper = stop_me(0.1, 2.5);
    thz_error err = {0};
    double t0 = thz_now_s();
    thz_status st = child_run("sleeping", sleeper, &work, 1.0, &err);
    double took = thz_now_s() - t0;
    waitpid(stopper, NULL, 0);
    if (st != THZ_OK)
        fail_msg("%s (after %.2f s)", err.message, took);
    assert_true(took > 2.0); /* it was stopped */
}

/* Stopped while waiting with no report yet: the wait that ends long after its time moves
 * the deadline on by the stop (a 3 s child under a 2 s limit, the caller stopped 2.5 s). */
static void test_stopped_while_waiting(void **state)
{
    (void)state;
    double work = 3.0;
    pid_t stopper = stop_me(0.1, 2.5);
    thz_error err = {0};
    thz_status st = child_run("sleeping", sleeper, &work, 2.0, &err);
    waitpid(stopper, NULL, 0);
    if (st != THZ_OK)
        fail_msg("%s", err.message);
}

static void test_a_child_too_long_is_stopped(void **state)
{
    (void)state;
    double work = 5.0;
    thz_error err = {0};
    double t0 = thz_now_s();
    assert_int_equal(child_run("sleeping", sleeper, &work, 0.5, &err), THZ_ERR_IO);
    assert_true(thz_now_s() - t0 < 3.0);
    assert_non_null(strstr(err.message, "no result after"));
}

static double cancel_after_s;
static int cancel_late(void *user)
{
    return thz_now_s() > *(const double *)user;
}

static void test_cancel_ends_the_group(void **state)
{
    (void)state;
    double work[3] = {5.0, 5.0, 5.0};
    void *args[3] = {&work[0], &work[1], &work[2]};
    const char *whats[3] = {"one", "two", "three"};
    cancel_after_s = thz_now_s() + 0.3;
    cancel_check cancel = {cancel_late, &cancel_after_s};
    thz_error err = {0};
    double t0 = thz_now_s();
    assert_int_equal(child_run_group(whats, sleeper, args, 3, 60.0, &cancel, &err),
                     THZ_ERR_CANCELLED);
    assert_true(thz_now_s() - t0 < 2.0);
    assert_non_null(strstr(err.message, "cancelled while one"));
    errno = 0; /* every child reaped */
    assert_true(waitpid(-1, NULL, WNOHANG) == -1 && errno == ECHILD);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stopped_time_is_not_the_childs),
        cmocka_unit_test(test_stopped_while_waiting),
        cmocka_unit_test(test_a_child_too_long_is_stopped),
        cmocka_unit_test(test_cancel_ends_the_group),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
