/* The sensor's PSF (sensor/psf.h) on a delta image, against a band-averaged Airy pattern
 * computed here independently (libm's j1, the channel's Gaussian response on a
 * trapezoid grid of its own):
 *  - the radial profile of the blurred delta matches it (normalised to the peak);
 *  - its FWHM is within 3 % of the band-averaged expectation (~1.029 lambda/D) in each
 *    of two channels;
 *  - a narrow PSF is integrated over the pixel cell (sub-sampling): the centre weight
 *    is the cell integral of the pattern over the power within the support;
 *  - the summed power equals the sharp image's within 0.5 % (a delta at the border too:
 *    the mirror border), and a uniform image stays uniform, through the FFT and the
 *    direct path;
 *  - the result does not depend on the thread count. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "physics/channel.h"
#include "sensor/psf.h"

#define C_LIGHT 299792458.0
#define N 129 /* odd: a centre pixel */

/* A sensor on the x axis with an angular pixel pitch of pitch_rad at the centre. */
static thz_sensor test_sensor(double pitch_rad, double diameter_m)
{
    thz_sensor s;
    memset(&s, 0, sizeof s);
    s.name = "cam";
    s.direction[0] = 1.0;
    s.up[2] = 1.0;
    s.columns = s.rows = N;
    s.oversampling = 1;
    s.fov_deg = 2.0 * atan(tan(pitch_rad / 2.0) * N) * 180.0 / M_PI;
    s.aperture_diameter_m = diameter_m;
    s.psf = PSF_AIRY;
    return s;
}

/* The band-averaged Airy pattern per sr at theta (Gaussian response, 241 nodes over
 * +-6 sigma, trapezoid). */
static double expected_airy(const thz_channel *ch, double d_m, double theta)
{
    double sigma = ch->relative_width * ch->center_hz / 2.3548200450309493;
    double num = 0.0, den = 0.0;
    for (int i = 0; i <= 240; i++) {
        double t = -6.0 + 12.0 * i / 240.0, w = exp(-0.5 * t * t) * (i == 0 || i == 240 ? 0.5 : 1);
        double lambda = C_LIGHT / (ch->center_hz + sigma * t);
        double x = M_PI * d_m * sin(theta) / lambda;
        double a = x < 1e-9 ? 1.0 : 2.0 * j1(x) / x;
        num += w * M_PI * d_m * d_m / (4.0 * lambda * lambda) * a * a;
        den += w;
    }
    return num / den;
}

/* Band-averaged encircled energy within theta: 1 - J0^2(x) - J1^2(x). */
static double expected_encircled(const thz_channel *ch, double d_m, double theta)
{
    double sigma = ch->relative_width * ch->center_hz / 2.3548200450309493;
    double num = 0.0, den = 0.0;
    for (int i = 0; i <= 240; i++) {
        double t = -6.0 + 12.0 * i / 240.0, w = exp(-0.5 * t * t) * (i == 0 || i == 240 ? 0.5 : 1);
        double x = M_PI * d_m * sin(theta) * (ch->center_hz + sigma * t) / C_LIGHT;
        num += w * (1.0 - j0(x) * j0(x) - j1(x) * j1(x));
        den += w;
    }
    return num / den;
}

/* Half-width at half maximum (in the units of step) of a profile sampled at i*step,
 * by linear interpolation. */
static double half_width(const double *v, size_t n, double step)
{
    double half = 0.5 * v[0];
    for (size_t i = 1; i < n; i++)
        if (v[i] < half)
            return step * ((double)(i - 1) + (v[i - 1] - half) / (v[i - 1] - v[i]));
    return NAN;
}

static float *blur(const thz_sensor *s, const thz_channel *ch, const float *in, int threads)
{
    psf_kernel k;
    thz_error err;
    assert_int_equal(psf_kernel_init(&k, s, ch, &err), THZ_OK);
    float *out = calloc(N * N, sizeof *out);
    assert_non_null(out);
    assert_int_equal(psf_apply(&k, in, out, N, N, threads, &err), THZ_OK);
    psf_kernel_fini(&k);
    return out;
}

static double sum(const float *v)
{
    double s = 0.0;
    for (size_t i = 0; i < N * N; i++)
        s += v[i];
    return s;
}

/* A wide PSF (FWHM ~ 12 pixels: the FFT path): profile, FWHM, power. Channel c, 30 %
 * wide, tells the band average from the pattern at the centre frequency alone: they
 * differ by 1 % of the peak 2 pixels out, twice the profile's tolerance (a PSF taken at
 * the centre frequency failed here and passed channels a and b, 1 and 5 % wide, where
 * the two differ by 3e-5 and 6e-4 of the peak, below what a cell-integrated kernel
 * compared with point values can resolve). */
