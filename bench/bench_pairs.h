/* Thread speed-ups from alternating pairs of runs (bench/thzbench.c, sections 3 and 5).
 *
 * A speed-up compares runs on 1 thread and on all; on a shared machine the two must see
 * the same machine. The runs therefore alternate (1 thread, all, 1, all, ...), each
 * 1-thread run and the all-thread run after it a pair, and the speed-up is the **median
 * over the pairs** of their ratio t_1 / t_all. Each side's fastest run would not do: on
 * this project's VM a single thread now and then runs about 1.45 x faster than its usual
 * speed for a few seconds (when, by all appearances, its host core has no other work),
 * and both threads together seldom do, so the fastest 1-thread run over a few pairs is a
 * lucky one and fastest / fastest falls well below what the pairs show: a loop of pure
 * arithmetic with no memory traffic gave 1.38-1.77 that way against 1.9-2.0 as the
 * median of its pairs (2026-12-04). Both figures are reported, and the machine's own
 * ceiling (that loop, bench_measure_ceiling) beside them.
 */
#ifndef THZ_BENCH_PAIRS_H
#define THZ_BENCH_PAIRS_H

#define BENCH_MAX_PAIRS 16

/* The runs of one speed-up, in the order they ran. */
typedef struct bench_pairs {
    int n;
    double s_1[BENCH_MAX_PAIRS], s_all[BENCH_MAX_PAIRS];     /* wall seconds */
    double cpu_1[BENCH_MAX_PAIRS], cpu_all[BENCH_MAX_PAIRS]; /* CPU seconds of the process */
} bench_pairs;

/* Adds a pair (ignored beyond BENCH_MAX_PAIRS). */
void bench_pairs_add(bench_pairs *p, double s_1, double s_all, double cpu_1, double cpu_all);

/* The median over the pairs of s_1 / s_all (of the middle two for an even count); 0 with
 * no pairs. */
double bench_pairs_speedup(const bench_pairs *p);

/* The fastest 1-thread run over the fastest all-thread run; 0 with no pairs. */
double bench_pairs_speedup_fastest(const bench_pairs *p);

/* The smallest and largest ratio of a pair. */
void bench_pairs_range(const bench_pairs *p, double *lo, double *hi);

/* The seconds and CPU seconds of the pair whose ratio is the median (the lower middle
 * one for an even count); zeros with no pairs. */
void bench_pairs_median_pair(const bench_pairs *p, double *s_1, double *s_all, double *cpu_1,
                             double *cpu_all);

/* Runs of one scaling point at most (bench_measure_series). */
#define BENCH_MAX_RUNS 15

/* The median of n values (of the middle two for an even count; n at most BENCH_MAX_PAIRS
 * or BENCH_MAX_RUNS, the larger); 0 for none. */
double bench_median(const double *v, int n);

/* Two measurements taken in the same rounds (pair i of a and pair i of b in one round of
 * runs, one after the other): the median over the rounds of a's all-thread seconds over
 * b's, and the smallest and largest round's ratio. A ratio of two kinds of work on one
 * machine, measured as the speed-ups are: each round's two runs see the same machine. */
double bench_pairs_across(const bench_pairs *a, const bench_pairs *b, double *lo, double *hi);

/* The machine's own ceiling in this run: a loop of pure arithmetic (xorshift and a
 * square root, no memory traffic), the same work split over 1 thread and over
 * `threads`, in `pairs` alternating pairs of about 0.3 s on 1 thread. */
void bench_measure_ceiling(int threads, int pairs, bench_pairs *out);

#endif
