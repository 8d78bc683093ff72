/* Running a piece of work in a child process, so that a library that ends the process
 * (exit() or abort() when an allocation fails, as PLplot, fontconfig and GLib do) or
 * deadlocks cannot take down or freeze the process that holds a run's staging files.
 *
 * The child is a fork() of the caller: it sees the caller's memory as it was (copy on
 * write), runs the function, sends back its status and message through a pipe and ends
 * with _exit(), so no exit handler of the caller runs in it. The caller waits, up to a
 * time limit after which the child is killed.
 */
#ifndef THZ_CORE_CHILD_H
#define THZ_CORE_CHILD_H

#include <stdbool.h>

#include "core/cancel.h"
#include "core/error.h"

/* The work: returns a status and fills err like any fallible function. */
typedef thz_status (*child_fn)(void *arg, thz_error *err);

/* Runs fn(arg) in a child process and returns its status and message. `what` says
 * what the child does ("plotting out/cam.band-01.png") for the messages of a child
 * that cannot start (THZ_ERR_NOMEM "out of memory while <what>: ..." when fork fails
 * for lack of memory), dies from a signal, exits without reporting (a library called
 * exit()), or runs longer than timeout_s (it is then killed): THZ_ERR_IO, the message
 * saying which. Calls from several threads run one child at a time (a process-wide
 * lock, released in the child, so fn may call child_run too); the child runs only the
 * calling thread, so fn must not wait for other threads of the caller, nor start a team
 * of OpenMP threads: libgomp's pool is the parent's, whose threads the child lacks, and a
 * team of two waits for them for ever (a team of one, an `if` clause's, runs). */
thz_status child_run(const char *what, child_fn fn, void *arg, double timeout_s, thz_error *err);

/* child_run, and *crashed: true when it failed because the child died from a signal or
 * ran past timeout_s (the work's own failure; not one of starting the child, nor an exit
 * without a report, which a library makes when memory runs out). */
thz_status child_run_crash(const char *what, child_fn fn, void *arg, double timeout_s,
                           bool *crashed, thz_error *err);

/* At most this many children in a group. */
#define CHILD_GROUP_MAX 64

/* Runs fn(args[i]) for i < n (n <= CHILD_GROUP_MAX) in n children at once: started one
 * after the other by the calling thread (under child_run's lock), then each waited for,
 * and killed timeout_s after its start if still running. Returns THZ_OK or the first
 * failure in index order, its message as child_run gives it with whats[i] for `what`;
 * a child that cannot start leaves the later ones unstarted (the earlier are still
 * waited for). When `cancel` (may be NULL) says stop, every child still running is
 * killed and the group returns THZ_ERR_CANCELLED. */
thz_status child_run_group(const char *const *whats, child_fn fn, void *const *args, size_t n,
                           double timeout_s, const cancel_check *cancel, thz_error *err);

#endif
