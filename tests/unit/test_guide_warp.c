/* final-gather's photon guide as a warp of the unit square (src/sensor/guide.h): a point
 * drawn uniformly and warped lands in cell c with the cell's probability P_c (a
 * chi-square over the 32 cells), stays inside the square, and its weight is 1 / (N P_c)
 * of the cell it lands in, so that the weighted mean of a function over warped points is
 * its integral over the square (within 5 of its standard errors). A guide of no weight
 * leaves every point where it was, with weight 1. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "core/rng.h"
#include "sensor/guide.h"

#define WARP_POINTS 320000

/* A skewed table: one bright cell, one dimmer one, a weak ramp, empty cells. */
static void skewed(double *w)
{
    for (int c = 0; c < GUIDE_CELLS; c++)
        w[c] = (double)(c % 3);
    w[5] = 60.0;
    w[GUIDE_CELLS - 3] = 15.0;
}

static double integrand(double up, double ua)
{
    return 1.0 + up * up + 0.5 * sin(2.0 * M_PI * ua) + (up > 0.6 && ua < 0.2 ? 3.0 : 0.0);
}

static void test_warp_density_and_weight(void **state)
{
    (void)state;
    double w[GUIDE_CELLS], total = 0.0, p[GUIDE_CELLS];
    skewed(w);
    for (int c = 0; c < GUIDE_CELLS; c++)
        total += w[c];
    for (int c = 0; c < GUIDE_CELLS; c++)
        p[c] = (1.0 - GUIDE_DEFENSIVE) * w[c] / total + GUIDE_DEFENSIVE / GUIDE_CELLS;
    render_guide g;
    render_guide_from_weights(&g, w);
    rng_stream rng;
    rng_init(&rng, 7, 0, 1, 0);
    double count[GUIDE_CELLS] = {0}, sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < WARP_POINTS; i++) {
        double up = rng_uniform(&rng), ua = rng_uniform(&rng);
        double weight = render_guide_warp(&g, NULL, NULL, v3(0.0, 0.0, 1.0), &up, &ua);
        assert_true(up >= 0.0 && up < 1.0 && ua >= 0.0 && ua < 1.0);
        int c = (int)(up * GUIDE_POLAR) * GUIDE_AZIMUTH + (int)(ua * GUIDE_AZIMUTH);
        count[c]++;
        if (fabs(weight * GUIDE_CELLS * p[c] - 1.0) > 1e-12)
            fail_msg("cell %d: weight %.17g, expected 1 / (N P_c) = %.17g", c, weight,
                     1.0 / (GUIDE_CELLS * p[c]));
        double f = weight * integrand(up, ua);
        sum += f;
        sum2 += f * f;
    }
    double chi2 = 0.0;
    for (int c = 0; c < GUIDE_CELLS; c++) {
        double e = WARP_POINTS * p[c];
        chi2 += (count[c] - e) * (count[c] - e) / e;
    }
    /* 31 degrees of freedom: mean 31, standard deviation 7.9 */
    print_message("chi-square of the cells drawn: %.1f (31 degrees of freedom)\n", chi2);
    assert_true(chi2 < 31.0 + 6.0 * sqrt(62.0));
    /* the integral over the square: 1 + 1/3 + 0 + 3 x 0.4 x 0.2 */
    double exact = 1.0 + 1.0 / 3.0 + 3.0 * 0.4 * 0.2;
    double mean = sum / WARP_POINTS, se = sqrt((sum2 / WARP_POINTS - mean * mean) / WARP_POINTS);
    print_message("weighted mean %.6f against %.6f (standard error %.6f)\n", mean, exact, se);
    assert_true(fabs(mean - exact) <= 5.0 * se);
    assert_true(se < 0.01 * exact);
}

static void test_even_guide_is_identity(void **state)
{
    (void)state;
    double w[GUIDE_CELLS] = {0};
    render_guide g;
    render_guide_from_weights(&g, w);
    rng_stream rng;
    rng_init(&rng, 8, 0, 1, 0);
    for (int i = 0; i < 10000; i++) {
        double up = rng_uniform(&rng), ua = rng_uniform(&rng), u0 = up, a0 = ua;
        double weight = render_guide_warp(&g, NULL, NULL, v3(0.0, 0.0, 1.0), &up, &ua);
        assert_true(fabs(weight - 1.0) < 1e-12);
        assert_true(fabs(up - u0) < 1e-12 && fabs(ua - a0) < 1e-12);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_warp_density_and_weight),
        cmocka_unit_test(test_even_guide_is_identity),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
