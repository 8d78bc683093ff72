/* Band selection's criterion and search (bands_search.h). */
#include "analysis/bands_search.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/linalg.h"
#include "core/alloc.h"

/* Worst-pair JM values closer than this count as tied (JM runs from 0 to 2). */
#define BANDS_JM_TIE 1e-3

void bands_search_result_fini(bands_search_result *r)
{
    free(r->sets);
    free(r->scores);
    memset(r, 0, sizeof *r);
}

/* The m x m submatrix of class k's covariance on `set`. */
static void sub_cov(const bands_classes *cl, size_t k, const size_t *set, size_t m, double *out)
{
    size_t n = cl->n_candidates;
    const double *c = cl->cov + k * n * n;
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++)
            out[i * m + j] = c[set[i] * n + set[j]];
}

double bands_noise_bhattacharyya(const bands_classes *cl, const size_t *set, size_t m, size_t i,
                                 size_t j, const double *mean_var, bool spread_is_noise,
                                 double *work)
{
    size_t n = cl->n_candidates;
    double *s = work, *inv = s + m * m, *e = inv + m * m;
    const double *ci = cl->cov + i * n * n, *cj = cl->cov + j * n * n;
    for (size_t a = 0; a < m; a++)
        for (size_t b = 0; b < m; b++)
            s[a * m + b] = 0.5 * (ci[set[a] * n + set[b]] + cj[set[a] * n + set[b]]);
    if (!linalg_cholesky(s, m))
        return NAN;
    double spread = 0.0; /* B's second term, all of it noise when spread_is_noise */
    if (spread_is_noise) {
        double logdet[2];
        for (size_t q = 0; q < 2; q++) {
            sub_cov(cl, q ? j : i, set, m, inv);
            if (!linalg_cholesky(inv, m))
                return NAN;
            logdet[q] = linalg_cholesky_logdet(inv, m);
        }
        spread = fmax(0.0, 0.5 * (linalg_cholesky_logdet(s, m) - 0.5 * (logdet[0] + logdet[1])));
    }
    for (size_t b = 0; b < m; b++) { /* column b of S^-1 */
        for (size_t a = 0; a < m; a++)
            e[a] = a == b;
        linalg_cholesky_solve(s, m, e, e);
        for (size_t a = 0; a < m; a++)
            inv[a * m + b] = e[a];
    }
    double mean = 0.0, var = 0.0;
    for (size_t a = 0; a < m; a++) {
        double da = mean_var[i * n + set[a]] + mean_var[j * n + set[a]];
        mean += inv[a * m + a] * da;
        for (size_t b = 0; b < m; b++) {
            double db = mean_var[i * n + set[b]] + mean_var[j * n + set[b]];
            var += 2.0 * inv[a * m + b] * inv[b * m + a] * da * db;
        }
    }
    return (mean + 3.0 * sqrt(var)) / 8.0 + spread;
}

thz_status bands_score_set(const bands_classes *cl, const size_t *set, size_t m, double *work,
                           bands_score *out, thz_error *err)
{
    double *a = work, *b = a + m * m, *s = b + m * m, *tmp = s + m * m, *d = tmp + m * m;
    double *w = d + m;
    size_t nc = cl->n_classes, n = cl->n_candidates;
    out->worst_jm = INFINITY;
    out->worst_b = INFINITY;
    out->mean_jm = 0.0;
    out->worst_pair[0] = out->worst_pair[1] = 0;
    size_t pairs = 0;
    for (size_t i = 0; i < nc; i++) {
        sub_cov(cl, i, set, m, a);
        memcpy(tmp, a, m * m * sizeof *a);
        if (!linalg_cholesky(tmp, m))
            goto not_definite;
        double logdet_i = linalg_cholesky_logdet(tmp, m);
        for (size_t j = i + 1; j < nc; j++) {
            sub_cov(cl, j, set, m, b);
            memcpy(tmp, b, m * m * sizeof *b);
            if (!linalg_cholesky(tmp, m))
                goto not_definite;
            double logdet_j = linalg_cholesky_logdet(tmp, m);
            for (size_t q = 0; q < m * m; q++)
                s[q] = 0.5 * (a[q] + b[q]);
            if (!linalg_cholesky(s, m))
                goto not_definite;
            for (size_t q = 0; q < m; q++)
                d[q] = cl->mean[i * n + set[q]] - cl->mean[j * n + set[q]];
            double bh = linalg_cholesky_quad(s, m, d, w) / 8.0 +
                        0.5 * (linalg_cholesky_logdet(s, m) - 0.5 * (logdet_i + logdet_j));
            if (bh < 0.0) /* rounding: B >= 0 */
                bh = 0.0;
            double jm = 2.0 * (1.0 - exp(-bh));
            out->mean_jm += jm;
            pairs++;
            if (bh < out->worst_b) {
                out->worst_b = bh;
                out->worst_jm = jm;
                out->worst_pair[0] = i;
                out->worst_pair[1] = j;
            }
        }
    }
    out->mean_jm = pairs ? out->mean_jm / (double)pairs : 0.0;
    return THZ_OK;
not_definite:
    return thz_error_set(err, THZ_ERR_INPUT,
                         "band selection: a class's covariance over the chosen channels is "
                         "not positive definite (its pixels do not vary in them; give the "
                         "sensor noise, NETD > 0 K, or wider nuisance ranges)");
}

