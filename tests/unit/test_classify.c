/* Classification (analysis/classify.c): on a synthetic cube of three distinct spectra
 * every method is exact without noise; with noise raised the accuracy falls
 * monotonically; the confusion matrix sums to the pixels that see an object, its rows
 * to each object's (the truth) and its columns to the pixels assigned each; the
 * training split depends on the seed alone; the AUC and the ROC's points are those of
 * the held-out pixels, ties counted one half, against a count done here. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "analysis/classify.h"

enum { BANDS = 4, COLS = 30, ROWS = 20, PIXELS = COLS * ROWS };

/* Objects 0, 2 and 5 (indices need not be contiguous) in vertical stripes; the first
 * column sees nothing (-1). Spectra in K, 1-2 K apart in one or two bands. */
static const double spectra[3][BANDS] = {
    {300.0, 300.0, 300.0, 300.0}, {300.0, 302.0, 300.0, 300.0}, {300.0, 300.0, 301.5, 301.5}};
static const int32_t objects[3] = {0, 2, 5};

static void make_cube(float *cube, int32_t *truth)
{
    for (size_t p = 0; p < PIXELS; p++) {
        size_t col = p % COLS;
        int cls = col == 0 ? -1 : (int)((col - 1) * 3 / (COLS - 1));
        truth[p] = cls < 0 ? -1 : objects[cls];
        for (size_t b = 0; b < BANDS; b++)
            cube[b * PIXELS + p] = cls < 0 ? 0.0f : (float)spectra[cls][b];
    }
}

static uint64_t confusion_sum(const classify_result *r)
{
    uint64_t s = 0;
    for (size_t i = 0; i < r->n_classes * r->n_classes; i++)
        s += r->confusion[i];
    return s;
}

/* Rows are the truth and columns the class assigned (docs/analysis.md): row k sums to
 * the pixels of class k's object, column j to the pixels assigned object j. Transposed,
 * the sums still hold in total and the accuracy stays, but a class's accuracy (the
 * diagonal over its row) becomes its precision. */
static void assert_confusion_rows_are_truth(const classify_result *r, const int32_t *truth)
{
    size_t nc = r->n_classes;
    for (size_t k = 0; k < nc; k++) {
        uint64_t in_truth = 0, assigned = 0, row = 0, column = 0;
        for (size_t p = 0; p < PIXELS; p++) {
            in_truth += truth[p] == r->class_object[k];
            assigned += truth[p] >= 0 && r->assigned[p] == r->class_object[k];
        }
        for (size_t j = 0; j < nc; j++) {
            row += r->confusion[k * nc + j];
            column += r->confusion[j * nc + k];
        }
        assert_int_equal(row, in_truth);
        assert_int_equal(column, assigned);
        /* a class's accuracy is its recall: its pixels assigned to it over its pixels
         * (analysis.md), not its precision (over the pixels assigned to it) */
        uint64_t hits = 0;
        for (size_t p = 0; p < PIXELS; p++)
            hits += truth[p] == r->class_object[k] && r->assigned[p] == r->class_object[k];
        assert_true(r->class_accuracy[k] == (double)hits / (double)in_truth);
    }
}

static void test_noise_free_exact(void **state)
{
    (void)state;
    static float cube[BANDS * PIXELS];
    static int32_t truth[PIXELS];
    make_cube(cube, truth);
    /* tiny noise so that covariances are estimated from something */
    double sigma[BANDS] = {1e-3, 1e-3, 1e-3, 1e-3};
    classify_add_noise(cube, BANDS, PIXELS, sigma, 7);
    for (int m = 0; m < CLASSIFY_METHOD_COUNT; m++) {
        classify_result r;
        thz_error err = {0};
        assert_int_equal(
            classify_run(cube, BANDS, PIXELS, truth, (classify_method)m, 0.5, 1, &r, &err), THZ_OK);
        assert_int_equal(r.n_classes, 3);
        assert_int_equal(r.class_object[1], 2);
        assert_int_equal(r.class_object[2], 5);
        assert_int_equal(confusion_sum(&r), PIXELS - ROWS); /* all but column 0 */
        assert_int_equal(r.n_train + r.n_held_out, PIXELS - ROWS);
        assert_true(r.accuracy == 1.0);
        for (size_t k = 0; k < 3; k++)
            assert_true(r.auc[k] == 1.0);
        for (size_t p = 0; p < PIXELS; p++)
            assert_int_equal(r.assigned[p], truth[p]);
        classify_result_fini(&r);
    }
}

