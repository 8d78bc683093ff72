/* Order statistics without sorting (order.h). */
#include "core/order.h"

#include <stdlib.h>

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
