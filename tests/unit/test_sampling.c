/* Sampling helpers: sampling_direction's azimuth (its libm-free cos and sin of 2 pi u)
 * against libm, its polar angle, and unit length; sampling_direction_many's directions
 * against sampling_direction's; sampling_cosine32's order of draws; the strata of
 * sampling_stratum_of; v3_normalize's zero vector. */
#include <math.h>
#include <setjmp.h>
#include <stdbool.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "core/rng.h"
#include "core/sampling.h"

/* With n = z the basis is (x, y), so the direction is (s cos 2 pi u, s sin 2 pi u, mu). */
static void check_azimuth(double u)
{
    vec3 d = sampling_direction(v3(0.0, 0.0, 1.0), 0.0, u);
    double phi = 2.0 * M_PI * u;
    if (fabs(d.x - cos(phi)) > 1e-14 || fabs(d.y - sin(phi)) > 1e-14 || fabs(d.z) > 1e-15)
        fail_msg("u = %.17g: (%.17g, %.17g) against (%.17g, %.17g)", u, d.x, d.y, cos(phi),
                 sin(phi));
}

static void test_azimuth_against_libm(void **state)
{
    (void)state;
    /* Quadrant and octant boundaries, where the reduction changes branch. */
    const double edges[] = {0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0};
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++)
        for (int j = -2; j <= 2; j++) {
            double u = edges[i] + j * 0x1p-32;
            if (u >= 0.0 && u <= 1.0)
                check_azimuth(u);
        }
    /* Every 32-bit uniform the photon phase draws is k 2^-32: a dense sample of them. */
    for (uint64_t k = 0; k < (1ull << 32); k += 65521)
        check_azimuth((double)k * 0x1p-32);
    /* 53-bit uniforms (the renderer's). */
    for (int k = 0; k < 100000; k++)
        check_azimuth(fmod(k * 0.6180339887498949, 1.0));
}

static void test_polar_angle_and_length(void **state)
{
    (void)state;
    vec3 n = v3_normalize(v3(0.3, -0.5, 0.81));
    for (int k = 0; k < 1000; k++) {
        double mu = (k + 0.5) / 1000.0, u = fmod(k * 0.7548776662466927, 1.0);
        vec3 d = sampling_direction(n, mu, u);
        assert_true(fabs(v3_length(d) - 1.0) < 1e-15);
        assert_true(fabs(v3_dot(d, n) - mu) < 1e-14);
    }
}

/* v3_normalize: unit length along the vector, and a zero vector stays zero rather than
 * NaN (0 / 0), as vec3.h promises: a degenerate normal or direction must not turn every
 * later dot product into NaN. */
static void test_normalize(void **state)
{
    (void)state;
    vec3 z = v3_normalize(v3(0.0, 0.0, 0.0));
    assert_true(z.x == 0.0 && z.y == 0.0 && z.z == 0.0);
    vec3 d = v3_normalize(v3(3.0, -4.0, 12.0)); /* length 13 */
    assert_true(fabs(d.x - 3.0 / 13.0) < 1e-16 && fabs(d.y + 4.0 / 13.0) < 1e-16 &&
                fabs(d.z - 12.0 / 13.0) < 1e-16);
    vec3 tiny = v3_normalize(v3(1e-100, 0.0, 0.0));
    assert_true(tiny.x == 1.0 && tiny.y == 0.0 && tiny.z == 0.0);
}

/* sampling_direction_many gives sampling_direction's directions bit for bit: normals
 * along and against every axis (Duff's basis switches at n.z = -0 / +0) and oblique, mu
 * 0 and 1 and between, the azimuth's quadrant edges; batches of 1 to 16. */
static void test_many(void **state)
{
    (void)state;
    const vec3 normals[] = {v3(0, 0, 1),     v3(0, 0, -1),     v3(1, 0, 0),
                            v3(-1, 0, 0),    v3(0, 1, 0),      v3(0, -1, -0.0),
                            v3(0.6, 0, 0.8), v3(0, 0.6, -0.8), v3_normalize(v3(0.3, -0.5, 0.81))};
    const double mus[] = {0.0, 1e-9, 0.5, 0.999999, 1.0};
    const double us[] = {0.0, 0.25 - 0x1p-32, 0.25, 0.5, 0.75 + 0x1p-32, 1 - 0x1p-32};
    enum { NN = 9, NM = 5, NU = 6, M = NN * NM * NU };
    vec3 n[M], many[M];
    double mu[M], u[M];
    size_t m = 0;
    for (int a = 0; a < NN; a++)
        for (int b = 0; b < NM; b++)
            for (int c = 0; c < NU; c++, m++) {
                n[m] = normals[a];
                mu[m] = mus[b];
                u[m] = us[c];
            }
    for (size_t off = 0, k = 0; off < m; off += 1 + k % 16, k++) {
        size_t count = 1 + k % 16 < m - off ? 1 + k % 16 : m - off;
        sampling_direction_many(n + off, mu + off, u + off, count, many + off);
    }
    for (size_t j = 0; j < m; j++) {
        vec3 one = sampling_direction(n[j], mu[j], u[j]);
        if (memcmp(&one, &many[j], sizeof one) != 0)
            fail_msg("n = (%g, %g, %g), mu = %.17g, u = %.17g: (%.17g, %.17g, %.17g), one at a "
                     "time (%.17g, %.17g, %.17g)",
                     n[j].x, n[j].y, n[j].z, mu[j], u[j], many[j].x, many[j].y, many[j].z, one.x,
                     one.y, one.z);
    }
}

