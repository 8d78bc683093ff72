/* Band selection's criterion and search (docs/analysis.md "thzmap bands"): Gaussian
 * classes given by a mean and a covariance over the candidate channels; the separability
 * of a set of channels is its worst pair's Bhattacharyya distance B, reported as the
 * Jeffries-Matusita distance JM = 2 (1 - exp(-B)); the search is exhaustive over every
 * set of 1..K channels when they are few, else sequential floating forward selection.
 */
#ifndef THZ_ANALYSIS_BANDS_SEARCH_H
#define THZ_ANALYSIS_BANDS_SEARCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "thzmap/analysis.h"

/* Largest K the search accepts (sets are small: a camera has a few channels). */
enum { BANDS_MAX_COUNT = THZ_BANDS_MAX_COUNT };

typedef struct bands_classes {
    size_t n_candidates, n_classes;
    const double *mean;  /* [class * n_candidates + c], e.g. K of Tb */
    const double *cov;   /* [class * n^2 + c * n + c'], positive definite on every subset */
    const size_t *group; /* per candidate its centre, non-decreasing with the candidate; a set
                            holds each group at most once (a centre with one width); NULL:
                            each candidate its own group */
} bands_classes;

/* A set's separability. */
typedef struct bands_score {
    double worst_jm;      /* the smallest pairwise JM, 0..2 */
    double worst_b;       /* the smallest pairwise B */
    double mean_jm;       /* mean pairwise JM */
    size_t worst_pair[2]; /* the classes of the worst pair */
} bands_score;

typedef struct bands_search_result {
    size_t count;         /* K */
    size_t *sets;         /* best set of size k (k = 1..K) at [(k - 1) * K], ascending */
    bands_score *scores;  /* per k */
    const char *search;   /* "exhaustive" or "sffs" */
    uint64_t evaluations; /* sets scored */
} bands_search_result;

/* Scores the set `set` of m candidates (m >= 1). THZ_ERR_INPUT when a covariance is not
 * positive definite on it. `work` holds 4 m^2 + 2 m doubles. */
thz_status bands_score_set(const bands_classes *cl, const size_t *set, size_t m, double *work,
                           bands_score *out, thz_error *err);

/* The Bhattacharyya distance that the Monte Carlo noise of classes i and j gives on `set`
 * (m candidates): with mean_var[class * n + c] the variance of a class mean's Monte Carlo
 * error, the means' difference d ~ N(0, D), D diagonal, has E[d^T S^-1 d] = tr(S^-1 D)
 * and variance 2 tr((S^-1 D)^2), S the pair's mean covariance; (mean + 3 standard
 * deviations) / 8 bounds the first term of B. spread_is_noise (the covariances hold the
 * render's noise, which no standard error let us take out): B's second term, the
 * covariances' difference, is added whole. A pair whose B is not above the result
 * cannot be told from two identical classes. `work` holds 2 m^2 + m doubles; NaN when a
 * covariance is not positive definite. */
double bands_noise_bhattacharyya(const bands_classes *cl, const size_t *set, size_t m, size_t i,
                                 size_t j, const double *mean_var, bool spread_is_noise,
                                 double *work);

/* Whether score a is better than b: worst-pair JM larger by more than 1e-3; when the
 * two are that close, the larger mean pairwise JM, and when that ties too (saturated
 * sets, JM = 2), the larger worst-pair B. */
int bands_score_better(const bands_score *a, const bands_score *b);

/* The best set of every size 1..count. At least two classes; count <= the groups and
 * <= BANDS_MAX_COUNT. Exhaustive when the sets of sizes 1..count number at most
 * exhaustive_limit, else SFFS. */
thz_status bands_search(const bands_classes *cl, size_t count, uint64_t exhaustive_limit,
                        bands_search_result *out, thz_error *err);

void bands_search_result_fini(bands_search_result *r);

#endif
