/* The sensor as built (scene-format.md "Sensors: optics and noise"): the measured
 * images S.measured_radiance and S.measured_brightness_temperature, made from a
 * sensor's finished noise-free radiance cube by its PSF (sensor/psf.h) and then its
 * radiometer noise (sensor/noise.h). The noise-free cubes are left as they are (they
 * are the truth). Tb is the same inversion as the truth cube's (physics.md "Rendering
 * phase": Planck at the channel centre; 0 where L <= 0).
 */
#ifndef THZ_SENSOR_MEASURE_H
#define THZ_SENSOR_MEASURE_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "scene/scene.h"
#include "sensor/images.h"

/* Whether sn has a PSF or noise, and so measured images. */
bool sensor_has_model(const thz_sensor *sn);

/* The seed of sn's noise: noise_seed when given, else the run's seed. */
uint64_t sensor_noise_seed(const thz_sensor *sn, uint64_t run_seed);

/* The names of the models as in the scene file: PSF (indexed by thz_psf_kind) and
 * noise ("netd", "total-power", "dicke", "none"). */
const char *sensor_psf_name(thz_psf_kind psf);
const char *sensor_noise_name(const thz_sensor_noise *noise);

/* A one-line description of sn's model in channel `channel` for titles and captions,
 * e.g. "Airy D 0.5 m; total-power T_rec 500 K tau 0.01 s; seed 1" or "no PSF; NETD
 * 0.3 K; seed 7" (the given NETD is the channel's; the seed is the noise's). With
 * channel SIZE_MAX, of the whole cube of n_channels: every channel's given NETD
 * ("NETD per channel 0.2 / 0.3 K"). */
void sensor_model_describe(const thz_sensor *sn, size_t channel, size_t n_channels,
                           uint64_t noise_seed, char *buf, size_t size);

/* Allocates and fills img->measured_* of scene sensor `sensor` from img->radiance
 * (nothing when the sensor has no model). Bit-identical for any thread count. */
thz_status sensor_measure(const thz_scene *scene, size_t sensor, uint64_t run_seed,
                          sensor_images *img, int threads, thz_error *err);

#endif
