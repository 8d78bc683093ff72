/* The detectors of classification (analysis/classify.c), recomputed here from the
 * training pixels the result reports (docs/analysis.md): for object k as the target,
 * mu_b and Sigma_b are the mean and covariance of the other classes' training pixels
 * (their scatter about mu_b, between the classes included), s~ = m_k - mu_b,
 * x~ = x - mu_b; the matched filter s~' Sigma_b^-1 x~ / s~' Sigma_b^-1 s~ and ACE's signed
 * (s~' Sigma_b^-1 x~)^2 / ((s~' Sigma_b^-1 s~)(x~' Sigma_b^-1 x~)); a pixel goes to the
 * largest. Three overlapping classes in two bands, so that many pixels lie near a
 * boundary: every pixel whose two best statistics differ by more than 1e-3 must go to the
 * best. Sigma_b without the between-class part, or ACE unsigned (a pixel on the far side
 * of the background from the target scoring as if it were on the target's side), passed
 * every test; each moves pixels here (checked, so that the test can fail). */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "analysis/classify.h"

enum { NC = 3, PER = 150, N = NC * PER };

/* Means: A in the middle, B and C either side of it on band 0, C a little up on band 1. */
static const double means[NC][2] = {{300.0, 300.0}, {302.0, 300.0}, {298.0, 300.8}};

typedef struct variant {
    bool between; /* Sigma_b holds the between-class scatter */
    bool signed_ace;
} variant;

/* Statistic of pixel x for target k, recomputed from the training pixels. */
static double statistic(const float *cube, const int32_t *truth, const uint8_t *train, size_t k,
                        const double x[2], bool ace, variant v)
{
    double m[2] = {0, 0}, mu[2] = {0, 0}, nk = 0, nb = 0;
    for (size_t p = 0; p < N; p++) {
        if (!train[p])
            continue;
        double *acc = truth[p] == (int32_t)k ? m : mu;
        for (size_t b = 0; b < 2; b++)
            acc[b] += cube[b * N + p];
        *(truth[p] == (int32_t)k ? &nk : &nb) += 1.0;
    }
    for (size_t b = 0; b < 2; b++) {
        m[b] /= nk;
        mu[b] /= nb;
    }
    /* the other classes' scatter about mu_b, or about each class's own mean */
    double cm[NC][2] = {{0}}, cn[NC] = {0};
    for (size_t p = 0; p < N; p++)
        if (train[p]) {
            for (size_t b = 0; b < 2; b++)
                cm[truth[p]][b] += cube[b * N + p];
            cn[truth[p]] += 1.0;
        }
    double s[3] = {0, 0, 0}; /* s00, s01, s11 */
    for (size_t p = 0; p < N; p++) {
        if (!train[p] || truth[p] == (int32_t)k)
            continue;
        const double *c =
            v.between ? mu
                      : (double[2]){cm[truth[p]][0] / cn[truth[p]], cm[truth[p]][1] / cn[truth[p]]};
        double d0 = cube[p] - c[0], d1 = cube[N + p] - c[1];
        s[0] += d0 * d0;
        s[1] += d0 * d1;
        s[2] += d1 * d1;
    }
    for (size_t i = 0; i < 3; i++)
        s[i] /= nb - 1.0;
    double det = s[0] * s[2] - s[1] * s[1];
    double inv[3] = {s[2] / det, -s[1] / det, s[0] / det};
    double st[2] = {m[0] - mu[0], m[1] - mu[1]}, xt[2] = {x[0] - mu[0], x[1] - mu[1]};
    double t =
        st[0] * (inv[0] * xt[0] + inv[1] * xt[1]) + st[1] * (inv[1] * xt[0] + inv[2] * xt[1]);
    double q =
        st[0] * (inv[0] * st[0] + inv[1] * st[1]) + st[1] * (inv[1] * st[0] + inv[2] * st[1]);
    if (!ace)
        return t / q;
    double xx =
        xt[0] * (inv[0] * xt[0] + inv[1] * xt[1]) + xt[1] * (inv[1] * xt[0] + inv[2] * xt[1]);
    return (v.signed_ace && t < 0.0 ? -1.0 : 1.0) * t * t / (q * xx);
}

/* The class of the largest statistic, or -1 when the best two are within 1e-3. */
static int best_class(const float *cube, const int32_t *truth, const uint8_t *train, size_t p,
                      bool ace, variant v)
{
    double x[2] = {cube[p], cube[N + p]}, sc[NC];
    for (size_t k = 0; k < NC; k++)
        sc[k] = statistic(cube, truth, train, k, x, ace, v);
    int best = 0;
    for (int k = 1; k < NC; k++)
        if (sc[k] > sc[best])
            best = k;
    for (int k = 0; k < NC; k++)
        if (k != best && sc[best] - sc[k] <= 1e-3)
            return -1;
    return best;
}

static void check(classify_method method)
{
    static float cube[2 * N];
    static int32_t truth[N];
    for (size_t p = 0; p < N; p++) {
        truth[p] = (int32_t)(p / PER);
        for (size_t b = 0; b < 2; b++)
            cube[b * N + p] = (float)means[truth[p]][b];
    }
    const double sd[2] = {0.7, 0.3};
    classify_add_noise(cube, 2, N, sd, 9);
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 2, N, truth, method, 0.5, 1, &r, &err), THZ_OK);
    bool ace = method == CLASSIFY_ACE;
    const variant doc = {true, true}, other = {ace, !ace}; /* MF: no between; ACE: unsigned */
    size_t checked = 0, moved = 0;
    for (size_t p = 0; p < N; p++) {
        int want = best_class(cube, truth, r.train, p, ace, doc);
        if (want < 0)
            continue;
        if (r.assigned[p] != want)
            fail_msg("%s: pixel %zu (%.3f, %.3f K) of object %d assigned %d, expected %d",
                     classify_method_name(method), p, cube[p], cube[N + p], truth[p], r.assigned[p],
                     want);
        checked++;
        moved += best_class(cube, truth, r.train, p, ace, other) != want;
    }
    if (!(checked > N - 10 && moved > 5))
        fail_msg("%s: %zu pixels checked, %zu moved by the mutant", classify_method_name(method),
                 checked, moved);
    classify_result_fini(&r);
}

static void test_matched_filter_background_covariance(void **state)
{
    (void)state;
    check(CLASSIFY_MATCHED_FILTER);
}

static void test_ace_signed(void **state)
{
    (void)state;
    check(CLASSIFY_ACE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matched_filter_background_covariance),
        cmocka_unit_test(test_ace_signed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
