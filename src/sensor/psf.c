/* The sensor's PSF: band-averaged Airy or Gaussian kernel in pixel units, applied with
 * a mirror border, directly or by FFT (psf.h has the model and its limits). */
#include "sensor/psf.h"

#include <fftw3.h>
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/threads.h"
#include "physics/planck.h"
#include "sensor/camera.h"

/* FWHM of [2 J1(x)/x]^2 in x: 1.029 lambda / D in angle. */
#define PSF_AIRY_FWHM_X (1.02899 * M_PI)
#define PSF_GAUSS_FWHM_PER_SIGMA 2.3548200450309493
/* The Gaussian PSF's support, in FWHM. */
#define PSF_GAUSS_SUPPORT 4.0
/* Radial table of the band-averaged profile: points over the support. */
#define PSF_TABLE_POINTS 4096u

/* The FFTW planner is not thread-safe: plans are made and destroyed under this lock
 * (the module's only static); executing a plan needs none. */
static pthread_mutex_t psf_fftw_lock = PTHREAD_MUTEX_INITIALIZER;

double psf_airy(double theta_rad, double freq_hz, double diameter_m)
{
    double lambda = THZ_SPEED_OF_LIGHT / freq_hz;
    double x = M_PI * diameter_m * sin(theta_rad) / lambda;
    double a = fabs(x) < 1e-8 ? 1.0 : 2.0 * j1(x) / x;
    return M_PI * diameter_m * diameter_m / (4.0 * lambda * lambda) * a * a;
}

/* The radial profile P_c(theta) tabulated at theta_i = i h, i = 0 .. n - 1. */
typedef struct psf_profile {
    size_t n;
    double h_rad;
    double *value;
} psf_profile;

static double psf_profile_at(const psf_profile *p, double theta_rad)
{
    double u = theta_rad / p->h_rad;
    if (!(u < (double)(p->n - 1)))
        return 0.0; /* beyond the support */
    size_t i = (size_t)u;
    double f = u - (double)i;
    return (1.0 - f) * p->value[i] + f * p->value[i + 1];
}

/* Tabulates sn's PSF in channel ch over [0, radius_rad]. */
static thz_status psf_profile_init(psf_profile *p, const thz_sensor *sn, const thz_channel *ch,
                                   double radius_rad, thz_error *err)
{
    p->n = PSF_TABLE_POINTS;
    p->h_rad = radius_rad / (double)(p->n - 1);
    p->value = thz_malloc_array(p->n, sizeof *p->value);
    if (!p->value)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the PSF table");
    if (sn->psf == PSF_GAUSSIAN) {
        double sigma = sn->psf_fwhm_deg * M_PI / 180.0 / PSF_GAUSS_FWHM_PER_SIGMA;
        for (size_t i = 0; i < p->n; i++) {
            double t = (double)i * p->h_rad / sigma;
            p->value[i] = exp(-0.5 * t * t);
        }
        return THZ_OK;
    }
    channel_quadrature q;
    thz_status st = channel_quadrature_init(&q, ch, CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK) {
        free(p->value);
        p->value = NULL;
        return st;
    }
    for (size_t i = 0; i < p->n; i++) {
        double sum = 0.0;
        for (size_t k = 0; k < q.n; k++)
            sum +=
                q.weight[k] * psf_airy((double)i * p->h_rad, q.freq_hz[k], sn->aperture_diameter_m);
        p->value[i] = sum;
    }
    channel_quadrature_fini(&q);
    return THZ_OK;
}

/* Offset d folded into [-n, n] modulo 2n (the mirror border's period), as up to two
 * offsets and their shares of the weight: -n and n read the same pixels, and each takes
 * half, so that the kernel stays symmetric. */
static int psf_fold(long long d, uint32_t n, long long out[2])
{
    long long p = 2 * (long long)n, m = ((d + n) % p + p) % p - n; /* in [-n, n - 1] */
    out[0] = m;
    if (m != -(long long)n)
        return 1;
    out[1] = n;
    return 2;
}

/* Adds w at kernel offset (dx, dy), folded onto the image's period where fold is set. */
static void psf_kernel_add(psf_kernel *k, bool fold, uint32_t columns, uint32_t rows, long long dx,
                           long long dy, double w)
{
    long long h = k->half, side = 2 * h + 1;
    if (!fold) {
        k->weight[(dy + h) * side + dx + h] += w;
        return;
    }
    long long xs[2], ys[2];
    int nx = psf_fold(dx, columns, xs), ny = psf_fold(dy, rows, ys);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++)
            k->weight[(ys[j] + h) * side + xs[i] + h] += w / (nx * ny);
}

