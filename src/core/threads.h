/* The thread count "all cores" (0) stands for: OpenMP's default (OMP_NUM_THREADS, else
 * the processors), at most THZ_MAX_THREADS, the most any run takes when asked by count.
 * OMP_NUM_THREADS=100000 crashed libgomp while it started its team (stack exhausted).
 * And the threads under an address-space limit (threads.c).
 */
#ifndef THZ_CORE_THREADS_H
#define THZ_CORE_THREADS_H

#include "thzmap/thzmap.h"

#ifdef _OPENMP
#include <omp.h>
#endif

static inline int thz_threads_all(void)
{
#ifdef _OPENMP
    int n = omp_get_max_threads();
    return n < 1 ? 1 : n > THZ_MAX_THREADS ? THZ_MAX_THREADS : n;
#else
    return 1;
#endif
}

/* `threads` when positive, else thz_threads_all(). */
static inline int thz_threads_or_all(int threads)
{
    return threads > 0 ? threads : thz_threads_all();
}

/* OMP_STACKSIZE as libgomp reads it (a size, K by default; B, K, M, G suffixes), in
 * bytes; 0 when unset or not a size (libgomp then warns and keeps its default). */
uint64_t thz_thread_omp_stack_bytes(void);
/* The stack an OpenMP thread gets: OMP_STACKSIZE, else the C library's default (from
 * ulimit -s when the process started; 8 MiB under the usual 8192 KiB). */
uint64_t thz_thread_stack_bytes(void);
/* The address space one more thread maps: its stack, a guard page, and the malloc arena
 * glibc reserves for it once it allocates (64 MiB on 64-bit systems). */
uint64_t thz_thread_address_bytes(void);
/* The threads of this process now (/proc/self/status), at least 1. */
int thz_threads_running(void);
/* thz_threads_or_all(threads), or fewer under an address-space limit (ulimit -v): as
 * many as the threads running plus those whose thz_thread_address_bytes fit in half the
 * room the limit leaves (the other half is the work's), at least 1. libgomp ends the
 * process ("Thread creation failed") when a thread's stack cannot be mapped. */
int thz_threads_fitting(int threads);
/* Starts thz_threads_fitting(threads) OpenMP threads of the calling thread's team now
 * (0: OpenMP's default), and lowers OpenMP's default to that count
 * when it is fewer: later parallel regions of no more threads find them started, their
 * stacks mapped before the data that would leave no room. Returns the count. */
int thz_threads_start(int threads);

#endif