static void test_airy_profile_and_fwhm(void **state)
{
    (void)state;
    const double d_m = 0.05, pitch = 1.5e-3;
    const thz_channel chans[3] = {{.name = "a", .center_hz = 0.35e12, .relative_width = 0.01},
                                  {.name = "b", .center_hz = 0.5e12, .relative_width = 0.05},
                                  {.name = "c", .center_hz = 0.5e12, .relative_width = 0.3}};
    for (int c = 0; c < 3; c++) {
        const thz_channel *ch = &chans[c];
        thz_sensor s = test_sensor(pitch, d_m);
        float *in = calloc(N * N, sizeof *in);
        in[(N / 2) * N + N / 2] = 1.0f;
        float *out = blur(&s, ch, in, 2);
        const float *row = out + (N / 2) * N + N / 2;
        /* profile along the centre row, normalised to the peak */
        double e0 = expected_airy(ch, d_m, 0.0);
        for (int i = 0; i < 40; i++) {
            double want = expected_airy(ch, d_m, i * pitch) / e0;
            double got = row[i] / row[0];
            if (fabs(got - want) > 5e-3)
                fail_msg("channel %d: profile at %d px: %.5f, expected %.5f", c, i, got, want);
            double diag = out[(N / 2 + i / 2) * N + N / 2 + i / 2] / row[0];
            double want_diag = expected_airy(ch, d_m, (i / 2) * M_SQRT2 * pitch) / e0;
            if (fabs(diag - want_diag) > 5e-3)
                fail_msg("channel %d: diagonal at %d px: %.5f, expected %.5f", c, i / 2, diag,
                         want_diag);
        }
        /* FWHM against the band-averaged expectation, and 1.029 lambda/D */
        double prof[60], want[600];
        for (int i = 0; i < 60; i++)
            prof[i] = row[i];
        for (int i = 0; i < 600; i++)
            want[i] = expected_airy(ch, d_m, i * pitch / 10.0);
        double fwhm = 2.0 * half_width(prof, 60, pitch);
        double fwhm_want = 2.0 * half_width(want, 600, pitch / 10.0);
        double fwhm_mono = 1.029 * C_LIGHT / ch->center_hz / d_m;
        if (fabs(fwhm / fwhm_want - 1.0) > 0.03)
            fail_msg("channel %d: FWHM %.4g mrad, band-averaged Airy %.4g mrad", c, fwhm * 1e3,
                     fwhm_want * 1e3);
        if (ch->relative_width < 0.1 && fabs(fwhm_want / fwhm_mono - 1.0) > 0.01)
            fail_msg("channel %d: band-averaged FWHM %.4g mrad far from 1.029 lambda/D = %.4g", c,
                     fwhm_want * 1e3, fwhm_mono * 1e3);
        if (fabs(sum(out) - 1.0) > 0.005)
            fail_msg("channel %d: summed power %.6f, sharp 1", c, sum(out));
        /* at a corner: the mirror border keeps the power */
        memset(in, 0, N * N * sizeof *in);
        in[2 * N + 1] = 1.0f;
        float *edge = blur(&s, ch, in, 1);
        if (fabs(sum(edge) - 1.0) > 0.005)
            fail_msg("channel %d: power of a delta at the border %.6f", c, sum(edge));
        /* threads: bit-identical */
        in[2 * N + 1] = 0.0f;
        in[(N / 2) * N + N / 2] = 1.0f;
        float *one = blur(&s, ch, in, 1);
        assert_memory_equal(one, out, N * N * sizeof *out);
        free(one);
        free(edge);
        free(out);
        free(in);
    }
}

/* A narrow PSF (FWHM ~ 2 pixels: sub-sampled, direct or FFT): the centre weight is the
 * cell integral over the support's power; uniform stays uniform. */
static void test_airy_narrow(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 0.35e12, .relative_width = 0.01};
    const double d_m = 0.05, pitch = 8.5e-3;
    thz_sensor s = test_sensor(pitch, d_m);
    psf_kernel k;
    thz_error err;
    assert_int_equal(psf_kernel_init(&k, &s, &ch, &err), THZ_OK);
    assert_true(k.subsamples > 1);
    size_t side = 2 * (size_t)k.half + 1;
    double cell = 0.0;
    const int m = 40;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            double ox = ((i + 0.5) / m - 0.5) * pitch, oy = ((j + 0.5) / m - 0.5) * pitch;
            cell += expected_airy(&ch, d_m, sqrt(ox * ox + oy * oy));
        }
    cell *= pitch * pitch / (m * m);
    double support = expected_encircled(&ch, d_m, PSF_AIRY_SUPPORT * C_LIGHT / ch.center_hz / d_m);
    double want = cell / support, got = k.weight[k.half * side + k.half];
    if (fabs(got / want - 1.0) > 0.01)
        fail_msg("centre weight %.5f, cell integral %.5f (point sample %.5f)", got, want,
                 expected_airy(&ch, d_m, 0.0) * pitch * pitch / support);
    psf_kernel_fini(&k);
    float *in = malloc(N * N * sizeof *in);
    for (size_t i = 0; i < N * N; i++)
        in[i] = 3.0f;
    float *out = blur(&s, &ch, in, 2);
    for (size_t i = 0; i < N * N; i++)
        if (fabs(out[i] - 3.0) > 1e-5)
            fail_msg("uniform image changed at %zu: %.7g", i, out[i]);
    free(out);
    free(in);
}