/* A kernel's extent: the angular pitch, the PSF's FWHM and support, the support in
 * pixels (full), the samples per kernel pixel side (n) and whether it is folded. */
typedef struct psf_extent {
    double pitch_rad, fwhm_rad, radius_rad, full;
    uint32_t n, max_half;
    bool within_pixel, fold;
} psf_extent;

static thz_status psf_extent_of(const thz_sensor *sn, const thz_channel *ch, psf_extent *e,
                                thz_error *err)
{
    memset(e, 0, sizeof *e);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    e->pitch_rad = 2.0 * atan(0.5 * cam.pixel_pitch);
    if (sn->psf == PSF_AIRY) {
        double lambda_over_d = THZ_SPEED_OF_LIGHT / ch->center_hz / sn->aperture_diameter_m;
        e->fwhm_rad = PSF_AIRY_FWHM_X / M_PI * lambda_over_d;
        e->radius_rad = PSF_AIRY_SUPPORT * lambda_over_d;
    } else if (sn->psf == PSF_GAUSSIAN) {
        e->fwhm_rad = sn->psf_fwhm_deg * M_PI / 180.0;
        e->radius_rad = PSF_GAUSS_SUPPORT * e->fwhm_rad;
    } else {
        return thz_error_set(err, THZ_ERR_INTERNAL, "psf: sensor '%s' has no PSF", sn->name);
    }
    /* the support lies in the pixel: no blur */
    e->within_pixel = e->radius_rad <= 0.5 * e->pitch_rad;
    if (e->within_pixel)
        return THZ_OK;
    /* A kernel wider than the image is folded: the mirror border repeats the image with a
     * period of 2 columns x 2 rows, so a tap dx reads what dx +- 2 columns reads, and the
     * weights of the whole support are summed onto offsets within the image's size. (It
     * was cut there and renormalised: a 30 deg PSF on a 20 deg field put an edge pixel of
     * a 300/400 K step 5.3 K off.) */
    e->full = ceil(e->radius_rad / e->pitch_rad);
    e->max_half = sn->columns > sn->rows ? sn->columns : sn->rows;
    e->fold = e->full > (double)e->max_half;
    /* with oversampling, the image is already the mean over each pixel: the PSF is then
     * taken at the kernel pixels' centres, not averaged over their cells again (that
     * counted the pixel twice: a step through a pixel's middle, a PSF of one pixel's FWHM,
     * oversampling 8, lit its neighbours with 0.059 of the step against 0.025) */
    e->n = sn->oversampling > 1 ? 1
                                : (uint32_t)fmin(fmax(ceil(8.0 * e->pitch_rad / e->fwhm_rad), 1.0),
                                                 PSF_MAX_SUBSAMPLES);
    double side = 2.0 * e->full + 1.0;
    if (e->fold && side * side * e->n * e->n > PSF_FOLD_MAX_SAMPLES) {
        /* the reach whose fold takes PSF_FOLD_MAX_SAMPLES samples */
        double most = floor((sqrt(PSF_FOLD_MAX_SAMPLES) / e->n - 1.0) / 2.0);
        return thz_error_set(err, THZ_ERR_INPUT,
                             "the PSF reaches %.0f pixels from the centre at %.4g THz, against "
                             "an image of %u x %u pixels: expected at most %.0f pixels, the "
                             "widest fold that can be computed; widen the field of view or "
                             "narrow the PSF",
                             e->full, ch->center_hz * 1e-12, sn->columns, sn->rows, most);
    }
    return THZ_OK;
}

thz_status psf_kernel_check(const thz_sensor *sn, const thz_channel *ch, thz_error *err)
{
    psf_extent e;
    return psf_extent_of(sn, ch, &e, err);
}

thz_status psf_sensor_check(const thz_scene *sc, size_t i, thz_error *err)
{
    const thz_sensor *sn = &sc->sensors[i];
    for (size_t c = 0; sn->psf != PSF_NONE && c < sc->n_channels; c++) {
        thz_error why = {0};
        if (psf_kernel_check(sn, &sc->channels[c], &why) != THZ_OK)
            return thz_error_set(
                err, why.status, "%s: sensors[%zu].%s: %s", sc->path ? sc->path : "scene", i,
                sn->psf == PSF_GAUSSIAN ? "psf_fwhm_deg" : "aperture_diameter_m", why.message);
    }
    return THZ_OK;
}

