/* cdf_search_guided finds cdf_search's index for every x it is asked, from its guide
 * table: CDFs of 1 to 300 entries with runs of equal values (triangles of zero area), a
 * few huge steps among tiny ones, and guide tables shorter and longer than the CDF; x at
 * every entry, just below and above it, and at 32-bit uniforms; and a guide table that
 * points past the answer (the fallback to bisection). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "core/cdf.h"

static void check(const double *cdf, size_t n, const uint32_t *guide, size_t n_guide, double u)
{
    double x = u * cdf[n - 1];
    size_t want = cdf_search(cdf, n, x), got = cdf_search_guided(cdf, n, guide, n_guide, u, x);
    if (got != want)
        fail_msg("n %zu, guide %zu, u %.17g, x %.17g: %zu, bisection %zu", n, n_guide, u, x, got,
                 want);
}

static void test_guided_equals_bisection(void **state)
{
    (void)state;
    uint64_t r = 88172645463325252ull;
    double cdf[300];
    uint32_t guide[700];
    for (size_t n = 1; n <= 300; n += n < 20 ? 1 : 37) {
        for (int shape = 0; shape < 3; shape++) {
            double sum = 0.0;
            for (size_t i = 0; i < n; i++) {
                r ^= r << 13, r ^= r >> 7, r ^= r << 17;
                double w = (double)(r >> 11) * 0x1p-53;
                if (shape == 1 && r % 3 == 0)
                    w = 0.0; /* runs of equal entries */
                if (shape == 2)
                    w = r % 17 == 0 ? 1e6 : 1e-6 * w; /* huge steps among tiny ones */
                sum += w;
                cdf[i] = sum;
            }
            if (!(cdf[n - 1] > 0.0))
                cdf[n - 1] = 1.0;
            const size_t sizes[3] = {1, n, 2 * n + 3};
            for (int s = 0; s < 3; s++) {
                size_t ng = sizes[s];
                cdf_guide_build(cdf, n, guide, ng);
                for (size_t i = 0; i < n; i++) {
                    double u = cdf[i] / cdf[n - 1];
                    if (u < 1.0)
                        check(cdf, n, guide, ng, u);
                    if (nextafter(u, 0.0) < 1.0)
                        check(cdf, n, guide, ng, nextafter(u, 0.0));
                    if (nextafter(u, 1.0) < 1.0)
                        check(cdf, n, guide, ng, nextafter(u, 1.0));
                }
                for (uint64_t k = 0; k < (1ull << 32); k += 0x10001ull * 97)
                    check(cdf, n, guide, ng, (double)k * 0x1p-32);
                check(cdf, n, guide, ng, 0.0);
                check(cdf, n, guide, ng, 1.0 - 0x1p-32);
            }
            /* a guide past the answer (what a rounding of u n_guide up could give): the
             * search falls back to bisection below it */
            for (size_t g = 0; g < n; g++)
                guide[g] = (uint32_t)(n - 1);
            for (size_t i = 0; i < n; i++)
                check(cdf, n, guide, n, (double)i / (double)n);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_guided_equals_bisection),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
