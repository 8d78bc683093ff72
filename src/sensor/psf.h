/* The sensor's point-spread function (scene-format.md "Sensors: optics and noise";
 * physics.md "Sensor: optics and noise"): the blur of the aperture, applied to a
 * channel's noise-free radiance image in angle.
 *
 * airy:     the Fraunhofer pattern of a circular aperture of diameter D at frequency nu,
 *           per steradian and normalised to 1 over the sphere (small angles):
 *             P_nu(theta) = (pi D^2 / (4 lambda^2)) [2 J1(x) / x]^2,
 *             x = pi D sin(theta) / lambda,  lambda = c / nu,
 *           averaged over the channel's response g_c with the channel's quadrature
 *           (channel_quadrature_init): P_c(theta) = sum_k w_k P_nu_k(theta).
 *           Support: theta <= PSF_AIRY_SUPPORT lambda_c / D (>= 99 % of the power of
 *           every frequency of the band; the rest is put back by normalisation).
 * gaussian: exp(-theta^2 / (2 sigma^2)), sigma = FWHM / 2.3548, out to 4 FWHM.
 *
 * Discretisation: the kernel lives in pixel units, with the angular pixel pitch at the
 * image centre (the camera's pitch s = 2 tan(fov/2) / columns, which is d(angle) per
 * pixel on the axis). Off axis a pixel subtends less angle (cos^2 of the off-axis angle
 * radially, cos tangentially), so the blur there is slightly too small in angle: exact
 * on the axis, 1 % at 5.7 deg, 3 % at 10 deg off axis. Kernel pixel (dx, dy) is the
 * mean of P_c over its cell, sampled at n x n points (n chosen so that the sub-sample
 * spacing is at most an eighth of the PSF's FWHM, 1 <= n <= PSF_MAX_SUBSAMPLES): the
 * sharp image is taken as pixel-centre samples and each detector pixel integrates the
 * PSF over its cell. With oversampling > 1 the sharp image is already each pixel's mean,
 * and n = 1: P_c at the kernel pixels' centres (the cell counted once). The kernel is
 * normalised to sum exactly to 1. A PSF wider than the image is folded onto offsets
 * within the image's size (the mirror border's period, below); one whose fold would
 * take more than PSF_FOLD_MAX_SAMPLES samples is refused. A PSF whose support
 * lies within the central pixel (radius <= half the pitch: a large aperture or a tiny
 * FWHM) is the one-pixel kernel 1 exactly: no blur.
 *
 * Border: the image is extended beyond each edge by mirror reflection about the edge
 * (pixel -1 is pixel 0, pixel -2 is pixel 1, ..., repeated for kernels wider than the
 * image). With a kernel that sums to 1 and is symmetric, this conserves the image's
 * total radiance exactly (the power one pixel sends past an edge is what its mirror
 * image sends back in) and leaves a uniform image unchanged.
 *
 * Convolution: direct for kernels of at most PSF_DIRECT_MAX_TAPS taps, else FFT (FFTW,
 * real-to-complex, FFTW_ESTIMATE plans on fftw_malloc'd arrays: the same plan, and so
 * bit-identical results, on every run; plan creation is serialised by a process-wide
 * mutex, the FFTW planner not being thread-safe). Both are independent of the thread
 * count.
 */
#ifndef THZ_SENSOR_PSF_H
#define THZ_SENSOR_PSF_H

#include <stdint.h>

#include "core/error.h"
#include "physics/channel.h"
#include "scene/scene.h"

/* Airy support radius in units of lambda_c / D. */
#define PSF_AIRY_SUPPORT 25.0
/* Most sub-samples per pixel side. */
#define PSF_MAX_SUBSAMPLES 16u
/* Most PSF samples a kernel folded onto the image (wider than it) may take: a PSF
 * reaching 4 096 pixels from the centre. */
#define PSF_FOLD_MAX_SAMPLES ((double)(1u << 26))
/* Kernels with more taps than this are applied by FFT. */
#define PSF_DIRECT_MAX_TAPS 441u

typedef struct psf_kernel {
    uint32_t half;       /* the kernel is (2 half + 1)^2 pixels, centred on the pixel */
    uint32_t subsamples; /* n: n x n samples of the PSF per kernel pixel */
    double pitch_rad;    /* angular pixel pitch at the image centre, rad */
    double *weight;      /* [(dy + half) (2 half + 1) + dx + half], sums to 1 */
} psf_kernel;

/* P_nu(theta) of the circular aperture, per steradian (normalised to 1 over the sphere
 * for small angles). */
double psf_airy(double theta_rad, double freq_hz, double diameter_m);

/* The kernel of sensor sn's PSF (psf != none) in channel ch, in pixel units. */
thz_status psf_kernel_init(psf_kernel *k, const thz_sensor *sn, const thz_channel *ch,
                           thz_error *err);
void psf_kernel_fini(psf_kernel *k);
/* THZ_OK if psf_kernel_init can build sn's kernel in channel ch, else its refusal (a PSF
 * too much wider than the image): the run asks before its work. */
thz_status psf_kernel_check(const thz_sensor *sn, const thz_channel *ch, thz_error *err);
/* THZ_OK if sensor i of scene sc has no PSF or psf_kernel_check accepts it in every
 * channel, else that refusal named "FILE: sensors[i].KEY: ...", KEY the one that sets the
 * PSF's width: the Gaussian's psf_fwhm_deg, or the aperture_diameter_m whose diffraction
 * spreads the Airy pattern. Loading through the API asks it of every sensor (so validate
 * says it), a run of the sensors it renders. */
thz_status psf_sensor_check(const thz_scene *sc, size_t i, thz_error *err);

/* out = k convolved with in (one plane of columns x rows, row-major), with the mirror
 * border above; in and out must not overlap. */
thz_status psf_apply(const psf_kernel *k, const float *in, float *out, uint32_t columns,
                     uint32_t rows, int threads, thz_error *err);

#endif
