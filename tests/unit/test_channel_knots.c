/* The fixed band-mean rules with a scene's spectral knots and a structure to refine by
 * (channel_quadrature_init_knots): a tabled line narrower than the band, or a line in
 * the air seen over a long path, is integrated to the adaptive band mean's accuracy,
 * where the plain 401-node rule misses it by 1e-5 to 1e-3. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "physics/channel.h"

/* A triangular line on a flat base, linear between its three knots. */
typedef struct line {
    double knots[3]; /* Hz: start, peak, end */
    double base, peak;
    double distance_m; /* > 0: the function is exp(-value * d), a transmittance */
} line;

static void line_init(line *l, const thz_channel *ch, double base, double peak, double d)
{
    double s = channel_sigma_hz(ch), at = ch->center_hz + 0.3 * s, hw = s / 5.0;
    l->knots[0] = at - hw;
    l->knots[1] = at;
    l->knots[2] = at + hw;
    l->base = base;
    l->peak = peak;
    l->distance_m = d;
}

static double line_value(double nu, void *ctx)
{
    const line *l = ctx;
    double v = l->base;
    if (nu > l->knots[0] && nu < l->knots[2]) {
        double u = nu < l->knots[1] ? (nu - l->knots[0]) / (l->knots[1] - l->knots[0])
                                    : (l->knots[2] - nu) / (l->knots[2] - l->knots[1]);
        v = l->base + (l->peak - l->base) * u;
    }
    return l->distance_m > 0.0 ? exp(-v * l->distance_m) : v;
}

static void line_structure(double nu, void *ctx, double *values)
{
    values[0] = line_value(nu, ctx);
}

/* As the air's: NaN at or below 0 Hz (atmosphere_alpha_per_m there). */
static void line_structure_nan_below_0(double nu, void *ctx, double *values)
{
    values[0] = nu > 0.0 ? line_value(nu, ctx) : NAN;
}

static double rule_mean(const channel_quadrature *q, double (*f)(double, void *), void *ctx)
{
    double s = 0.0;
    for (size_t i = 0; i < q->n; i++)
        s += q->weight[i] * f(q->freq_hz[i], ctx);
    return s;
}

/* Weights sum to 1, nodes strictly increase and are > 0, and every knot is a node. */
static void check_rule(const channel_quadrature *q, const double *knots, size_t n_knots)
{
    double sum = 0.0;
    for (size_t i = 0; i < q->n; i++) {
        sum += q->weight[i];
        assert_true(q->freq_hz[i] > 0.0 && q->weight[i] >= 0.0);
        if (i > 0)
            assert_true(q->freq_hz[i] > q->freq_hz[i - 1]);
    }
    assert_true(fabs(sum - 1.0) < 1e-13);
    for (size_t k = 0; k < n_knots; k++) {
        bool found = false;
        for (size_t i = 0; i < q->n && !found; i++)
            found = q->freq_hz[i] == knots[k];
        assert_true(found);
    }
}

/* |rule / adaptive - 1| for the line through rule q. */
static double rule_error(const channel_quadrature *q, const thz_channel *ch, line *l)
{
    double exact = channel_band_mean(ch, line_value, l);
    return fabs(rule_mean(q, line_value, l) / exact - 1.0);
}

static void knots_case(const thz_channel *ch)
{
    thz_error err;
    line l;
    line_init(&l, ch, 0.1, 0.9, 0.0);
    channel_quadrature plain, knotted;
    assert_int_equal(channel_quadrature_init(&plain, ch, CHANNEL_QUADRATURE_NODES, &err), THZ_OK);
    assert_int_equal(channel_quadrature_init_knots(&knotted, ch, CHANNEL_QUADRATURE_NODES, l.knots,
                                                   3, NULL, &err),
                     THZ_OK);
    check_rule(&knotted, l.knots, 3);
    double e_plain = rule_error(&plain, ch, &l), e_knots = rule_error(&knotted, ch, &l);
    print_message("%s: tabled line, plain rule %.2e, with its knots %.2e (%zu nodes)\n", ch->name,
                  e_plain, e_knots, knotted.n);
    assert_true(e_plain > 1e-6); /* the kinks between nodes cost the plain rule */
    assert_true(e_knots < 1e-7); /* Simpson's own error on g f between the knots */
    assert_false(knotted.even);
    assert_true(knotted.n <= channel_quadrature_max_nodes(ch, CHANNEL_QUADRATURE_NODES, 3, false));
    channel_quadrature_fini(&plain);
    channel_quadrature_fini(&knotted);
}