thz_status psf_kernel_init(psf_kernel *k, const thz_sensor *sn, const thz_channel *ch,
                           thz_error *err)
{
    memset(k, 0, sizeof *k);
    psf_extent e;
    thz_status st = psf_extent_of(sn, ch, &e, err);
    if (st != THZ_OK)
        return st;
    k->pitch_rad = e.pitch_rad;
    if (e.within_pixel) {
        k->weight = thz_malloc_array(1, sizeof *k->weight);
        if (!k->weight)
            return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a PSF kernel");
        k->half = 0;
        k->subsamples = 1;
        k->weight[0] = 1.0;
        return THZ_OK;
    }
    bool fold = e.fold;
    uint32_t n = e.n;
    double radius_rad = e.radius_rad;
    k->half = fold ? e.max_half : (uint32_t)e.full;
    k->subsamples = n;
    long long reach_half = fold ? (long long)e.full : (long long)k->half;
    /* the table reaches the far corner of the outermost pixel summed */
    double reach = fmin(radius_rad, ((double)reach_half + 1.0) * k->pitch_rad * M_SQRT2);
    psf_profile prof;
    st = psf_profile_init(&prof, sn, ch, reach, err);
    if (st != THZ_OK)
        return st;
    size_t side = 2 * (size_t)k->half + 1;
    k->weight = thz_calloc(side * side, sizeof *k->weight);
    if (!k->weight) {
        free(prof.value);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a PSF kernel of %zu x %zu",
                             side, side);
    }
    double total = 0.0;
    for (long long dy = -reach_half; dy <= reach_half; dy++) {
        for (long long dx = -reach_half; dx <= reach_half; dx++) {
            double sum = 0.0;
            for (uint32_t j = 0; j < n; j++) {
                double oy = ((double)dy + ((double)j + 0.5) / n - 0.5) * k->pitch_rad;
                for (uint32_t i = 0; i < n; i++) {
                    double ox = ((double)dx + ((double)i + 0.5) / n - 0.5) * k->pitch_rad;
                    sum += psf_profile_at(&prof, sqrt(ox * ox + oy * oy));
                }
            }
            psf_kernel_add(k, fold, sn->columns, sn->rows, dx, dy, sum);
            total += sum;
        }
    }
    free(prof.value);
    if (!(total > 0.0)) {
        psf_kernel_fini(k);
        return thz_error_set(err, THZ_ERR_INTERNAL, "psf: empty kernel for sensor '%s'", sn->name);
    }
    for (size_t i = 0; i < side * side; i++)
        k->weight[i] /= total;
    return THZ_OK;
}

void psf_kernel_fini(psf_kernel *k)
{
    if (!k)
        return;
    free(k->weight);
    memset(k, 0, sizeof *k);
}

/* Index i (any integer) of a line of n pixels mirrored about its edges: -1 -> 0,
 * n -> n - 1, periodic with period 2n. */
static size_t psf_mirror(long long i, size_t n)
{
    long long p = 2 * (long long)n;
    long long m = ((i % p) + p) % p;
    return (size_t)(m < (long long)n ? m : p - 1 - m);
}

/* The mirrored index of each position -h .. n - 1 + h of a line of n pixels, at [i + h]:
 * the taps then read it instead of dividing twice each. NULL when out of memory. */
static size_t *psf_mirror_table(size_t n, size_t h)
{
    size_t *t = thz_malloc_array(n + 2 * h, sizeof *t);
    for (size_t i = 0; t && i < n + 2 * h; i++)
        t[i] = psf_mirror((long long)i - (long long)h, n);
    return t;
}

static thz_status psf_direct(const psf_kernel *k, const float *in, float *out, uint32_t columns,
                             uint32_t rows, int threads, thz_error *err)
{
    long long h = k->half, side = 2 * h + 1;
    size_t *mx = psf_mirror_table(columns, (size_t)h), *my = psf_mirror_table(rows, (size_t)h);
    if (!mx || !my) {
        free(mx);
        free(my);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the PSF's border");
    }
    int nt = thz_threads_or_all(threads);
#pragma omp parallel for schedule(static) num_threads(nt)
    for (long long r = 0; r < (long long)rows; r++) {
        for (long long c = 0; c < (long long)columns; c++) {
            double sum = 0.0;
            /* tap (kx, ky) reads pixel (c - (kx - h), r - (ky - h)), at [. + h] */
            for (long long ky = 0; ky < side; ky++) {
                const float *line = in + my[r + 2 * h - ky] * columns;
                const double *w = k->weight + ky * side;
                const size_t *xs = mx + c + 2 * h;
                for (long long kx = 0; kx < side; kx++)
                    sum += w[kx] * line[xs[-kx]];
            }
            out[(size_t)r * columns + (size_t)c] = (float)sum;
        }
    }
    free(mx);
    free(my);
    return THZ_OK;
}

