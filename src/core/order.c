/* Order statistics without sorting (order.h). */
#include "core/order.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int order_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Hoare's selection with the median of three as the pivot; a range that shrinks too
 * slowly is sorted instead (linear in expectation, n log n at worst). */
double order_select(double *x, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1, rounds = 0, limit = 16;
    for (size_t m = n; m > 1; m >>= 1)
        limit += 2;
    while (hi > lo) {
        if (++rounds > limit) {
            qsort(x + lo, hi - lo + 1, sizeof *x, order_cmp);
            break;
        }
        /* the median of three as the pivot, then Hoare's partition around its value */
        size_t mid = lo + (hi - lo) / 2;
        double a = x[lo], b = x[mid], c = x[hi];
        double pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        size_t i = lo, j = hi;
        while (i <= j) {
            while (x[i] < pivot)
                i++;
            while (x[j] > pivot)
                j--;
            if (i <= j) {
                double t = x[i];
                x[i] = x[j];
                x[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        /* now x[lo..j] <= pivot <= x[i..hi], and x[j+1..i-1] == pivot */
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return x[k];
    }
    return x[k];
}

static int order_u64_cmp(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

void order_sort_u64(uint64_t *x, size_t n)
{
    uint64_t *tmp = n > 1 ? malloc(n * sizeof *tmp) : NULL;
    enum { BITS = 16, BUCKETS = 1 << BITS }; /* 4 passes; 11-bit digits took 6, 13 % slower */
    size_t *count = tmp ? calloc(BUCKETS, sizeof *count) : NULL;
    if (!count) { /* no room for the passes: the library's sort, slower but in place */
        free(tmp);
        if (n > 1)
            qsort(x, n, sizeof *x, order_u64_cmp);
        return;
    }
    uint64_t *src = x, *dst = tmp;
    for (int shift = 0; shift < 64; shift += BITS) {
        memset(count, 0, BUCKETS * sizeof *count);
        for (size_t i = 0; i < n; i++)
            count[src[i] >> shift & (BUCKETS - 1u)]++;
        if (count[src[0] >> shift & (BUCKETS - 1u)] == n)
            continue; /* every key has this digit: nothing moves */
        size_t at = 0;
        for (size_t d = 0; d < BUCKETS; d++) {
            size_t c = count[d];
            count[d] = at;
            at += c;
        }
        for (size_t i = 0; i < n; i++)
            dst[count[src[i] >> shift & (BUCKETS - 1u)]++] = src[i];
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    if (src != x)
        memcpy(x, src, n * sizeof *x);
    free(count);
    free(tmp);
}