int bands_score_better(const bands_score *a, const bands_score *b)
{
    if (fabs(a->worst_jm - b->worst_jm) > BANDS_JM_TIE)
        return a->worst_jm > b->worst_jm;
    if (fabs(a->mean_jm - b->mean_jm) > BANDS_JM_TIE)
        return a->mean_jm > b->mean_jm;
    return a->worst_b > b->worst_b;
}

/* The search's state: the best set and score found of every size. */
typedef struct search {
    const bands_classes *cl;
    size_t count;
    bands_search_result *r;
    bool *have; /* per size k - 1 */
    double *work;
    size_t tmp[BANDS_MAX_COUNT];
} search;

static int size_cmp(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* Scores `set` (m entries, any order) and records it as size m's best if it is. */
static thz_status consider(search *s, const size_t *set, size_t m, bands_score *score,
                           bool *improved, thz_error *err)
{
    thz_status st = bands_score_set(s->cl, set, m, s->work, score, err);
    s->r->evaluations++;
    *improved = false;
    if (st != THZ_OK)
        return st;
    bands_score *best = &s->r->scores[m - 1];
    if (!s->have[m - 1] || bands_score_better(score, best)) {
        *best = *score;
        size_t *dst = s->r->sets + (m - 1) * s->count;
        memcpy(dst, set, m * sizeof *set);
        qsort(dst, m, sizeof *dst, size_cmp);
        s->have[m - 1] = true;
        *improved = true;
    }
    return THZ_OK;
}

static size_t group_of(const bands_classes *cl, size_t c)
{
    return cl->group ? cl->group[c] : c;
}

/* Whether set (m entries, ascending) holds a group twice: groups are non-decreasing
 * with the candidate, so such entries are neighbours. */
static bool repeats_group(const bands_classes *cl, const size_t *set, size_t m)
{
    for (size_t i = 1; i < m; i++)
        if (group_of(cl, set[i]) == group_of(cl, set[i - 1]))
            return true;
    return false;
}

/* Every set of size m in lexicographic order (but those holding a group twice). */
static thz_status exhaustive(search *s, size_t m, thz_error *err)
{
    size_t n = s->cl->n_candidates;
    size_t idx[BANDS_MAX_COUNT];
    for (size_t i = 0; i < m; i++)
        idx[i] = i;
    for (;;) {
        bands_score sc;
        bool improved;
        thz_status st =
            repeats_group(s->cl, idx, m) ? THZ_OK : consider(s, idx, m, &sc, &improved, err);
        if (st != THZ_OK)
            return st;
        size_t i = m;
        while (i > 0 && idx[i - 1] == n - m + i - 1)
            i--;
        if (i == 0)
            return THZ_OK;
        idx[i - 1]++;
        for (size_t j = i; j < m; j++)
            idx[j] = idx[j - 1] + 1;
    }
}

/* Whether set (m entries) holds c's group already. */
static bool in_set(const bands_classes *cl, const size_t *set, size_t m, size_t c)
{
    for (size_t i = 0; i < m; i++)
        if (group_of(cl, set[i]) == group_of(cl, c))
            return true;
    return false;
}

/* Sequential floating forward selection (Pudil, Novovicova and Kittler, 1994): add the
 * best channel, then drop channels while dropping one gives a better set of the smaller
 * size than any seen; stop at size K. */
static thz_status sffs(search *s, thz_error *err)
{
    size_t n = s->cl->n_candidates, K = s->count;
    size_t cur[BANDS_MAX_COUNT], m = 0;
    bands_score sc;
    bool improved;
    size_t steps = 0, max_steps = 20 * K * K + 100; /* the floating loop always ends; a guard */
    while (m < K && steps++ < max_steps) {
        /* inclusion */
        size_t best_c = n;
        bands_score best = {0};
        for (size_t c = 0; c < n; c++) {
            if (in_set(s->cl, cur, m, c))
                continue;
            cur[m] = c;
            thz_status st = consider(s, cur, m + 1, &sc, &improved, err);
            if (st != THZ_OK)
                return st;
            if (best_c == n || bands_score_better(&sc, &best)) {
                best = sc;
                best_c = c;
            }
        }
        cur[m++] = best_c;
        if (bands_score_better(&s->r->scores[m - 1], &best)) /* a better set of this size */
            memcpy(cur, s->r->sets + (m - 1) * K, m * sizeof *cur);
        /* conditional exclusion */
        while (m > 2) {
            size_t drop = m;
            bands_score best_drop = {0};
            for (size_t i = 0; i < m; i++) {
                size_t t = 0;
                for (size_t j = 0; j < m; j++)
                    if (j != i)
                        s->tmp[t++] = cur[j];
                thz_status st = bands_score_set(s->cl, s->tmp, m - 1, s->work, &sc, err);
                s->r->evaluations++;
                if (st != THZ_OK)
                    return st;
                if (drop == m || bands_score_better(&sc, &best_drop)) {
                    best_drop = sc;
                    drop = i;
                }
            }
            if (!bands_score_better(&best_drop, &s->r->scores[m - 2]))
                break;
            for (size_t j = drop; j + 1 < m; j++)
                cur[j] = cur[j + 1];
            m--;
            thz_status st = consider(s, cur, m, &sc, &improved, err);
            if (st != THZ_OK)
                return st;
        }
    }
    return THZ_OK;
}

/* Sets of sizes 1..K among n, capped at limit + 1. */
static uint64_t count_sets(size_t n, size_t K, uint64_t limit)
{
    uint64_t total = 0;
    double c = 1.0;
    for (size_t k = 1; k <= K; k++) {
        c = c * (double)(n - k + 1) / (double)k;
        if (c + (double)total > (double)limit)
            return limit + 1;
        total += (uint64_t)llround(c);
    }
    return total;
}

thz_status bands_search(const bands_classes *cl, size_t count, uint64_t exhaustive_limit,
                        bands_search_result *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    if (cl->n_classes < 2)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "band selection needs at least two classes, got %zu", cl->n_classes);
    size_t groups = cl->n_candidates ? 1 : 0;
    for (size_t c = 1; c < cl->n_candidates; c++)
        groups += group_of(cl, c) != group_of(cl, c - 1);
    if (count < 1 || count > groups || count > BANDS_MAX_COUNT)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "count %zu: expected 1 to %zu (the candidate centres, at most %d)",
                             count, groups, BANDS_MAX_COUNT);
    search s = {.cl = cl, .count = count, .r = out};
    out->count = count;
    out->sets = thz_calloc(count * count, sizeof *out->sets);
    out->scores = thz_calloc(count, sizeof *out->scores);
    s.have = thz_calloc(count, sizeof *s.have);
    s.work = thz_calloc(4 * count * count + 2 * count, sizeof *s.work);
    thz_status st = THZ_OK;
    if (!out->sets || !out->scores || !s.have || !s.work) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (count_sets(cl->n_candidates, count, exhaustive_limit) <= exhaustive_limit) {
        out->search = "exhaustive";
        for (size_t m = 1; m <= count && st == THZ_OK; m++)
            st = exhaustive(&s, m, err);
    } else {
        out->search = "sffs";
        st = sffs(&s, err);
        for (size_t m = 1; m <= count && st == THZ_OK; m++)
            if (!s.have[m - 1])
                st = thz_error_set(err, THZ_ERR_INTERNAL, "SFFS ended without a set of %zu", m);
    }
done:
    free(s.have);
    free(s.work);
    if (st != THZ_OK)
        bands_search_result_fini(out);
    return st;
}
