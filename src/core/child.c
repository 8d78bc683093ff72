/* Work in a child process (child.h). */
#define _GNU_SOURCE /* pipe2 */
#include "core/child.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <stdbool.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/clock.h"

/* Registered in the child first thing, so run first of the exit handlers when a library
 * ends the child with exit() (PLplot does when an allocation fails): the child ends at
 * once with status 1, which the parent reports as a stop before the end. The handlers
 * after it are the caller's, copied into the child with its memory, and they have
 * nothing to do there. One of them, under LeakSanitizer, is a leak check of the caller's
 * heap as copied, with the caller's other threads missing ("Running thread ... was not
 * suspended"): a report that says nothing about the child, seen once a child drew
 * several figures (test_alloc_fail.sh: PLplot's set-up of a later figure). */
static void child_exit_now(void)
{
    _exit(1);
}

/* The child: runs fn, writes its error (status and message, about 1 KiB: one write
 * below PIPE_BUF that the pipe takes whole) and ends without exit handlers. */
static _Noreturn void child_main(int fd, child_fn fn, void *arg)
{
    (void)atexit(child_exit_now); /* may fail for want of memory: exit() runs them all */
    /* The caller's handlers only set a flag the child never reads: a SIGTERM or
     * SIGINT sent to the child must end it. */
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    thz_error e;
    memset(&e, 0, sizeof e);
    e.status = fn(arg, &e);
    ssize_t n = write(fd, &e, sizeof e);
    _exit(n == (ssize_t)sizeof e ? 0 : 1);
}

/* How waiting for a child's report ended. */
typedef enum child_wait { CHILD_REPORTED, CHILD_LATE, CHILD_CANCELLED } child_wait;

/* Reads the child's report into *report (*got bytes so far) until its end of the pipe
 * closes, which happens when it exits; CHILD_LATE when the deadline, moved on by the
 * time the process spent stopped (*paused_s, for the whole group), passes first,
 * CHILD_CANCELLED when `cancel` says stop. A poll that times out more than a second after
 * its own wait had the process stopped (Ctrl-Z, a scheduler's suspend) or starved: that
 * time is not the child's, whose own clock stood still with the process group; a job
 * suspended for over a minute while drawing failed on resuming. A report that arrived
 * while the process was stopped is taken, whatever the clock says by then. */
static child_wait child_collect(int fd, double deadline_s, double *paused_s,
                                const cancel_check *cancel, thz_error *report, size_t *got)
{
    int slice_ms = cancel && cancel->fn ? 100 : 1000;
    bool fresh = false; /* the last poll brought the report: the child is not late */
    for (;;) {
        if (cancel_now(cancel))
            return CHILD_CANCELLED;
        double before_s = thz_now_s();
        double left_s = deadline_s + *paused_s - before_s;
        if (left_s <= 0.0 && !fresh)
            return CHILD_LATE;
        int wait_ms = left_s <= 0.0             ? 100
                      : left_s * 1e3 > slice_ms ? slice_ms
                                                : (int)(left_s * 1e3) + 1;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        int r = poll(&p, 1, wait_ms);
        fresh = false;
        if (r == 0) { /* a wait that ended long after its time: the process was stopped */
            double beyond_s = thz_now_s() - before_s - 1e-3 * wait_ms;
            if (beyond_s > 1.0)
                *paused_s += beyond_s;
            continue;
        }
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0)
            return CHILD_REPORTED; /* cannot wait here: waitpid blocks instead */
        char buf[2048];
        ssize_t n = read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return CHILD_REPORTED;
        size_t room = sizeof *report - *got, take = (size_t)n < room ? (size_t)n : room;
        memcpy((char *)report + *got, buf, take);
        *got += take;
        fresh = true;
    }
}

/* Children are started one at a time per process: a fork while another thread is inside
 * fork, malloc or a child's set-up can leave the new child holding a lock no thread will
 * release (seen under AddressSanitizer: three threads plotting at once, a child hung until
 * its time limit). The figures were serialised before they moved into children, too. A
 * group (child_run_group) starts its children one after the other from one thread under
 * this lock, and they then run at once. */