static void test_accuracy_falls_with_noise(void **state)
{
    (void)state;
    static float clean[BANDS * PIXELS], cube[BANDS * PIXELS];
    static int32_t truth[PIXELS];
    make_cube(clean, truth);
    const double levels[] = {0.01, 0.3, 1.0, 3.0, 10.0}; /* K */
    for (int m = 0; m < CLASSIFY_METHOD_COUNT; m++) {
        double last = 2.0;
        for (size_t i = 0; i < sizeof levels / sizeof levels[0]; i++) {
            memcpy(cube, clean, sizeof cube);
            double sigma[BANDS];
            for (size_t b = 0; b < BANDS; b++)
                sigma[b] = levels[i];
            classify_add_noise(cube, BANDS, PIXELS, sigma, 3);
            classify_result r;
            thz_error err = {0};
            assert_int_equal(
                classify_run(cube, BANDS, PIXELS, truth, (classify_method)m, 0.5, 1, &r, &err),
                THZ_OK);
            assert_int_equal(confusion_sum(&r), PIXELS - ROWS);
            assert_confusion_rows_are_truth(&r, truth);
            if (!(r.held_out_accuracy <= last))
                fail_msg("%s: held-out accuracy %g at %g K above %g at the level before",
                         classify_method_name((classify_method)m), r.held_out_accuracy, levels[i],
                         last);
            last = r.held_out_accuracy;
            if (i == 0)
                assert_true(r.held_out_accuracy == 1.0);
            classify_result_fini(&r);
        }
        /* 10 K of noise on 1-2 K differences: close to chance (1/3) */
        assert_true(last < 0.6);
    }
}

/* One band, two classes of 120 and 80 pixels (objects 0 and 1) on a grid of integer
 * values that overlap, so that held-out pixels of both classes tie: class 0 holds 10 ..
 * 29, class 1 0 .. 19, each value 6 resp. 4 times. LDA's margin of class 0 rises with
 * the value (its mean is the larger), so its ROC is the value's: the test's own
 * Mann-Whitney count over the held-out pixels (a tie counting one half) and the curve
 * after the pixels down to the i-th largest value, point i of 100 at rank i n / 100. */
enum { ROC_A = 120, ROC_B = 80, ROC_PIXELS = ROC_A + ROC_B };

