/* Whether to stop a long piece of work: a run's progress callback behind it, asked on the
 * thread that started the run (never a worker) between the work's steps. One shape for
 * every stage that cannot report progress of its own (figures drawn in child processes,
 * the photon map's index build).
 */
#ifndef THZ_CORE_CANCEL_H
#define THZ_CORE_CANCEL_H

#include <stdbool.h>
#include <stddef.h>

typedef struct cancel_check {
    int (*fn)(void *user); /* non-zero: stop */
    void *user;
} cancel_check;

/* Whether c (may be NULL, or without fn: never) says stop. */
static inline bool cancel_now(const cancel_check *c)
{
    return c && c->fn && c->fn(c->user) != 0;
}

#endif