/* sampling_cosine32 takes the azimuth from the stream's first word and mu = sqrt(1 - u)
 * from its second (docs/physics.md "Random streams"): the photon phase's and path's
 * streams, and so every image, depend on that order. */
static void test_cosine32_order(void **state)
{
    (void)state;
    const vec3 normals[] = {v3(0, 0, 1), v3(0, -1, 0), v3_normalize(v3(0.3, -0.5, 0.81))};
    for (uint64_t i = 0; i < 64; i++) {
        vec3 n = normals[i % 3];
        rng_stream a, b;
        rng_init(&a, 11, 2, RNG_PURPOSE_PATH, i);
        rng_init(&b, 11, 2, RNG_PURPOSE_PATH, i);
        vec3 d = sampling_cosine32(n, &a);
        double w0 = rng_uniform32(&b), w1 = rng_uniform32(&b);
        vec3 want = sampling_direction(n, sqrt(1.0 - w1), w0);
        if (memcmp(&d, &want, sizeof d) != 0)
            fail_msg("stream %u: (%.17g, %.17g, %.17g), want (%.17g, %.17g, %.17g)", (unsigned)i,
                     d.x, d.y, d.z, want.x, want.y, want.z);
        /* and it took exactly those two words */
        assert_int_equal(rng_next_u32(&a), rng_next_u32(&b));
    }
}

/* sampling_stratum_of: the members of a set meet each polar band once, with azimuths
 * 1/count apart; and every member alone is uniform on [0, 1)^2 (its polar band and an
 * azimuth bin independent), by a chi-square over 40 000 sets whose limit, dof + 6
 * sqrt(2 dof), a correct sampler exceeds with probability below 1e-6 and a permutation
 * drawn with r = u k (the classic off-by-one: the last member never keeps its place)
 * exceeds by far. */
static void test_strata(void **state)
{
    (void)state;
    const uint32_t counts[] = {2, 4, 9, 16};
    enum { SETS = 40000, AZIMUTH_BINS = 8 };
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
        uint32_t count = counts[c];
        static unsigned hist[2][SAMPLING_STRATA_MAX][AZIMUTH_BINS];
        memset(hist, 0, sizeof hist);
        for (uint64_t set = 0; set < SETS; set++) {
            bool seen[SAMPLING_STRATA_MAX] = {false};
            double azimuth0 = 0.0;
            for (uint32_t m = 0; m < count; m++) {
                rng_stream rng;
                rng_init(&rng, 5, 1, RNG_PURPOSE_GATHER_STRATA, set);
                sampling_stratum st = sampling_stratum_of(&rng, count, m);
                assert_true(st.polar_width == 1.0 / count);
                uint32_t band = (uint32_t)lround(st.polar_lo * count);
                assert_true(band < count && fabs(st.polar_lo - (double)band / count) < 1e-15);
                assert_false(seen[band]);
                seen[band] = true;
                assert_true(st.azimuth >= 0.0 && st.azimuth < 1.0);
                if (m == 0)
                    azimuth0 = st.azimuth;
                double step = st.azimuth - azimuth0 - (double)m / count;
                assert_true(fabs(step - round(step)) < 1e-14);
                if (m == 0 || m == count - 1)
                    hist[m ? 1 : 0][band][(int)(st.azimuth * AZIMUTH_BINS)]++;
            }
        }
        for (int which = 0; which < 2; which++) {
            double expect = (double)SETS / (count * AZIMUTH_BINS), chi2 = 0.0;
            for (uint32_t b = 0; b < count; b++)
                for (int a = 0; a < AZIMUTH_BINS; a++) {
                    double d = hist[which][b][a] - expect;
                    chi2 += d * d / expect;
                }
            double dof = count * AZIMUTH_BINS - 1.0;
            if (!(chi2 < dof + 6.0 * sqrt(2.0 * dof)))
                fail_msg("count %u, member %s: chi-square %.1f for %.0f degrees of freedom", count,
                         which ? "last" : "first", chi2, dof);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_azimuth_against_libm),
        cmocka_unit_test(test_polar_angle_and_length),
        cmocka_unit_test(test_normalize),
        cmocka_unit_test(test_many),
        cmocka_unit_test(test_cosine32_order),
        cmocka_unit_test(test_strata),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
