/* Material recognition against a truth map (classify.h). */
#include "analysis/classify.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/linalg.h"
#include "core/alloc.h"
#include "core/rng.h"

/* Relative ridge added to every covariance (linalg_add_ridge): keeps a class of fewer
 * training pixels than bands, or of identical pixels, invertible. */
#define CLASSIFY_RIDGE 1e-6

static const char *const method_names[CLASSIFY_METHOD_COUNT] = {"sam", "mahalanobis", "lda",
                                                                "matched-filter", "ace"};

const char *classify_method_name(classify_method m)
{
    return (unsigned)m < CLASSIFY_METHOD_COUNT ? method_names[m] : "?";
}

int classify_method_from_name(const char *name)
{
    for (int m = 0; m < CLASSIFY_METHOD_COUNT; m++)
        if (name && strcmp(name, method_names[m]) == 0)
            return m;
    return -1;
}

void classify_result_fini(classify_result *r)
{
    free(r->class_object);
    free(r->assigned);
    free(r->train);
    free(r->confusion);
    free(r->class_accuracy);
    free(r->auc);
    free(r->roc_fpr);
    free(r->roc_tpr);
    memset(r, 0, sizeof *r);
}

void classify_add_noise(float *cube, size_t bands, size_t pixels, const double *sigma,
                        uint64_t seed)
{
    for (size_t b = 0; b < bands; b++) {
        if (!(sigma[b] > 0.0))
            continue;
        for (size_t p = 0; p < pixels; p++) {
            rng_stream rng; /* one stream per value: independent of any loop order */
            rng_init(&rng, seed, (uint32_t)b, RNG_PURPOSE_ANALYSIS, p);
            double u1 = rng_uniform_open0(&rng), u2 = rng_uniform(&rng);
            double z = sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2); /* Box-Muller */
            cube[b * pixels + p] = (float)((double)cube[b * pixels + p] + sigma[b] * z);
        }
    }
}

/* Per class: the training pixels' mean and scatter matrix sum (x - mean)(x - mean)^T. */
typedef struct class_stats {
    size_t n_classes, bands;
    uint64_t *n;     /* training pixels per class */
    double *mean;    /* [class * bands + b] */
    double *scatter; /* [class * bands^2 + i * bands + j] */
} class_stats;

static void stats_fini(class_stats *s)
{
    free(s->n);
    free(s->mean);
    free(s->scatter);
}