/* Circular convolution of the mirror-extended image (columns + 2h) x (rows + 2h) with
 * the kernel wrapped about (0, 0): exact for the image's own pixels, whose taps never
 * wrap. */
static thz_status psf_fft(const psf_kernel *k, const float *in, float *out, uint32_t columns,
                          uint32_t rows, thz_error *err)
{
    size_t h = k->half, side = 2 * h + 1;
    size_t mx = columns + 2 * h, my = rows + 2 * h, mc = mx / 2 + 1;
    double *ext = fftw_malloc(mx * my * sizeof *ext);
    double *ker = fftw_malloc(mx * my * sizeof *ker);
    fftw_complex *fe = fftw_malloc(my * mc * sizeof *fe);
    fftw_complex *fk = fftw_malloc(my * mc * sizeof *fk);
    fftw_plan pe = NULL, pk = NULL, pb = NULL;
    thz_status st = THZ_OK;
    if (!ext || !ker || !fe || !fk) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the PSF's FFT (%zu x %zu)", mx,
                           my);
        goto cleanup;
    }
    pthread_mutex_lock(&psf_fftw_lock);
    pe = fftw_plan_dft_r2c_2d((int)my, (int)mx, ext, fe, FFTW_ESTIMATE);
    pk = fftw_plan_dft_r2c_2d((int)my, (int)mx, ker, fk, FFTW_ESTIMATE);
    pb = fftw_plan_dft_c2r_2d((int)my, (int)mx, fe, ext, FFTW_ESTIMATE);
    pthread_mutex_unlock(&psf_fftw_lock);
    if (!pe || !pk || !pb) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "psf: FFTW made no plan for %zu x %zu", mx, my);
        goto cleanup;
    }
    for (size_t y = 0; y < my; y++)
        for (size_t x = 0; x < mx; x++)
            ext[y * mx + x] = in[psf_mirror((long long)y - (long long)h, rows) * columns +
                                 psf_mirror((long long)x - (long long)h, columns)];
    memset(ker, 0, mx * my * sizeof *ker);
    for (size_t ky = 0; ky < side; ky++)
        for (size_t kx = 0; kx < side; kx++)
            ker[((ky + my - h) % my) * mx + (kx + mx - h) % mx] = k->weight[ky * side + kx];
    fftw_execute(pe);
    fftw_execute(pk);
    double scale = 1.0 / ((double)mx * (double)my);
    for (size_t i = 0; i < my * mc; i++) {
        double re = fe[i][0] * fk[i][0] - fe[i][1] * fk[i][1];
        double im = fe[i][0] * fk[i][1] + fe[i][1] * fk[i][0];
        fe[i][0] = re * scale;
        fe[i][1] = im * scale;
    }
    fftw_execute(pb);
    for (size_t r = 0; r < rows; r++)
        for (size_t c = 0; c < columns; c++)
            out[r * columns + c] = (float)ext[(r + h) * mx + c + h];
cleanup:
    pthread_mutex_lock(&psf_fftw_lock);
    if (pe)
        fftw_destroy_plan(pe);
    if (pk)
        fftw_destroy_plan(pk);
    if (pb)
        fftw_destroy_plan(pb);
    pthread_mutex_unlock(&psf_fftw_lock);
    fftw_free(ext);
    fftw_free(ker);
    fftw_free(fe);
    fftw_free(fk);
    return st;
}

thz_status psf_apply(const psf_kernel *k, const float *in, float *out, uint32_t columns,
                     uint32_t rows, int threads, thz_error *err)
{
    size_t side = 2 * (size_t)k->half + 1;
    if (side * side <= PSF_DIRECT_MAX_TAPS)
        return psf_direct(k, in, out, columns, rows, threads, err);
    return psf_fft(k, in, out, columns, rows, err);
}