static void test_auc_and_roc_of_held_out_pixels(void **state)
{
    (void)state;
    static float cube[ROC_PIXELS];
    static int32_t truth[ROC_PIXELS];
    for (size_t p = 0; p < ROC_PIXELS; p++) {
        truth[p] = p < ROC_A ? 0 : 1;
        cube[p] = p < ROC_A ? (float)(10 + p % 20) : (float)((p - ROC_A) % 20);
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 1, ROC_PIXELS, truth, CLASSIFY_LDA, 0.5, 3, &r, &err),
                     THZ_OK);
    /* held out: 60 of class 0, 40 of class 1, 100 in all (a ROC point per rank) */
    assert_int_equal(r.n_held_out, 100);
    double x[100];
    int positive[100];
    size_t n = 0, pos = 0, neg = 0;
    for (size_t p = 0; p < ROC_PIXELS; p++)
        if (!r.train[p]) {
            x[n] = cube[p];
            positive[n] = truth[p] == 0;
            pos += (size_t)positive[n];
            n++;
        }
    assert_int_equal(n, 100);
    neg = n - pos;
    assert_int_equal(pos, 60);
    double wins = 0.0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            if (positive[i] && !positive[j])
                wins += x[i] > x[j] ? 1.0 : x[i] == x[j] ? 0.5 : 0.0;
    double auc = wins / ((double)pos * (double)neg);
    assert_true(auc > 0.8 && auc < 0.99); /* the case has overlap and ties */
    if (!(fabs(r.auc[0] - auc) < 1e-12))
        fail_msg("AUC of class 0 %.15g, the held-out pixels' Mann-Whitney count %.15g", r.auc[0],
                 auc);
    /* class 1's margin is class 0's negated: the same area */
    assert_true(fabs(r.auc[1] - auc) < 1e-12);
    double sorted[100];
    memcpy(sorted, x, sizeof sorted);
    for (size_t i = 1; i < n; i++) /* descending */
        for (size_t j = i; j > 0 && sorted[j] > sorted[j - 1]; j--) {
            double t = sorted[j];
            sorted[j] = sorted[j - 1];
            sorted[j - 1] = t;
        }
    assert_true(r.roc_fpr[0] == 0.0 && r.roc_tpr[0] == 0.0);
    for (size_t i = 1; i < CLASSIFY_ROC_POINTS; i++) {
        double threshold = sorted[i - 1]; /* rank i = i n / 100 with n = 100 */
        size_t tp = 0, fp = 0;
        for (size_t j = 0; j < n; j++)
            if (x[j] >= threshold) {
                tp += (size_t)positive[j];
                fp += (size_t)!positive[j];
            }
        double want_fpr = (double)fp / (double)neg, want_tpr = (double)tp / (double)pos;
        if (!(fabs(r.roc_fpr[i] - want_fpr) < 1e-12 && fabs(r.roc_tpr[i] - want_tpr) < 1e-12))
            fail_msg("ROC point %zu: (%g, %g), expected (%g, %g)", i, r.roc_fpr[i], r.roc_tpr[i],
                     want_fpr, want_tpr);
    }
    assert_true(r.roc_fpr[CLASSIFY_ROC_POINTS - 1] == 1.0);
    assert_true(r.roc_tpr[CLASSIFY_ROC_POINTS - 1] == 1.0);
    classify_result_fini(&r);
}

/* Four classes of unequal sizes in two bands: A (200 pixels) on the segment between B
 * (40) and D (60), C (100) off that line, 1.5-4 K apart, noise 0.05 K. The classifiers
 * and ACE assign every pixel its class; every method ranks all held-out pixels of a
 * corner of the classes' hull (B, C, D) above the rest (AUC 1). The matched filter, a
 * linear detector, cannot single out A, between B and D, and is not exact (its
 * assignments compare targets). Its background is the other classes' training pixels
 * with their counts as weights: their means unweighted, C's AUC fell to 0.8. */
static void test_unequal_classes(void **state)
{
    (void)state;
    enum { N = 400 };
    static const double tb[4][2] = {{300.0, 300.0}, {302.0, 300.0}, {300.0, 301.5}, {296.0, 300.0}};
    static const size_t count[4] = {200, 40, 100, 60};
    static float cube[2 * N];
    static int32_t truth[N];
    size_t p = 0;
    for (size_t k = 0; k < 4; k++)
        for (size_t i = 0; i < count[k]; i++, p++) {
            truth[p] = (int32_t)k;
            for (size_t b = 0; b < 2; b++)
                cube[b * N + p] = (float)tb[k][b];
        }
    assert_int_equal(p, N);
    const double sd[2] = {0.05, 0.05};
    classify_add_noise(cube, 2, N, sd, 5);
    for (int m = 0; m < CLASSIFY_METHOD_COUNT; m++) {
        classify_result r;
        thz_error err = {0};
        assert_int_equal(classify_run(cube, 2, N, truth, (classify_method)m, 0.5, 1, &r, &err),
                         THZ_OK);
        const char *name = classify_method_name((classify_method)m);
        if (m != CLASSIFY_MATCHED_FILTER && !(r.accuracy == 1.0))
            fail_msg("%s: accuracy %g", name, r.accuracy);
        for (size_t k = 1; k < 4; k++)
            if (!(r.auc[k] == 1.0))
                fail_msg("%s: AUC of class %zu %g", name, k, r.auc[k]);
        classify_result_fini(&r);
    }
}

