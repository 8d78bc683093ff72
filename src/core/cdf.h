/* Sampling from a tabulated cumulative distribution: the one binary search that
 * emission, air emission and the benchmark's photon-like rays all use. */
#ifndef THZ_CORE_CDF_H
#define THZ_CORE_CDF_H

#include <stddef.h>

/* The first index i in [0, n) with cdf[i] > x, for a non-decreasing cdf of n >= 1
 * entries and x in [0, cdf[n-1]); n - 1 if there is none. */
static inline size_t cdf_search(const double *cdf, size_t n, double x)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cdf[mid] > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

#endif
