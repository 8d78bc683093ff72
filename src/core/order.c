/* Order statistics without sorting (order.h). */
#include "core/order.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/threads.h"

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

/* Keys from this many on are sorted by all threads: each counts, then moves, its own
 * contiguous part of the keys (the parts' keys of one digit in the parts' order, so the
 * passes stay stable and the result is the sort's whatever the thread count). */
#define ORDER_PARALLEL_MIN ((size_t)1 << 20)
/* Fewer keys than this are sorted by the library's sort: each radix pass clears and scans
 * 2^16 counts (512 KiB), which for a small mesh's few hundred edges took 0.3 ms a sort,
 * most of a scene's load (a 2500-frame sequence's check spent 70 % of its time there).
 * qsort is the faster up to 2000-3000 keys (1000: 91 against 224 us; 4096: 450 against
 * 242 us; 65535: 10.8 against 2.3 ms). */
#define ORDER_RADIX_MIN ((size_t)1 << 11)

void order_sort_u64(uint64_t *x, size_t n)
{
    order_sort_u64_threads(x, n, thz_threads_all());
}

void order_sort_u64_threads(uint64_t *x, size_t n, int threads)
{
    if (n < 2)
        return;
    if (n < ORDER_RADIX_MIN) {
        qsort(x, n, sizeof *x, order_u64_cmp);
        return;
    }
    enum { BITS = 16, BUCKETS = 1 << BITS }; /* 11-bit digits took 6 passes, 13 % slower */
    /* One thread: no OpenMP team at all (if clauses below), as a forked child needs. */
    int nt = n >= ORDER_PARALLEL_MIN && threads > 1 ? threads : 1;
    uint64_t *tmp = malloc(n * sizeof *tmp);
    if (tmp && n >= ORDER_PARALLEL_MIN)
        thz_populate(tmp, n * sizeof *tmp); /* each pass writes it whole */
    size_t *count = tmp ? calloc((size_t)nt * BUCKETS, sizeof *count) : NULL;
    if (!count) { /* no room for the passes: the library's sort, slower but in place */
        free(tmp);
        qsort(x, n, sizeof *x, order_u64_cmp);
        return;
    }
    uint64_t any = 0; /* the bits some key has: the digits above them need no pass */
#pragma omp parallel for num_threads(nt) if (nt > 1) schedule(static) reduction(| : any)
    for (size_t i = 0; i < n; i++)
        any |= x[i];
    uint64_t *src = x, *dst = tmp;
    for (int shift = 0; shift < 64 && any >> shift; shift += BITS) {
        int moved = 0;
#pragma omp parallel num_threads(nt) if (nt > 1)
        {
            int t = 0, parts = 1;
#ifdef _OPENMP
            t = omp_get_thread_num();
            parts = omp_get_num_threads();
#endif
            size_t lo = n / (size_t)parts * (size_t)t;
            size_t hi = t == parts - 1 ? n : n / (size_t)parts * (size_t)(t + 1);
            size_t *c = count + (size_t)t * BUCKETS;
            memset(c, 0, BUCKETS * sizeof *c);
            for (size_t i = lo; i < hi; i++)
                c[src[i] >> shift & (BUCKETS - 1u)]++;
#pragma omp barrier
#pragma omp single
            { /* each part's first place for each digit: the digits in order, within a
               * digit the parts in order; none when every key has the same digit */
                size_t at = 0;
                for (size_t d = 0; d < BUCKETS; d++) {
                    size_t first = at;
                    for (int p = 0; p < parts; p++) {
                        size_t k = count[(size_t)p * BUCKETS + d];
                        count[(size_t)p * BUCKETS + d] = at;
                        at += k;
                    }
                    moved = moved || (at > first && at - first < n);
                }
            }
            if (moved)
                for (size_t i = lo; i < hi; i++)
                    dst[c[src[i] >> shift & (BUCKETS - 1u)]++] = src[i];
        }
        if (!moved)
            continue; /* every key has this digit: nothing moves */
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    if (src != x)
        memcpy(x, src, n * sizeof *x);
    free(count);
    free(tmp);
}