static void test_split_depends_on_seed(void **state)
{
    (void)state;
    static float cube[BANDS * PIXELS];
    static int32_t truth[PIXELS];
    make_cube(cube, truth);
    classify_result a, b, c;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, BANDS, PIXELS, truth, CLASSIFY_SAM, 0.5, 11, &a, &err),
                     THZ_OK);
    assert_int_equal(classify_run(cube, BANDS, PIXELS, truth, CLASSIFY_SAM, 0.5, 11, &b, &err),
                     THZ_OK);
    assert_int_equal(classify_run(cube, BANDS, PIXELS, truth, CLASSIFY_SAM, 0.5, 12, &c, &err),
                     THZ_OK);
    assert_memory_equal(a.train, b.train, PIXELS);
    assert_true(memcmp(a.train, c.train, PIXELS) != 0);
    /* half of each class (19 x 10 = 190 pixels of each... in stripes of 9 or 10 columns) */
    assert_true(a.n_train >= (PIXELS - ROWS) / 2 - 2 && a.n_train <= (PIXELS - ROWS) / 2 + 2);
    classify_result_fini(&a);
    classify_result_fini(&b);
    classify_result_fini(&c);
}

/* The split is a shuffle of each class's pixels: in a class of two pixels, half training,
 * each pixel trains for about half of the seeds (40 seeds: 20 +- 3.2 sigma). A shuffle
 * that stopped before its last swap (a mutant) passed every test: it never moved the
 * class's first pixel out of the first place, so that it trained for every seed. */
static void test_split_is_a_shuffle(void **state)
{
    (void)state;
    enum { N = 6, SEEDS = 40 };
    const float cube[2 * N] = {300, 300, 302, 302, 304, 304, 300, 300, 300, 300, 301, 301};
    const int32_t truth[N] = {0, 0, 1, 1, 2, 2};
    size_t first_trains[3] = {0, 0, 0};
    for (uint64_t seed = 1; seed <= SEEDS; seed++) {
        classify_result r;
        thz_error err = {0};
        assert_int_equal(classify_run(cube, 2, N, truth, CLASSIFY_LDA, 0.5, seed, &r, &err),
                         THZ_OK);
        for (size_t k = 0; k < 3; k++) {
            assert_int_equal(r.train[2 * k] + r.train[2 * k + 1], 1);
            first_trains[k] += r.train[2 * k];
        }
        classify_result_fini(&r);
    }
    for (size_t k = 0; k < 3; k++)
        if (first_trains[k] < 10 || first_trains[k] > 30)
            fail_msg("class %zu: its first pixel trained for %zu of %d seeds", k, first_trains[k],
                     SEEDS);
}

/* A tie goes to the class of the lower object index (analysis.md): two objects whose
 * spectra have the same shape, (300, 301) K and twice that, are the same to `sam` (angle 0
 * to both means, exactly: the means are whole numbers and the second is twice the
 * first), so every pixel goes to object 3, none to object 7; the last class taking the
 * ties passed every test. */
static void test_tie_goes_to_lower_object(void **state)
{
    (void)state;
    enum { N = 40 };
    float cube[2 * N];
    int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        double scale = p < N / 2 ? 1.0 : 2.0;
        truth[p] = p < N / 2 ? 3 : 7;
        cube[p] = (float)(300.0 * scale);
        cube[N + p] = (float)(301.0 * scale);
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 2, N, truth, CLASSIFY_SAM, 0.5, 1, &r, &err), THZ_OK);
    for (size_t p = 0; p < N; p++)
        assert_int_equal(r.assigned[p], 3);
    assert_true(r.accuracy == 0.5);
    classify_result_fini(&r);
}

/* LDA's prior: one band, object 0 of 180 pixels at -1 and +1 K (mean 0, variance 1),
 * object 1 of 20 at +1 and +3 K (mean 2, variance 1). At x = 1 K, midway, the
 * discriminants differ by ln(180 / 20) = 2.2 in favour of object 0, against what the
 * training half's means move them by (0.1 and 0.3 K standard errors: about +-0.35): every
 * pixel at 1 K goes to object 0. With the prior's sign reversed they went to object 1;
 * the test of unequal classes did not see it. */
static void test_lda_prior(void **state)
{
    (void)state;
    enum { N = 200, N0 = 180 };
    float cube[N];
    int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        truth[p] = p < N0 ? 0 : 1;
        cube[p] = p < N0 ? (p % 2 ? 1.0f : -1.0f) : (p % 2 ? 1.0f : 3.0f);
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 1, N, truth, CLASSIFY_LDA, 0.5, 1, &r, &err), THZ_OK);
    for (size_t p = 0; p < N; p++)
        if (cube[p] <= 1.0f)
            assert_int_equal(r.assigned[p], 0);
    classify_result_fini(&r);
}