static pthread_mutex_t child_lock = PTHREAD_MUTEX_INITIALIZER;

/* A started child: its pid, the read end of its report pipe and its deadline. */
typedef struct child_proc {
    pid_t pid;
    int fd;
    double deadline_s;
} child_proc;

/* Forks a child running fn(arg); child_lock held. */
static thz_status child_start(const char *what, child_fn fn, void *arg, double timeout_s,
                              child_proc *c, thz_error *err)
{
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return thz_error_set(err, errno == ENOMEM ? THZ_ERR_NOMEM : THZ_ERR_IO,
                             "%s while %s: cannot create a pipe: %s",
                             errno == ENOMEM ? "out of memory" : "failed", what, strerror(errno));
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]);
        close(fds[1]);
        if (e == ENOMEM)
            return thz_error_set(err, THZ_ERR_NOMEM,
                                 "out of memory while %s: cannot start a process: %s", what,
                                 strerror(e));
        if (e == EAGAIN) /* the process limit, as often as memory: say both */
            return thz_error_set(err, THZ_ERR_IO,
                                 "failed while %s: cannot start a process: %s (the limit on "
                                 "processes, ulimit -u, is reached, or memory is short)",
                                 what, strerror(e));
        return thz_error_set(err, THZ_ERR_IO, "failed while %s: cannot start a process: %s", what,
                             strerror(e));
    }
    if (pid == 0) {
        /* The child shares the parent's lock files (flock follows the descriptor): it
         * must not outlive a parent killed with SIGKILL, or a rerun finds OUTDIR locked. */
        if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent)
            _exit(127);
        /* child_lock was held across the fork by the thread this one replicates: release
         * it, or an fn that starts a child of its own waits for it until its time limit. */
        pthread_mutex_unlock(&child_lock);
        close(fds[0]);
        child_main(fds[1], fn, arg);
    }
    close(fds[1]);
    c->pid = pid;
    c->fd = fds[0];
    c->deadline_s = thz_now_s() + timeout_s;
    return THZ_OK;
}

/* Ends a started child at once and waits for it. */
static void child_kill(child_proc *c)
{
    close(c->fd);
    kill(c->pid, SIGKILL);
    while (waitpid(c->pid, NULL, 0) < 0 && errno == EINTR) {
    }
}

/* Waits for a started child (killed at its deadline, or when cancelled) and returns its
 * status. */
static thz_status child_finish(const char *what, child_proc *c, double timeout_s, double *paused_s,
                               const cancel_check *cancel, bool *crashed, thz_error *err)
{
    *crashed = false;
    thz_error report;
    memset(&report, 0, sizeof report);
    size_t got = 0;
    child_wait w = child_collect(c->fd, c->deadline_s, paused_s, cancel, &report, &got);
    if (w == CHILD_CANCELLED) {
        child_kill(c);
        return thz_error_set(err, THZ_ERR_CANCELLED, "cancelled while %s", what);
    }
    bool timed_out = w == CHILD_LATE;
    close(c->fd);
    if (timed_out)
        kill(c->pid, SIGKILL);
    int ws = 0;
    while (waitpid(c->pid, &ws, 0) < 0 && errno == EINTR) {
    }

    *crashed = timed_out || WIFSIGNALED(ws); /* not an exit without a report: out of memory */
    if (timed_out)
        return thz_error_set(err, THZ_ERR_IO, "failed while %s: no result after %.0f s (stopped)",
                             what, timeout_s);
    /* the child shares the parent's ulimit -v, and starts with its address space: GLib
     * ends it (SIGTRAP) when it cannot map a thread's stack there */
    char limited[96] = "";
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
        snprintf(limited, sizeof limited, " (the address space is limited: ulimit -v %llu KiB)",
                 (unsigned long long)rl.rlim_cur / 1024);
    if (WIFSIGNALED(ws))
        return thz_error_set(err, THZ_ERR_IO,
                             "failed while %s: the process doing it ended by signal %d (%s)%s",
                             what, WTERMSIG(ws), strsignal(WTERMSIG(ws)), limited);
    if (got != sizeof report || !WIFEXITED(ws) || WEXITSTATUS(ws) != 0)
        return thz_error_set(err, THZ_ERR_IO,
                             "failed while %s: the process doing it stopped with exit status %d "
                             "before it finished (a library it uses ends the process when it "
                             "runs out of memory)%s",
                             what, WIFEXITED(ws) ? WEXITSTATUS(ws) : -1, limited);
    report.message[sizeof report.message - 1] = '\0';
    if (report.status == THZ_OK)
        return THZ_OK;
    return thz_error_set(err, report.status, "%s", report.message);
}

