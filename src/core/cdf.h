/* Sampling from a tabulated cumulative distribution: the one binary search that
 * emission, air emission and the benchmark's photon-like rays all use. */
#ifndef THZ_CORE_CDF_H
#define THZ_CORE_CDF_H

#include <stddef.h>
#include <stdint.h>

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

/* A guide table for cdf_search (Chen and Asau's): guide[g] = cdf_search(cdf, n, x_g) at
 * x_g = total g / n_guide for g in [0, n_guide), total = cdf[n-1]. */
static inline void cdf_guide_build(const double *cdf, size_t n, uint32_t *guide, size_t n_guide)
{
    const double total = cdf[n - 1];
    for (size_t g = 0; g < n_guide; g++)
        guide[g] = (uint32_t)cdf_search(cdf, n, total * ((double)g / (double)n_guide));
}

/* cdf_search(cdf, n, x) for x = u cdf[n-1], u in [0, 1), from its guide table: the same
 * index (every index below the guide's has cdf <= x, checked; a search from 0 where the
 * rounding of u n_guide went past), found by a step or two up from the guide's instead of
 * a bisection whose branches the processor cannot predict. n <= 2^32. */
static inline size_t cdf_search_guided(const double *cdf, size_t n, const uint32_t *guide,
                                       size_t n_guide, double u, double x)
{
    size_t g = (size_t)(u * (double)n_guide);
    size_t k = guide[g < n_guide ? g : n_guide - 1];
    if (k > 0 && cdf[k - 1] > x)
        return cdf_search(cdf, k, x); /* the first above x lies below k */
    while (k < n - 1 && !(cdf[k] > x))
        k++;
    return k;
}

#endif