/* The matched filter's statistic is normalised, 1 at the target's mean and 0 at the
 * background's, so that the classes' scores compare: one band, object 0 at -1 and +1 K
 * (mean 0, variance 1), object 1 at 4 and 16 K (mean 10, variance 36). A pixel at 1 K
 * scores (1 - 10) / (0 - 10) = 0.9 as object 0 and 1 / 10 = 0.1 as object 1; unnormalised,
 * s~ Sigma_b^-1 (x - mu_b) gives 10 x 9 / 36 = 2.5 against 10 x 1 / 1 = 10, and every pixel
 * of object 0 at +1 K went to object 1 (the noise-free test's classes have equal spreads,
 * where the two agree). */
static void test_matched_filter_normalised(void **state)
{
    (void)state;
    enum { N = 200 };
    float cube[N];
    int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        truth[p] = p < N / 2 ? 0 : 1;
        cube[p] = p < N / 2 ? (p % 2 ? 1.0f : -1.0f) : (p % 2 ? 4.0f : 16.0f);
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 1, N, truth, CLASSIFY_MATCHED_FILTER, 0.5, 1, &r, &err),
                     THZ_OK);
    for (size_t p = 0; p < N / 2; p++)
        assert_int_equal(r.assigned[p], 0);
    classify_result_fini(&r);
}

/* --netd-k X adds Gaussian noise of X K (classify_add_noise): 4000 values of 0 K with
 * sigma 0.5 K in band 0 have a spread of 0.5 K within 3 / sqrt(2 (N - 1)) of it and a mean
 * of 0 within 3 sigma / sqrt(N); band 1, sigma 0, is untouched. A noise of sigma^2
 * (0.25 K here) passed every test. */
static void test_added_noise_spread(void **state)
{
    (void)state;
    enum { N = 4000 };
    static float cube[2 * N];
    memset(cube, 0, sizeof cube);
    const double sigma[2] = {0.5, 0.0};
    classify_add_noise(cube, 2, N, sigma, 7);
    double sum = 0.0, sum2 = 0.0;
    for (size_t p = 0; p < N; p++) {
        sum += cube[p];
        sum2 += (double)cube[p] * cube[p];
        assert_true(cube[N + p] == 0.0f);
    }
    double mean = sum / N, sd = sqrt((sum2 - N * mean * mean) / (N - 1));
    if (!(fabs(sd / 0.5 - 1.0) < 3.0 / sqrt(2.0 * (N - 1)) && fabs(mean) < 3.0 * 0.5 / sqrt(N)))
        fail_msg("noise of 0.5 K: spread %.4f K, mean %+.4f K", sd, mean);
}

/* Mahalanobis with each class's own covariance, the unbiased scatter / (n - 1): one band,
 * object 0 of 5 pixels (0 .. 4 K: 3 train) against object 1 of 120 (3 .. 14.9 K), whose
 * distances are recomputed here from the training pixels the result reports. Every pixel
 * whose two distances differ by more than 1e-3 (the ridge is 1e-6) must go to the nearer
 * class; with scatter / n the small class's variance is 2/3 of that and some pixels
 * between the classes change sides (checked below, so that the test can fail), which
 * passed every test. */
static double class_distance(const float *x, const int32_t *truth, const uint8_t *train, size_t n,
                             int32_t object, double v, bool unbiased)
{
    double sum = 0.0, sum2 = 0.0, k = 0.0;
    for (size_t p = 0; p < n; p++)
        if (truth[p] == object && train[p]) {
            sum += x[p];
            k += 1.0;
        }
    double mean = sum / k;
    for (size_t p = 0; p < n; p++)
        if (truth[p] == object && train[p])
            sum2 += (x[p] - mean) * (x[p] - mean);
    double var = sum2 / (unbiased ? k - 1.0 : k);
    return (v - mean) * (v - mean) / var;
}

