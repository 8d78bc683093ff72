/* Pixel statistics of the renderer: per pixel, the mean and spread of the independent
 * estimates of every pass so far (render.h "Passes and the noise estimate"), their
 * standard error, and the channel planes of the images written from them.
 */
#ifndef THZ_SENSOR_RENDER_ACCUM_H
#define THZ_SENSOR_RENDER_ACCUM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "photon/photon_map.h"
#include "scene/scene.h"
#include "sensor/images.h"

/* Per-pixel statistics of one sensor's channel over the passes rendered so far. */
typedef struct render_accum {
    size_t pixels;
    uint64_t n; /* estimates per pixel so far (the same for every pixel) */
    uint32_t passes;
    bool poisson; /* photon-map: var holds the Poisson variance of the mean */
    double *mean; /* per pixel: mean of the estimates, W m^-2 sr^-1 Hz^-1 */
    double *m2;   /* per pixel: sum of squared deviations from the mean (or, poisson,
                     the variance of the mean: NaN, unknown, where a sample was short
                     of photons) */
    /* final-gather with a batched photon map (photon_map.h), else NULL: the map's own
     * noise, which the spread of the estimates given the map cannot show */
    double *batch;    /* [pixel * PHOTON_MAP_BATCHES + b]: sum over all estimates of the
                         photon terms of batch b */
    double *disk_var; /* per pixel: sum over all estimates of their photon terms' Poisson
                        variance (sum of squared terms over disk areas squared) */
} render_accum;

thz_status render_accum_init(render_accum *acc, size_t pixels, thz_error *err);
void render_accum_fini(render_accum *acc);

/* Standard error of pixel p's mean, W m^-2 sr^-1 Hz^-1 (0 with fewer than 2 estimates;
 * NaN, unknown, for a photon-map pixel with a sample short of photons).
 * With a batched photon map (final-gather) the variance is s^2 / N from the estimates'
 * spread given the map, plus the map's own variance given the gather rays: the spread of
 * the pixel's photon part between the independent batches, s_B^2 / B, less what s^2 / N
 * already holds of it (each gather disk's own Poisson variance, sum / N^2), at least 0. */
double render_accum_stderr(const render_accum *acc, size_t p);

/* The photon map's share of pixel p's standard error (the second term above): the part
 * that more estimates from the same map do not lower, final-gather's floor. 0 without
 * batches or with fewer than 2 estimates. */
double render_accum_map_stderr(const render_accum *acc, size_t p);

/* Allocates the photon batches and disk variances (final-gather from a batched map);
 * nothing if they are there. */
thz_status render_accum_want_batches(render_accum *acc, thz_error *err);

/* Merges pixel p's n_est estimates of one pass (est; with batches, their batch sums and
 * disk variance) into acc (Chan et al.); acc->n still counts the earlier passes only.
 * Poisson (photon-map, one estimate): sets the pixel's mean est[0] and variance var. */
void render_accum_add_pixel(render_accum *acc, size_t p, const double *est, uint32_t n_est,
                            const double *batch, const double *disk_var);
void render_accum_set_poisson_pixel(render_accum *acc, size_t p, double mean, double var);

/* Closes a pass of n_est estimates per pixel (poisson: photon-map's one pass). */
void render_accum_end_pass(render_accum *acc, uint32_t n_est, bool poisson);

/* Writes the channel's planes of `images` from `acc`: radiance, power,
 * brightness_temperature, normalized and, when images->radiance_stderr is set, the
 * standard error of L_c. */
thz_status render_accum_write(const thz_scene *scene, size_t channel, size_t sensor,
                              const render_accum *acc, sensor_images *images, thz_error *err);

/* dTb/dL inverse: the standard error in K of a brightness temperature tb_k (> 0) at
 * freq_hz whose radiance has standard error stderr_l (W m^-2 sr^-1 Hz^-1), to first
 * order: stderr_l / (dB_nu/dT at tb_k). */
double render_stderr_k(double freq_hz, double tb_k, double stderr_l);

#endif