/* A PSF whose support lies within a pixel (a tiny FWHM, a huge aperture) is the one-pixel
 * kernel 1: its sub-samples all fell outside the support, and the run failed with "empty
 * kernel" (exit 1) on a scene validate accepted. */
static void test_narrower_than_a_pixel(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 3e12, .relative_width = 0.05};
    const double pitch = 1e-2;
    for (int form = 0; form < 2; form++) {
        thz_sensor s = test_sensor(pitch, form ? 1e3 : 0.0); /* Airy: 25 lambda/D = pitch/4000 */
        if (!form) {
            s.psf = PSF_GAUSSIAN;
            s.psf_fwhm_deg = 1e-3 * pitch * 180.0 / M_PI;
        }
        psf_kernel k;
        thz_error err = {0};
        if (psf_kernel_init(&k, &s, &ch, &err) != THZ_OK)
            fail_msg("%s: %s", form ? "airy" : "gaussian", err.message);
        assert_int_equal(k.half, 0);
        assert_true(k.weight[0] == 1.0);
        psf_kernel_fini(&k);
    }
}

/* The Gaussian PSF through the direct path (few taps): power and uniformity. */
static void test_gaussian_direct(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 0.35e12, .relative_width = 0.01};
    const double pitch = 1e-3;
    thz_sensor s = test_sensor(pitch, 0.0);
    s.psf = PSF_GAUSSIAN;
    s.psf_fwhm_deg = 1.5 * pitch * 180.0 / M_PI;
    psf_kernel k;
    thz_error err;
    assert_int_equal(psf_kernel_init(&k, &s, &ch, &err), THZ_OK);
    size_t side = 2 * (size_t)k.half + 1;
    assert_true(side * side <= PSF_DIRECT_MAX_TAPS);
    psf_kernel_fini(&k);
    float *in = calloc(N * N, sizeof *in);
    in[0] = 1.0f; /* the corner */
    in[(N / 2) * N + N / 2] = 2.0f;
    float *out = blur(&s, &ch, in, 2);
    if (fabs(sum(out) - 3.0) > 3e-6)
        fail_msg("summed power %.7f, sharp 3", sum(out));
    free(out);
    free(in);
}

/* A sensor of columns x rows with an angular pixel pitch of pitch_rad and a Gaussian PSF
 * of fwhm_px pixels. */
static thz_sensor gauss_sensor(uint32_t columns, uint32_t rows, double pitch_rad, double fwhm_px)
{
    thz_sensor s = test_sensor(pitch_rad, 0.0);
    s.columns = columns;
    s.rows = rows;
    s.fov_deg = 2.0 * atan(tan(pitch_rad / 2.0) * columns) * 180.0 / M_PI;
    s.psf = PSF_GAUSSIAN;
    s.psf_fwhm_deg = fwhm_px * pitch_rad * 180.0 / M_PI;
    return s;
}

static size_t mirror(long long i, long long n)
{
    long long m = ((i % (2 * n)) + 2 * n) % (2 * n);
    return (size_t)(m < n ? m : 2 * n - 1 - m);
}

/* A PSF far wider than the image (FWHM twice its width: support 96 pixels, image 12 x 9)
 * is the whole PSF on the mirror-extended image, against a convolution summed over the
 * whole support (the Gaussian at the pixels' centres, as the kernel samples it at this
 * width): it was cut at the image's size and renormalised, 1e-2 off at the edges. */