static thz_status child_run_group_crash(const char *const *whats, child_fn fn, void *const *args,
                                        size_t n, double timeout_s, const cancel_check *cancel,
                                        bool *crashed, thz_error *err);

thz_status child_run(const char *what, child_fn fn, void *arg, double timeout_s, thz_error *err)
{
    bool crashed;
    return child_run_group_crash(&what, fn, &arg, 1, timeout_s, NULL, &crashed, err);
}

thz_status child_run_crash(const char *what, child_fn fn, void *arg, double timeout_s,
                           bool *crashed, thz_error *err)
{
    return child_run_group_crash(&what, fn, &arg, 1, timeout_s, NULL, crashed, err);
}

thz_status child_run_group(const char *const *whats, child_fn fn, void *const *args, size_t n,
                           double timeout_s, const cancel_check *cancel, thz_error *err)
{
    bool crashed;
    return child_run_group_crash(whats, fn, args, n, timeout_s, cancel, &crashed, err);
}

/* child_run_group, and *crashed: whether its failure is a child's crash or time-out. */
static thz_status child_run_group_crash(const char *const *whats, child_fn fn, void *const *args,
                                        size_t n, double timeout_s, const cancel_check *cancel,
                                        bool *crashed, thz_error *err)
{
    *crashed = false;
    if (n == 0)
        return THZ_OK;
    if (n > CHILD_GROUP_MAX)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%zu child processes at once (at most %d)", n,
                             CHILD_GROUP_MAX);
    child_proc procs[CHILD_GROUP_MAX];
    thz_error start_err;
    memset(&start_err, 0, sizeof start_err);
    thz_status start_st = THZ_OK;
    size_t started = 0;
    pthread_mutex_lock(&child_lock);
    while (started < n && start_st == THZ_OK) {
        start_st =
            child_start(whats[started], fn, args[started], timeout_s, &procs[started], &start_err);
        started += start_st == THZ_OK;
    }
    pthread_mutex_unlock(&child_lock);
    /* Each child's report is one write of about 1 KiB, which its pipe holds: the reports
     * are read in order, the later children finishing meanwhile. The first failure in
     * that order is the group's; a child that could not start comes after those that
     * did. */
    thz_status st = THZ_OK;
    double paused_s = 0.0;
    for (size_t i = 0; i < started; i++) {
        thz_error e;
        memset(&e, 0, sizeof e);
        bool died = false;
        thz_status s = child_finish(whats[i], &procs[i], timeout_s, &paused_s, cancel, &died, &e);
        if (s == THZ_ERR_CANCELLED) { /* the others too, at once */
            for (size_t j = i + 1; j < started; j++)
                child_kill(&procs[j]);
            if (err)
                *err = e;
            return s;
        }
        if (s != THZ_OK && st == THZ_OK) {
            st = s;
            *crashed = died;
            if (err)
                *err = e;
        }
    }
    if (st == THZ_OK && start_st != THZ_OK) {
        st = start_st;
        if (err)
            *err = start_err;
    }
    return st;
}
