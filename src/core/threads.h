/* The thread count "all cores" (0) stands for: OpenMP's default (OMP_NUM_THREADS, else
 * the processors), at most THZ_MAX_THREADS, the most any run takes when asked by count.
 * OMP_NUM_THREADS=100000 crashed libgomp while it started its team (stack exhausted).
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

#endif