static void test_wider_than_the_image(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 0.35e12, .relative_width = 0.01};
    enum { W = 12, H = 9 };
    const double pitch = 2e-3, fwhm_px = 2.0 * W;
    thz_sensor s = gauss_sensor(W, H, pitch, fwhm_px);
    float in[W * H], out[W * H];
    for (int i = 0; i < W * H; i++) /* a step and a slope: no symmetry to hide behind */
        in[i] = (float)((i % W >= 7 ? 1.0 : 0.0) + 0.01 * (i / W));
    psf_kernel k;
    thz_error err;
    assert_int_equal(psf_kernel_init(&k, &s, &ch, &err), THZ_OK);
    assert_int_equal(k.subsamples, 1);
    assert_int_equal(psf_apply(&k, in, out, W, H, 1, &err), THZ_OK);
    psf_kernel_fini(&k);
    const double sigma = fwhm_px / 2.3548200450309493, radius = 4.0 * fwhm_px;
    const long long f = (long long)ceil(radius);
    double worst = 0.0;
    for (long long r = 0; r < H; r++) {
        for (long long c = 0; c < W; c++) {
            double num = 0.0, den = 0.0;
            for (long long dy = -f; dy <= f; dy++) {
                for (long long dx = -f; dx <= f; dx++) {
                    double d = sqrt((double)(dx * dx + dy * dy));
                    double w = d <= radius ? exp(-0.5 * d * d / (sigma * sigma)) : 0.0;
                    num += w * in[mirror(r - dy, H) * W + mirror(c - dx, W)];
                    den += w;
                }
            }
            worst = fmax(worst, fabs(out[r * W + c] - num / den));
        }
    }
    if (worst > 1e-5)
        fail_msg("wider than the image: %.3g off the whole PSF on the mirrored image", worst);
}

/* With oversampling the image is already each pixel's mean: a step through the middle of
 * the central column (0, 0.5, 1) under a PSF of one pixel's FWHM lights its left
 * neighbour with 0.0249 of the step (a pixel integrating the blurred scene:
 * int_{-1.5}^{-0.5} Phi(x / sigma) dx); the PSF taken at the kernel pixels' centres gives
 * 0.0278, and averaged over their cells again, as before, 0.0593. */
static void test_oversampled_pixel_counted_once(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 0.35e12, .relative_width = 0.01};
    enum { W = 15, H = 7 };
    thz_sensor s = gauss_sensor(W, H, 1e-3, 1.0);
    s.oversampling = 8;
    float in[W * H], out[W * H];
    for (int i = 0; i < W * H; i++)
        in[i] = i % W < W / 2 ? 0.0f : i % W == W / 2 ? 0.5f : 1.0f;
    psf_kernel k;
    thz_error err;
    assert_int_equal(psf_kernel_init(&k, &s, &ch, &err), THZ_OK);
    assert_int_equal(psf_apply(&k, in, out, W, H, 1, &err), THZ_OK);
    psf_kernel_fini(&k);
    double left = out[3 * W + W / 2 - 1], right = out[3 * W + W / 2 + 1];
    if (fabs(left - 0.0249) > 0.005 || fabs(right - (1.0 - 0.0249)) > 0.005)
        fail_msg("neighbours of the step's pixel: %.4f and %.4f, a pixel integrating the "
                 "blurred scene 0.0249 and 0.9751",
                 left, right);
}

/* A PSF whose fold would take more than PSF_FOLD_MAX_SAMPLES samples (a 120 deg FWHM on
 * a field of 0.01 deg: 4 x 120 / (0.01 / 64) = 3072000 pixels of reach, against at most
 * (sqrt(2^26) - 1) / 2 = 4095) is refused, by the check the run makes before its work and
 * by the kernel; the 12 x 9 image under a PSF twice its width is not. */
static void test_fold_too_large_refused(void **state)
{
    (void)state;
    const thz_channel ch = {.name = "a", .center_hz = 0.35e12, .relative_width = 0.01};
    thz_sensor s = gauss_sensor(64, 48, 0.01 / 64 * M_PI / 180.0, 0.0);
    s.psf_fwhm_deg = 120.0;
    thz_error err = {0};
    assert_int_equal(psf_kernel_check(&s, &ch, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "the PSF reaches 3072000 pixels from the centre"));
    assert_non_null(strstr(err.message, "against an image of 64 x 48 pixels: expected at most "
                                        "4095 pixels"));
    psf_kernel k;
    assert_int_equal(psf_kernel_init(&k, &s, &ch, &err), THZ_ERR_INPUT);
    assert_null(k.weight);
    thz_sensor ok = gauss_sensor(12, 9, 2e-3, 24.0);
    assert_int_equal(psf_kernel_check(&ok, &ch, &err), THZ_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_airy_profile_and_fwhm),
        cmocka_unit_test(test_airy_narrow),
        cmocka_unit_test(test_gaussian_direct),
        cmocka_unit_test(test_narrower_than_a_pixel),
        cmocka_unit_test(test_wider_than_the_image),
        cmocka_unit_test(test_oversampled_pixel_counted_once),
        cmocka_unit_test(test_fold_too_large_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
