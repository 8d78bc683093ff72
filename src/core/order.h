/* Order statistics without sorting: the k-th smallest of n values in linear time, where
 * sorting every pixel of a channel twice for its noise figures took 7 s for a 4096 x 4096
 * sensor, and sorting it for a preview's colour scale 2 s. Exact whatever the order the
 * values come in, so the result is a sort's x[k]: the same figures for any thread count.
 */
#ifndef THZ_CORE_ORDER_H
#define THZ_CORE_ORDER_H

#include <stddef.h>
#include <stdint.h>

/* The k-th smallest of x[0..n) (0-based), 0 <= k < n; x is reordered so that
 * x[0..k) <= x[k] <= x[k+1..n). No NaN in x (the caller maps them). */
double order_select(double *x, size_t n, size_t k);

/* Sorts x[0..n) in increasing order: a radix sort (16 bits a pass, the passes whose digit
 * every key shares skipped), where qsort's comparisons took most of the 21 s a scene of
 * three 5 M-triangle meshes spent loading (the edges' checks). Fewer than 2^11 keys, and
 * keys whose scratch (8 bytes a key) cannot be had, are sorted by qsort. */
void order_sort_u64(uint64_t *x, size_t n);
/* The same with at most `threads` threads. With 1 it starts no OpenMP team (a team of
 * one, the if clause's): so in a forked child (core/child.h), where the threads of the
 * parent's OpenMP pool do not exist and a team of two waits for them for ever. */
void order_sort_u64_threads(uint64_t *x, size_t n, int threads);

#endif
