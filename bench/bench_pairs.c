/* Speed-ups from alternating pairs: see bench_pairs.h. */
#include "bench_pairs.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include <omp.h>

#include "bench_measure.h"

void bench_pairs_add(bench_pairs *p, double s_1, double s_all, double cpu_1, double cpu_all)
{
    if (p->n >= BENCH_MAX_PAIRS)
        return;
    p->s_1[p->n] = s_1;
    p->s_all[p->n] = s_all;
    p->cpu_1[p->n] = cpu_1;
    p->cpu_all[p->n] = cpu_all;
    p->n++;
}

static double bench_pair_ratio(const bench_pairs *p, int i)
{
    return p->s_all[i] > 0.0 ? p->s_1[i] / p->s_all[i] : 0.0;
}

/* The pairs' indices in order of their ratios (a small insertion sort). */
static void bench_pairs_order(const bench_pairs *p, int *order)
{
    for (int i = 0; i < p->n; i++) {
        int j = i;
        while (j > 0 && bench_pair_ratio(p, order[j - 1]) > bench_pair_ratio(p, i)) {
            order[j] = order[j - 1];
            j--;
        }
        order[j] = i;
    }
}

double bench_pairs_speedup(const bench_pairs *p)
{
    double r[BENCH_MAX_PAIRS];
    for (int i = 0; i < p->n; i++)
        r[i] = bench_pair_ratio(p, i);
    return bench_median(r, p->n);
}

void bench_pairs_median_pair(const bench_pairs *p, double *s_1, double *s_all, double *cpu_1,
                             double *cpu_all)
{
    *s_1 = *s_all = *cpu_1 = *cpu_all = 0.0;
    if (p->n <= 0)
        return;
    int order[BENCH_MAX_PAIRS];
    bench_pairs_order(p, order);
    int m = order[(p->n - 1) / 2];
    *s_1 = p->s_1[m];
    *s_all = p->s_all[m];
    *cpu_1 = p->cpu_1[m];
    *cpu_all = p->cpu_all[m];
}

double bench_pairs_speedup_fastest(const bench_pairs *p)
{
    if (p->n <= 0)
        return 0.0;
    double f1 = p->s_1[0], fa = p->s_all[0];
    for (int i = 1; i < p->n; i++) {
        f1 = fmin(f1, p->s_1[i]);
        fa = fmin(fa, p->s_all[i]);
    }
    return fa > 0.0 ? f1 / fa : 0.0;
}

void bench_pairs_range(const bench_pairs *p, double *lo, double *hi)
{
    *lo = *hi = 0.0;
    for (int i = 0; i < p->n; i++) {
        double r = bench_pair_ratio(p, i);
        *lo = i == 0 || r < *lo ? r : *lo;
        *hi = i == 0 || r > *hi ? r : *hi;
    }
}

double bench_median(const double *v, int n)
{
    if (n <= 0)
        return 0.0;
    double w[BENCH_MAX_PAIRS > BENCH_MAX_RUNS ? BENCH_MAX_PAIRS : BENCH_MAX_RUNS];
    if (n > (int)(sizeof w / sizeof w[0]))
        n = (int)(sizeof w / sizeof w[0]);
    for (int i = 0; i < n; i++) { /* insertion sort */
        int j = i;
        while (j > 0 && w[j - 1] > v[i]) {
            w[j] = w[j - 1];
            j--;
        }
        w[j] = v[i];
    }
    return 0.5 * (w[(n - 1) / 2] + w[n / 2]);
}

double bench_pairs_across(const bench_pairs *a, const bench_pairs *b, double *lo, double *hi)
{
    double r[BENCH_MAX_PAIRS];
    int n = a->n < b->n ? a->n : b->n;
    *lo = *hi = 0.0;
    for (int i = 0; i < n; i++) {
        r[i] = b->s_all[i] > 0.0 ? a->s_all[i] / b->s_all[i] : 0.0;
        *lo = i == 0 || r[i] < *lo ? r[i] : *lo;
        *hi = i == 0 || r[i] > *hi ? r[i] : *hi;
    }
    return bench_median(r, n);
}

/* n steps of xorshift64 and a square root from seed: registers only. */
static double bench_ceiling_work(long n, uint64_t s)
{
    double acc = 0.0;
    for (long i = 0; i < n; i++) {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        double x = (double)(s >> 11) * 0x1p-53;
        acc += sqrt(x) * 1.0001 + x * x;
    }
    return acc;
}

void bench_measure_ceiling(int threads, int pairs, bench_pairs *out)
{
    memset(out, 0, sizeof *out);
    const long steps = 80000000; /* about 0.3 s on 1 thread here */
    volatile double sink = 0.0;
    double s_1 = 0.0, cpu_1 = 0.0;
    for (int k = 0; k < 2 * pairs; k++) {
        int nt = k % 2 == 0 ? 1 : threads;
        double t = bench_now_s(), c = bench_cpu_s(), acc = 0.0;
#pragma omp parallel num_threads(nt) reduction(+ : acc)
        {
            int id = omp_get_thread_num(), n = omp_get_num_threads();
            acc += bench_ceiling_work(steps / n, 88172645463325252ull + (uint64_t)id);
        }
        sink += acc;
        double dt = bench_now_s() - t, dc = bench_cpu_s() - c;
        if (k % 2 == 0) {
            s_1 = dt;
            cpu_1 = dc;
        } else {
            bench_pairs_add(out, s_1, dt, cpu_1, dc);
        }
    }
    (void)sink;
}