static thz_status stats_compute(const float *cube, size_t bands, size_t pixels, const int32_t *cls,
                                const uint8_t *train, size_t n_classes, class_stats *s,
                                thz_error *err)
{
    memset(s, 0, sizeof *s);
    s->n_classes = n_classes;
    s->bands = bands;
    s->n = thz_calloc(n_classes, sizeof *s->n);
    s->mean = thz_calloc(n_classes * bands, sizeof *s->mean);
    s->scatter = thz_calloc(n_classes * bands * bands, sizeof *s->scatter);
    double *x = thz_calloc(bands, sizeof *x);
    if (!s->n || !s->mean || !s->scatter || !x) {
        free(x);
        stats_fini(s);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    for (size_t p = 0; p < pixels; p++)
        if (cls[p] >= 0 && train[p]) {
            s->n[cls[p]]++;
            for (size_t b = 0; b < bands; b++)
                s->mean[(size_t)cls[p] * bands + b] += cube[b * pixels + p];
        }
    for (size_t k = 0; k < n_classes; k++)
        for (size_t b = 0; b < bands; b++)
            s->mean[k * bands + b] /= (double)s->n[k];
    for (size_t p = 0; p < pixels; p++) {
        if (cls[p] < 0 || !train[p])
            continue;
        size_t k = (size_t)cls[p];
        for (size_t b = 0; b < bands; b++)
            x[b] = cube[b * pixels + p] - s->mean[k * bands + b];
        double *sc = s->scatter + k * bands * bands;
        for (size_t i = 0; i < bands; i++)
            for (size_t j = 0; j < bands; j++)
                sc[i * bands + j] += x[i] * x[j];
    }
    free(x);
    return THZ_OK;
}

/* What scoring a pixel needs: per class a Cholesky factor (class covariance, pooled
 * covariance, or the background's covariance) and the means. */
typedef struct scorer {
    classify_method method;
    size_t n_classes, bands;
    const class_stats *stats;
    double *chol;    /* per class: bands^2 (Mahalanobis, MF, ACE), or one pooled (LDA) */
    double *bg_mean; /* per class: the mean of the other classes' training pixels */
    double *shat;    /* per class: Sigma^-1 s~ (MF, ACE) or Sigma^-1 m (LDA) */
    double *offset;  /* per class: s~^T Sigma^-1 s~ (MF, ACE), or LDA's constant */
    double *work, *work2;
} scorer;

static void scorer_fini(scorer *sc)
{
    free(sc->chol);
    free(sc->bg_mean);
    free(sc->shat);
    free(sc->offset);
    free(sc->work);
    free(sc->work2);
}

/* cov = scatter / (n - 1) (n <= 1: zero), ridged, factored. */
static bool factor_covariance(double *cov, const double *scatter, uint64_t n, size_t bands)
{
    double d = n > 1 ? (double)(n - 1) : 1.0;
    for (size_t i = 0; i < bands * bands; i++)
        cov[i] = n > 1 ? scatter[i] / d : 0.0;
    linalg_add_ridge(cov, bands, CLASSIFY_RIDGE);
    for (size_t i = 0; i < bands; i++)
        cov[i * bands + i] += 1e-12; /* a class of one pixel value: still definite */
    return linalg_cholesky(cov, bands);
}

static thz_status scorer_init(scorer *sc, classify_method method, const class_stats *st,
                              thz_error *err)
{
    memset(sc, 0, sizeof *sc);
    size_t nc = st->n_classes, nb = st->bands, nb2 = nb * nb;
    sc->method = method;
    sc->n_classes = nc;
    sc->bands = nb;
    sc->stats = st;
    sc->chol = thz_calloc(nc * nb2, sizeof *sc->chol);
    sc->bg_mean = thz_calloc(nc * nb, sizeof *sc->bg_mean);
    sc->shat = thz_calloc(nc * nb, sizeof *sc->shat);
    sc->offset = thz_calloc(nc, sizeof *sc->offset);
    sc->work = thz_calloc(nb, sizeof *sc->work);
    sc->work2 = thz_calloc(nb, sizeof *sc->work2);
    double *tmp = thz_calloc(nb2, sizeof *tmp);
    if (!sc->chol || !sc->bg_mean || !sc->shat || !sc->offset || !sc->work || !sc->work2 || !tmp) {
        free(tmp);
        scorer_fini(sc);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    uint64_t total = 0;
    for (size_t k = 0; k < nc; k++)
        total += st->n[k];
    bool ok = true;
    if (method == CLASSIFY_MAHALANOBIS) {
        for (size_t k = 0; k < nc && ok; k++)
            ok = factor_covariance(sc->chol + k * nb2, st->scatter + k * nb2, st->n[k], nb);
    } else if (method == CLASSIFY_LDA) {
        /* pooled within-class covariance; g_k = m^T W^-1 x - m^T W^-1 m / 2 + ln prior */
        memset(tmp, 0, nb2 * sizeof *tmp);
        for (size_t k = 0; k < nc; k++)
            for (size_t i = 0; i < nb2; i++)
                tmp[i] += st->scatter[k * nb2 + i];
        uint64_t dof = total > nc ? total - nc + 1 : 1;
        ok = factor_covariance(sc->chol, tmp, dof, nb);
        for (size_t k = 0; k < nc && ok; k++) {
            const double *m = st->mean + k * nb;
            linalg_cholesky_solve(sc->chol, nb, m, sc->shat + k * nb);
            double q = 0.0;
            for (size_t b = 0; b < nb; b++)
                q += m[b] * sc->shat[k * nb + b];
            sc->offset[k] = -0.5 * q + log((double)st->n[k] / (double)total);
        }
    } else if (method == CLASSIFY_MATCHED_FILTER || method == CLASSIFY_ACE) {
        /* background of class k: the other classes' training pixels, their mean and
         * covariance (scatter about the background mean: within-class scatters plus the
         * between-class part) */
        for (size_t k = 0; k < nc && ok; k++) {
            uint64_t nbg = total - st->n[k];
            double *mu = sc->bg_mean + k * nb;
            for (size_t j = 0; j < nc; j++)
                if (j != k)
                    for (size_t b = 0; b < nb; b++)
                        mu[b] += (double)st->n[j] * st->mean[j * nb + b];
            for (size_t b = 0; b < nb; b++)
                mu[b] = nbg ? mu[b] / (double)nbg : 0.0;
            memset(tmp, 0, nb2 * sizeof *tmp);
            for (size_t j = 0; j < nc; j++) {
                if (j == k)
                    continue;
                const double *mj = st->mean + j * nb;
                for (size_t a = 0; a < nb; a++)
                    for (size_t b = 0; b < nb; b++)
                        tmp[a * nb + b] += st->scatter[j * nb2 + a * nb + b] +
                                           (double)st->n[j] * (mj[a] - mu[a]) * (mj[b] - mu[b]);
            }
            double *l = sc->chol + k * nb2;
            ok = factor_covariance(l, tmp, nbg, nb);
            if (!ok)
                break;
            for (size_t b = 0; b < nb; b++)
                sc->work[b] = st->mean[k * nb + b] - mu[b];
            linalg_cholesky_solve(l, nb, sc->work, sc->shat + k * nb);
            double q = 0.0;
            for (size_t b = 0; b < nb; b++)
                q += sc->work[b] * sc->shat[k * nb + b];
            sc->offset[k] = q > 0.0 ? q : 1e-300;
        }
    }
    free(tmp);
    if (!ok) {
        scorer_fini(sc);
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: a class covariance is not positive definite (values not "
                             "finite?)",
                             classify_method_name(method));
    }
    return THZ_OK;
}

/* Scores of pixel x for every class (higher: more like that class). */
static void score_pixel(scorer *sc, const double *x, double *score)
{
    const class_stats *st = sc->stats;
    size_t nb = sc->bands, nb2 = nb * nb;
    for (size_t k = 0; k < sc->n_classes; k++) {
        const double *m = st->mean + k * nb;
        double s = 0.0;
        switch (sc->method) {
        case CLASSIFY_SAM: {
            double xm = 0.0, xx = 0.0, mm = 0.0;
            for (size_t b = 0; b < nb; b++) {
                xm += x[b] * m[b];
                xx += x[b] * x[b];
                mm += m[b] * m[b];
            }
            double c = xx > 0.0 && mm > 0.0 ? xm / sqrt(xx * mm) : 0.0;
            s = -acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c);
            break;
        }
        case CLASSIFY_MAHALANOBIS:
            for (size_t b = 0; b < nb; b++)
                sc->work2[b] = x[b] - m[b];
            s = -linalg_cholesky_quad(sc->chol + k * nb2, nb, sc->work2, sc->work);
            break;
        case CLASSIFY_LDA:
            s = sc->offset[k];
            for (size_t b = 0; b < nb; b++)
                s += sc->shat[k * nb + b] * x[b];
            break;
        case CLASSIFY_MATCHED_FILTER:
        case CLASSIFY_ACE: {
            const double *mu = sc->bg_mean + k * nb;
            double t = 0.0;
            for (size_t b = 0; b < nb; b++) {
                sc->work2[b] = x[b] - mu[b];
                t += sc->shat[k * nb + b] * sc->work2[b];
            }
            if (sc->method == CLASSIFY_MATCHED_FILTER) {
                s = t / sc->offset[k]; /* 1 at the target's mean, 0 at the background's */
            } else {
                double xx = linalg_cholesky_quad(sc->chol + k * nb2, nb, sc->work2, sc->work);
                s = xx > 0.0 ? (t >= 0.0 ? 1.0 : -1.0) * t * t / (sc->offset[k] * xx) : 0.0;
            }
            break;
        }
        case CLASSIFY_METHOD_COUNT:
            break;
        }
        score[k] = s;
    }
}

/* The score a ROC of class k thresholds: the detectors' own statistic (matched filter,
 * ACE: each is a detector of one target); for the classifiers, the margin of class k's
 * score over the best other class's, which is > 0 exactly where the pixel is assigned
 * to k (a discriminant alone is not comparable between pixels). */
static double roc_score(classify_method method, const double *s, size_t nc, size_t k)
{
    if (method == CLASSIFY_MATCHED_FILTER || method == CLASSIFY_ACE)
        return s[k];
    double other = -INFINITY;
    for (size_t j = 0; j < nc; j++)
        if (j != k && s[j] > other)
            other = s[j];
    return nc > 1 ? s[k] - other : s[k];
}

typedef struct scored {
    double score;
    int positive;
} scored;

static int scored_cmp(const void *a, const void *b)
{
    double x = ((const scored *)a)->score, y = ((const scored *)b)->score;
    return x > y ? -1 : x < y ? 1 : 0; /* descending */
}

/* ROC of one class against the rest from its held-out scores (sorted in place), its
 * area by the trapezoid rule over groups of tied scores (the Mann-Whitney statistic). */
static double roc_curve(scored *v, size_t n, double *fpr, double *tpr)
{
    size_t pos = 0;
    for (size_t i = 0; i < n; i++)
        pos += (size_t)v[i].positive;
    size_t neg = n - pos;
    for (size_t i = 0; i < CLASSIFY_ROC_POINTS; i++)
        fpr[i] = tpr[i] = NAN;
    if (!pos || !neg)
        return NAN;
    qsort(v, n, sizeof *v, scored_cmp);
    double area = 0.0;
    size_t tp = 0, fp = 0;
    /* the curve after every group of ties, sampled at CLASSIFY_ROC_POINTS ranks */
    size_t next_point = 0;
    fpr[0] = tpr[0] = 0.0;
    next_point = 1;
    for (size_t i = 0; i < n;) {
        size_t j = i, dtp = 0, dfp = 0;
        while (j < n && (j == i || v[j].score == v[i].score)) { /* NaN: a group of one */
            dtp += (size_t)v[j].positive;
            dfp += (size_t)!v[j].positive;
            j++;
        }
        area += (double)dfp * ((double)tp + 0.5 * (double)dtp);
        tp += dtp;
        fp += dfp;
        while (next_point < CLASSIFY_ROC_POINTS &&
               (next_point * n) / (CLASSIFY_ROC_POINTS - 1) <= j) {
            fpr[next_point] = (double)fp / (double)neg;
            tpr[next_point] = (double)tp / (double)pos;
            next_point++;
        }
        i = j;
    }
    return area / ((double)pos * (double)neg);
}

/* Marks train_fraction of each class's pixels (at least one) as training pixels: a
 * Fisher-Yates shuffle of the class's pixels in scan order, keyed by (seed, class). */
static thz_status split_train(const int32_t *cls, size_t pixels, size_t n_classes, double fraction,
                              uint64_t seed, uint8_t *train, thz_error *err)
{
    size_t *idx = thz_calloc(pixels, sizeof *idx);
    if (!idx)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t k = 0; k < n_classes; k++) {
        size_t n = 0;
        for (size_t p = 0; p < pixels; p++)
            if (cls[p] == (int32_t)k)
                idx[n++] = p;
        rng_stream rng;
        rng_init(&rng, seed, (uint32_t)k, RNG_PURPOSE_ANALYSIS, UINT64_MAX);
        for (size_t i = n; i > 1; i--) {
            size_t j = (size_t)(rng_uniform(&rng) * (double)i);
            size_t t = idx[i - 1];
            idx[i - 1] = idx[j];
            idx[j] = t;
        }
        size_t n_train = (size_t)floor(fraction * (double)n + 0.5);
        if (n_train < 1)
            n_train = 1;
        for (size_t i = 0; i < n_train && i < n; i++)
            train[idx[i]] = 1;
    }
    free(idx);
    return THZ_OK;
}