static void test_knots_gaussian(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "gauss", .center_hz = 0.5e12, .relative_width = 0.05};
    knots_case(&ch);
}

static void test_knots_table(void **state)
{
    (void)state;
    thz_channel ch = {.name = "table"};
    const double f[4] = {0.47e12, 0.49e12, 0.51e12, 0.53e12}, w[4] = {0.0, 1.0, 0.8, 0.0};
    thz_error err;
    assert_int_equal(channel_set_response(&ch, 4, f, w, 0.0, &err), THZ_OK);
    knots_case(&ch);
    channel_fini(&ch);
}

/* The line's rules through its knots alone (q[0]) and refined by s (q[1], checked), and
 * their errors e[0], e[1]. */
static void refine_pair(const thz_channel *ch, line *l, const channel_structure *s,
                        channel_quadrature q[2], double e[2])
{
    thz_error err;
    for (int i = 0; i < 2; i++) {
        assert_int_equal(channel_quadrature_init_knots(&q[i], ch, CHANNEL_QUADRATURE_NODES,
                                                       l->knots, 3, i ? s : NULL, &err),
                         THZ_OK);
        e[i] = rule_error(&q[i], ch, l);
    }
    check_rule(&q[1], l->knots, 3);
}

/* The line as the air's attenuation (0.05 /m, 1 /m at its peak) over 10 m: the knots
 * alone leave exp(-alpha d) under-resolved between them; the structure refines it. */
static void test_structure(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "air", .center_hz = 0.5e12, .relative_width = 0.05};
    thz_error err;
    line l;
    line_init(&l, &ch, 0.05, 1.0, 10.0);
    channel_structure s = {1, line_structure, &l};
    channel_quadrature q[2];
    double e[2];
    refine_pair(&ch, &l, &s, q, e);
    channel_quadrature knotted = q[0], refined = q[1];
    double e_knots = e[0], e_refined = e[1];
    print_message("line in the air over 10 m: knots alone %.2e (%zu nodes), refined %.2e (%zu "
                  "nodes)\n",
                  e_knots, knotted.n, e_refined, refined.n);
    assert_true(e_knots > 1e-5);
    assert_true(e_refined < 1e-7);
    assert_true(refined.n > knotted.n);
    assert_true(refined.n <= channel_quadrature_max_nodes(&ch, CHANNEL_QUADRATURE_NODES, 3, true));
    channel_quadrature_fini(&knotted);
    channel_quadrature_fini(&refined);

    /* a structure without variation adds no node beyond the pieces' */
    line flat;
    line_init(&flat, &ch, 0.05, 0.05, 10.0);
    s.ctx = &flat;
    assert_int_equal(
        channel_quadrature_init_knots(&refined, &ch, CHANNEL_QUADRATURE_NODES, NULL, 0, &s, &err),
        THZ_OK);
    assert_int_equal(refined.n, CHANNEL_QUADRATURE_NODES);
    channel_quadrature_fini(&refined);
}

/* A test function no panel resolves (a period of 6 MHz against base panels of 0.6 GHz):
 * the refinement spends its whole budget, 1604 splits of two nodes each (physics.md),
 * and stays within the memory estimate's bound. */
static void wiggle_structure(double nu, void *ctx, double *values)
{
    (void)ctx;
    values[0] = sin(nu * 1e-6);
}

static void test_structure_budget(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "air", .center_hz = 0.5e12, .relative_width = 0.05};
    channel_structure s = {1, wiggle_structure, NULL};
    channel_quadrature q;
    thz_error err;
    assert_int_equal(
        channel_quadrature_init_knots(&q, &ch, CHANNEL_QUADRATURE_NODES, NULL, 0, &s, &err),
        THZ_OK);
    check_rule(&q, NULL, 0);
    assert_int_equal(q.n, CHANNEL_QUADRATURE_NODES + 2 * CHANNEL_QUADRATURE_MAX_SPLITS);
    assert_true(q.n <= channel_quadrature_max_nodes(&ch, CHANNEL_QUADRATURE_NODES, 0, true));
    channel_quadrature_fini(&q);
}

/* A channel so wide (w = 0.5) that nu_c - 6 sigma is below 0 Hz, where the air's
 * transmittance is NaN: the refinement goes where the line is, not into the tail the
 * rule drops (the NaN there split every panel until the budget was spent). */
