/* The benchmark's printed table and its JSON (bench/thzbench.c): the targets list, and
 * each section's table (the paper's case, the tracing limit, photon, triangle and thread
 * scaling, rendering, end to end, the integrators' 2-thread speed-ups, time to a
 * converged image), printed to stdout and returned as JSON.
 */
#ifndef THZ_BENCH_REPORT_H
#define THZ_BENCH_REPORT_H

#include <stdbool.h>

#include <jansson.h>

#include "bench_child.h"
#include "bench_measure.h"
#include "bench_render.h"

/* a / b, 0 when b is not positive. */
double bench_ratio(double a, double b);
/* A JSON number; NaN and infinities (which JSON cannot hold) become null. */
json_t *bench_real(double v);

/* A target's verdict. NOT_SHOWN: measured, but not over the whole range the target names
 * (e.g. the photon scaling without its 100 M point), so neither met nor refuted. */
typedef enum bench_verdict { BENCH_MET, BENCH_NOT_MET, BENCH_NOT_SHOWN } bench_verdict;

typedef struct bench_targets {
    json_t *list;
    int met, total;
} bench_targets;

/* Prints one line of the targets table and appends it to t->list: name, value (unit),
 * the comparison op ("<=" or ">=") with limit, and the verdict: met when `value op limit`
 * holds (judged here, on the value and limit printed), else NOT met; "not shown" over
 * either when `shown` is false. */
void bench_target(bench_targets *t, const char *name, double value, const char *op, double limit,
                  const char *unit, bool shown);

/* A scaling point's runs into its JSON object o: how many, the median's CPU ns per photon,
 * the fastest run's seconds and CPU ns per photon, and its ratio to the reference runs. */
void bench_report_point_runs(json_t *o, const bench_point *p);

/* Section 1, the paper's case stage by stage (use: its child's CPU time and peak memory;
 * load: the load average at its start); *bytes_per_photon the memory of a stored photon
 * (its record and its shares of the index and of the renderers' directory). The JSON
 * takes the end-to-end runs after it. */
json_t *bench_report_paper(const bench_paper *paper, const bench_usage *use, double load,
                           double *bytes_per_photon);
/* Section 2, the tracing limit: the raw probe against the paper's case's photon phase,
 * which *phase_over_raw gets. */
json_t *bench_report_probe(const bench_probe_out *probe, const bench_paper *paper, double load,
                           double *phase_over_raw);

/* Section 3's photon scaling and section 4's rendering, from the same series. */
json_t *bench_report_photons(const bench_series *sp, size_t channel, double load);
json_t *bench_report_rendering(const bench_series *sp, size_t channel);

/* Section 3's triangle scaling, a row at a time as its points are measured: the table's
 * head, then each point's row and its JSON. */
void bench_report_triangles_head(uint64_t photons, double load);
json_t *bench_report_triangles_row(const bench_point *p);

/* Section 3's threads: the photon phase, the raw probe and the machine's ceiling, 1
 * thread against all (pairs pairs on threads threads); across gets the phase over the
 * probe on all threads, round by round: the median, the lowest and the highest. */
json_t *bench_report_threads(const bench_threads *th, const bench_pairs *ceiling, size_t channel,
                             int threads, int pairs, double load, double across[3]);

/* One end-to-end run: a line under the label, and its JSON. */
json_t *bench_report_e2e(const char *label, const bench_e2e *e, const bench_usage *use,
                         double load);

/* One speed-up from alternating pairs (bench_pairs.h): a line under `label` (NULL: none; the median
 * of the pairs' ratios, their range, fastest over fastest, the median pair's seconds and
 * CPU seconds), and its JSON. */
json_t *bench_report_pairs(const char *label, const bench_pairs *p);

/* The integrators' speed-ups (n of them, names[i] the integrator of r[i]). */
json_t *bench_report_speedups(const char *const *names, const bench_speedup *r, int n,
                              size_t channel, int threads, double load);

/* Time to a converged image of one integrator: per channel the two runs, the seconds to
 * target_k (extrapolated) and their ratio to limit_s; *worst_s the largest over channels. */
json_t *bench_report_converge(const char *integrator, const bench_converge *cv, double target_k,
                              double limit_s, double load, double *worst_s);

#endif
