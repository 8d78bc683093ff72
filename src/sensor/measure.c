/* Measured images: PSF, then noise, then the brightness temperature (measure.h). */
#include "sensor/measure.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/c_locale.h"
#include "physics/planck.h"
#include "sensor/noise.h"
#include "sensor/psf.h"

bool sensor_has_model(const thz_sensor *sn)
{
    return sn->psf != PSF_NONE || sn->noise.kind != NOISE_NONE;
}

uint64_t sensor_noise_seed(const thz_sensor *sn, uint64_t run_seed)
{
    return sn->noise_seed_given ? sn->noise_seed : run_seed;
}

const char *sensor_psf_name(thz_psf_kind psf)
{
    return psf == PSF_AIRY ? "airy" : psf == PSF_GAUSSIAN ? "gaussian" : "none";
}

const char *sensor_noise_name(const thz_sensor_noise *noise)
{
    if (noise->kind == NOISE_NETD)
        return "netd";
    if (noise->kind == NOISE_RADIOMETER)
        return noise->radiometer == RADIOMETER_DICKE ? "dicke" : "total-power";
    return "none";
}

void sensor_model_describe(const thz_sensor *sn, size_t channel, size_t n_channels,
                           uint64_t noise_seed, char *buf, size_t size)
{
    locale_t previous = thz_locale_enter(); /* written into files: "0.05", never "0,05" */
    int n = 0;
    if (sn->psf == PSF_AIRY)
        n = snprintf(buf, size, "Airy D %g m", sn->aperture_diameter_m);
    else if (sn->psf == PSF_GAUSSIAN)
        n = snprintf(buf, size, "Gaussian FWHM %g deg", sn->psf_fwhm_deg);
    else
        n = snprintf(buf, size, "no PSF");
    size_t used = n > 0 && (size_t)n < size ? (size_t)n : size - 1;
    const thz_sensor_noise *ns = &sn->noise;
    if (ns->kind == NOISE_NETD && channel != SIZE_MAX) {
        snprintf(buf + used, size - used, "; NETD %g K; seed %llu", ns->netd_k[channel],
                 (unsigned long long)noise_seed);
    } else if (ns->kind == NOISE_NETD) { /* the whole cube: every channel's NETD */
        int k = snprintf(buf + used, size - used, "; NETD per channel ");
        for (size_t c = 0; c < n_channels && k > 0; c++) {
            used += (size_t)k < size - used ? (size_t)k : size - used - 1;
            k = snprintf(buf + used, size - used, "%s%g", c ? " / " : "", ns->netd_k[c]);
        }
        if (k > 0)
            used += (size_t)k < size - used ? (size_t)k : size - used - 1;
        snprintf(buf + used, size - used, " K; seed %llu", (unsigned long long)noise_seed);
    } else if (ns->kind == NOISE_RADIOMETER)
        snprintf(buf + used, size - used, "; %s T_rec %g K tau %g s; seed %llu",
                 sensor_noise_name(ns), ns->receiver_temperature_k, ns->integration_time_s,
                 (unsigned long long)noise_seed);
    else
        snprintf(buf + used, size - used, "; no noise");
    thz_locale_leave(previous);
}

/* Tb of every pixel of a plane, as the truth cube's. */
static void measure_tb(const thz_channel *ch, const float *radiance, float *tb_k, size_t pixels)
{
    for (size_t p = 0; p < pixels; p++)
        tb_k[p] = radiance[p] > 0.0f
                      ? (float)planck_brightness_temperature(ch->center_hz, radiance[p])
                      : 0.0f;
}

/* Whether every measured radiance and brightness temperature is finite. */
static bool measure_finite(const float *l, const float *tb, size_t pixels)
{
    bool ok = true;
    for (size_t p = 0; p < pixels; p++)
        ok &= isfinite(l[p]) && isfinite(tb[p]);
    return ok;
}

thz_status sensor_measure(const thz_scene *scene, size_t sensor, uint64_t run_seed,
                          sensor_images *img, int threads, thz_error *err)
{
    const thz_sensor *sn = &scene->sensors[sensor];
    if (!sensor_has_model(sn))
        return THZ_OK;
    size_t pixels = (size_t)img->columns * img->rows;
    size_t cube = pixels * img->n_channels;
    free(img->measured_radiance);
    free(img->measured_brightness_temperature);
    img->measured_radiance = thz_malloc_array(cube, sizeof(float));
    img->measured_brightness_temperature = thz_malloc_array(cube, sizeof(float));
    if (!img->measured_radiance || !img->measured_brightness_temperature)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the measured images of '%s'",
                             sn->name);
    uint64_t seed = sensor_noise_seed(sn, run_seed);
    img->noise_seed = seed;
    thz_status st = THZ_OK;
    for (size_t c = 0; c < img->n_channels && st == THZ_OK; c++) {
        const thz_channel *ch = &scene->channels[c];
        const float *truth = img->radiance + c * pixels;
        float *l = img->measured_radiance + c * pixels;
        float *tb = img->measured_brightness_temperature + c * pixels;
        if (sn->psf != PSF_NONE) {
            psf_kernel k;
            st = psf_kernel_init(&k, sn, ch, err);
            if (st == THZ_OK)
                st = psf_apply(&k, truth, l, img->columns, img->rows, threads, err);
            psf_kernel_fini(&k);
        } else {
            memcpy(l, truth, pixels * sizeof *l);
        }
        if (st == THZ_OK && sn->noise.kind != NOISE_NONE) {
            measure_tb(ch, l, tb, pixels); /* noise-free, after the PSF */
            st = noise_apply(sn, sensor, ch, c, seed, tb, l, threads, err);
        }
        if (st == THZ_OK)
            measure_tb(ch, l, tb, pixels);
        if (st == THZ_OK && !measure_finite(l, tb, pixels))
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: sensors[%zu].noise (sensor '%s'), channel %zu: the noise "
                               "takes the measured image beyond the range of its 32-bit values "
                               "(an absurd netd_k, receiver_temperature_k or integration_time_s?)",
                               scene->path ? scene->path : "scene", sensor, sn->name, c + 1);
    }
    return st;
}