static void test_structure_wide(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "wide", .center_hz = 0.35e12, .relative_width = 0.5};
    line l;
    line_init(&l, &ch, 0.05, 1.0, 20.0);
    channel_structure s = {1, line_structure_nan_below_0, &l};
    channel_quadrature q[2];
    double e[2];
    refine_pair(&ch, &l, &s, q, e);
    channel_quadrature plain = q[0], refined = q[1];
    double e_plain = e[0], e_refined = e[1];
    print_message("wide channel, line over 20 m: knots alone %.2e, refined %.2e (%zu nodes)\n",
                  e_plain, e_refined, refined.n);
    assert_true(e_plain > 1e-5);
    assert_true(e_refined < 1e-6);
    channel_quadrature_fini(&plain);
    channel_quadrature_fini(&refined);
}

/* Knots outside the band change nothing; too many inside are thinned to the cap; knots a
 * rounding apart make no piece of nothing (no repeated node). */
static void test_knots_bounds(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "c", .center_hz = 1.0e12, .relative_width = 0.1};
    thz_error err;
    const double outside[2] = {0.1e12, 2.0e12};
    channel_quadrature plain, q;
    assert_int_equal(channel_quadrature_init(&plain, &ch, CHANNEL_QUADRATURE_NODES, &err), THZ_OK);
    assert_int_equal(
        channel_quadrature_init_knots(&q, &ch, CHANNEL_QUADRATURE_NODES, outside, 2, NULL, &err),
        THZ_OK);
    assert_true(q.even && q.n == plain.n);
    for (size_t i = 0; i < q.n; i++)
        assert_true(q.freq_hz[i] == plain.freq_hz[i] && q.weight[i] == plain.weight[i]);
    channel_quadrature_fini(&q);
    channel_quadrature_fini(&plain);

    const size_t many = 100000;
    double *k = malloc(many * sizeof *k);
    assert_non_null(k);
    for (size_t i = 0; i < many; i++)
        k[i] = 0.7e12 + 0.6e12 * (double)(i + 1) / (double)(many + 1);
    assert_int_equal(
        channel_quadrature_init_knots(&q, &ch, CHANNEL_QUADRATURE_NODES, k, many, NULL, &err),
        THZ_OK);
    check_rule(&q, NULL, 0);
    assert_true(q.n > CHANNEL_QUADRATURE_MAX_KNOTS);
    assert_true(q.n <= channel_quadrature_max_nodes(&ch, CHANNEL_QUADRATURE_NODES, many, false));
    channel_quadrature_fini(&q);
    /* between one and two caps' worth inside the band (physics.md: at most 512 points a
     * band, more thinned evenly): every second knot is a node, 500 of the 1000 (spaced
     * unevenly, so that no skipped knot falls on a piece's midpoint) */
    const size_t some = 1000;
    for (size_t i = 0; i < some; i++) {
        double x = (double)(i + 1) / (double)(some + 1);
        k[i] = 0.8e12 + 0.4e12 * x * x;
    }
    assert_int_equal(
        channel_quadrature_init_knots(&q, &ch, CHANNEL_QUADRATURE_NODES, k, some, NULL, &err),
        THZ_OK);
    check_rule(&q, NULL, 0);
    size_t as_nodes = 0;
    for (size_t i = 0, j = 0; i < some; i++) {
        while (j < q.n && q.freq_hz[j] < k[i])
            j++;
        as_nodes += j < q.n && q.freq_hz[j] == k[i];
    }
    assert_true(as_nodes == some / 2);
    assert_true(q.n <= channel_quadrature_max_nodes(&ch, CHANNEL_QUADRATURE_NODES, some, false));
    channel_quadrature_fini(&q);
    free(k);

    const double close[2] = {0.98e12, nextafter(0.98e12, 1e13)};
    assert_int_equal(
        channel_quadrature_init_knots(&q, &ch, CHANNEL_QUADRATURE_NODES, close, 2, NULL, &err),
        THZ_OK);
    check_rule(&q, close, 1);
    channel_quadrature_fini(&q);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_knots_gaussian),   cmocka_unit_test(test_knots_table),
        cmocka_unit_test(test_structure),        cmocka_unit_test(test_structure_wide),
        cmocka_unit_test(test_structure_budget), cmocka_unit_test(test_knots_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