static void test_mahalanobis_unbiased_covariance(void **state)
{
    (void)state;
    enum { N0 = 5, N = 125 };
    float cube[N];
    int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        truth[p] = p < N0 ? 0 : 1;
        cube[p] = p < N0 ? (float)p : (float)(3.0 + 0.1 * (double)(p - N0));
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 1, N, truth, CLASSIFY_MAHALANOBIS, 0.5, 1, &r, &err),
                     THZ_OK);
    size_t checked = 0, flips = 0;
    for (size_t p = 0; p < N; p++) {
        double d0 = class_distance(cube, truth, r.train, N, 0, cube[p], true);
        double d1 = class_distance(cube, truth, r.train, N, 1, cube[p], true);
        double b0 = class_distance(cube, truth, r.train, N, 0, cube[p], false);
        double b1 = class_distance(cube, truth, r.train, N, 1, cube[p], false);
        if (fabs(d0 - d1) <= 1e-3 * (d0 + d1))
            continue;
        assert_int_equal(r.assigned[p], d0 < d1 ? 0 : 1);
        checked++;
        flips += (d0 < d1) != (b0 < b1);
    }
    assert_true(checked > N - 3);
    assert_true(flips > 0);
    classify_result_fini(&r);
}

/* Of each class's pixels the fraction rounded, at least one, trains (analysis.md): one
 * band, object 0 of 3 pixels at 0 K, object 1 of 97 at 10 K, --train-fraction 0.1: 1 and
 * 10 training pixels (0.3 rounds to 0). With no training pixel object 0's mean was 0 / 0,
 * every pixel went to it (accuracy 0.03), and that passed every test. */
static void test_at_least_one_training_pixel(void **state)
{
    (void)state;
    enum { N = 100, N0 = 3 };
    float cube[N];
    int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        truth[p] = p < N0 ? 0 : 1;
        cube[p] = (p < N0 ? 0.0f : 10.0f) + 0.01f * (float)(p % 5);
    }
    /* (sam and ace say nothing in one band: every angle is 0, every coherence 1) */
    for (int m = CLASSIFY_MAHALANOBIS; m <= CLASSIFY_MATCHED_FILTER; m++) {
        classify_result r;
        thz_error err = {0};
        assert_int_equal(classify_run(cube, 1, N, truth, (classify_method)m, 0.1, 1, &r, &err),
                         THZ_OK);
        size_t train[2] = {0, 0};
        for (size_t p = 0; p < N; p++)
            train[truth[p]] += r.train[p];
        assert_int_equal(train[0], 1);
        assert_int_equal(train[1], 10);
        if (!(r.accuracy == 1.0))
            fail_msg("%s: accuracy %g", classify_method_name((classify_method)m), r.accuracy);
        classify_result_fini(&r);
    }
}

static void test_bad_input(void **state)
{
    (void)state;
    static float cube[BANDS * PIXELS];
    static int32_t truth[PIXELS];
    make_cube(cube, truth);
    classify_result r;
    thz_error err = {0};
    int32_t none[PIXELS];
    for (size_t p = 0; p < PIXELS; p++)
        none[p] = -1;
    assert_int_equal(classify_run(cube, BANDS, PIXELS, none, CLASSIFY_SAM, 0.5, 1, &r, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "no object"));
    cube[5] = NAN;
    assert_int_equal(classify_run(cube, BANDS, PIXELS, truth, CLASSIFY_SAM, 0.5, 1, &r, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "not finite"));
    assert_int_equal(classify_method_from_name("ace"), CLASSIFY_ACE);
    assert_int_equal(classify_method_from_name("svm"), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_noise_free_exact),
        cmocka_unit_test(test_accuracy_falls_with_noise),
        cmocka_unit_test(test_auc_and_roc_of_held_out_pixels),
        cmocka_unit_test(test_unequal_classes),
        cmocka_unit_test(test_split_depends_on_seed),
        cmocka_unit_test(test_split_is_a_shuffle),
        cmocka_unit_test(test_tie_goes_to_lower_object),
        cmocka_unit_test(test_lda_prior),
        cmocka_unit_test(test_matched_filter_normalised),
        cmocka_unit_test(test_added_noise_spread),
        cmocka_unit_test(test_mahalanobis_unbiased_covariance),
        cmocka_unit_test(test_at_least_one_training_pixel),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