thz_status classify_run(const float *cube, size_t bands, size_t pixels, const int32_t *truth,
                        classify_method method, double train_fraction, uint64_t seed,
                        classify_result *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    if ((unsigned)method >= CLASSIFY_METHOD_COUNT || bands == 0 ||
        !(train_fraction > 0.0 && train_fraction < 1.0))
        return thz_error_set(err, THZ_ERR_INPUT, "classify: bad method, bands or fraction");
    int32_t max_id = -1;
    for (size_t p = 0; p < pixels; p++)
        if (truth[p] > max_id)
            max_id = truth[p];
    if (max_id < 0)
        return thz_error_set(err, THZ_ERR_INPUT, "the truth map shows no object (all -1)");
    for (size_t i = 0; i < bands * pixels; i++)
        if (!isfinite(cube[i]))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "the cube holds a value that is not finite (band %zu, pixel %zu)",
                                 i / pixels + 1, i % pixels);
    thz_status st = THZ_OK;
    class_stats stats = {0};
    scorer sc = {0};
    int32_t *class_of = thz_calloc((size_t)max_id + 1, sizeof *class_of);
    int32_t *cls = thz_calloc(pixels, sizeof *cls);
    double *x = thz_calloc(bands, sizeof *x);
    scored *sv = NULL;
    double *scores = NULL;
    if (!class_of || !cls || !x)
        goto nomem;
    for (size_t p = 0; p < pixels; p++)
        if (truth[p] >= 0)
            class_of[truth[p]] = 1;
    size_t nc = 0;
    for (int32_t o = 0; o <= max_id; o++)
        class_of[o] = class_of[o] ? (int32_t)nc++ : -1;
    out->n_classes = nc;
    out->pixels = pixels;
    out->class_object = thz_calloc(nc, sizeof *out->class_object);
    out->assigned = thz_calloc(pixels, sizeof *out->assigned);
    out->train = thz_calloc(pixels, sizeof *out->train);
    out->confusion = thz_calloc(nc * nc, sizeof *out->confusion);
    out->class_accuracy = thz_calloc(nc, sizeof *out->class_accuracy);
    out->auc = thz_calloc(nc, sizeof *out->auc);
    out->roc_fpr = thz_calloc(nc * CLASSIFY_ROC_POINTS, sizeof *out->roc_fpr);
    out->roc_tpr = thz_calloc(nc * CLASSIFY_ROC_POINTS, sizeof *out->roc_tpr);
    scores = thz_calloc(pixels * nc, sizeof *scores);
    sv = thz_calloc(pixels, sizeof *sv);
    if (!out->class_object || !out->assigned || !out->train || !out->confusion ||
        !out->class_accuracy || !out->auc || !out->roc_fpr || !out->roc_tpr || !scores || !sv)
        goto nomem;
    for (int32_t o = 0; o <= max_id; o++)
        if (class_of[o] >= 0)
            out->class_object[class_of[o]] = o;
    for (size_t p = 0; p < pixels; p++)
        cls[p] = truth[p] >= 0 ? class_of[truth[p]] : -1;

    st = split_train(cls, pixels, nc, train_fraction, seed, out->train, err);
    if (st == THZ_OK)
        st = stats_compute(cube, bands, pixels, cls, out->train, nc, &stats, err);
    if (st == THZ_OK)
        st = scorer_init(&sc, method, &stats, err);
    if (st != THZ_OK)
        goto cleanup;

    uint64_t correct = 0, held = 0, held_correct = 0, seen = 0;
    for (size_t p = 0; p < pixels; p++) {
        out->assigned[p] = -1;
        if (cls[p] < 0)
            continue;
        for (size_t b = 0; b < bands; b++)
            x[b] = cube[b * pixels + p];
        double *s = scores + p * nc;
        score_pixel(&sc, x, s);
        size_t best = 0;
        for (size_t k = 1; k < nc; k++)
            if (s[k] > s[best])
                best = k;
        out->assigned[p] = out->class_object[best];
        out->confusion[(size_t)cls[p] * nc + best]++;
        seen++;
        correct += best == (size_t)cls[p];
        if (!out->train[p]) {
            held++;
            held_correct += best == (size_t)cls[p];
        } else {
            out->n_train++;
        }
    }
    out->n_held_out = held;
    out->accuracy = (double)correct / (double)seen;
    out->held_out_accuracy = held ? (double)held_correct / (double)held : NAN;
    for (size_t k = 0; k < nc; k++) {
        uint64_t row = 0;
        for (size_t j = 0; j < nc; j++)
            row += out->confusion[k * nc + j];
        out->class_accuracy[k] = row ? (double)out->confusion[k * nc + k] / (double)row : NAN;
        size_t n = 0;
        for (size_t p = 0; p < pixels; p++)
            if (cls[p] >= 0 && !out->train[p]) {
                sv[n].score = roc_score(method, scores + p * nc, nc, k);
                sv[n].positive = cls[p] == (int32_t)k;
                n++;
            }
        out->auc[k] = roc_curve(sv, n, out->roc_fpr + k * CLASSIFY_ROC_POINTS,
                                out->roc_tpr + k * CLASSIFY_ROC_POINTS);
    }
    goto cleanup;
nomem:
    st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
cleanup:
    scorer_fini(&sc);
    stats_fini(&stats);
    free(class_of);
    free(cls);
    free(x);
    free(sv);
    free(scores);
    if (st != THZ_OK)
        classify_result_fini(out);
    return st;
}
