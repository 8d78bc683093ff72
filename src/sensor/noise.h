/* The sensor's radiometer noise (scene-format.md "Sensors: optics and noise";
 * physics.md "Sensor: optics and noise").
 *
 * NETD per pixel and channel: given (netd_k), or the radiometer equation
 *   NETD = K (Tb + T_rec) / sqrt(B_n tau),  K = 1 total-power, 2 Dicke,
 * Tb the pixel's noise-free (post-PSF) brightness temperature, B_n the channel's noise
 * bandwidth (channel_noise_bandwidth_hz). The noise is Gaussian in L_c with
 *   sigma_L = NETD dB_c/dT (Tb),
 * dB_c/dT the band mean of dB_nu/dT over the channel's quadrature. sigma_L(Tb) is
 * computed so at 1027 temperatures spanning the plane's positive Tb, uniform in ln Tb,
 * and interpolated by a cubic per pixel: relative error below 1e-12 over 250..320 K; it
 * grows with the plane's span and the frequency where Tb << h nu / k, where sigma_L is
 * exponentially small (at 3 THz over 2.7..1000 K: about 1.5e-4). Its random numbers
 * come from rng_init(seed, channel, RNG_PURPOSE_SENSOR_NOISE, sensor << 32 | pixel): one
 * stream per (seed, sensor, channel, pixel), so the noise is independent between pixels
 * and channels and bit-identical for any thread count.
 */
#ifndef THZ_SENSOR_NOISE_H
#define THZ_SENSOR_NOISE_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "physics/channel.h"
#include "scene/scene.h"

/* NETD of channel c (ch) at brightness temperature tb_k, K; 0 without noise. */
double noise_netd_k(const thz_sensor_noise *n, const thz_channel *ch, size_t c, double tb_k);

/* Adds the noise of scene sensor `sensor` (its noise model is not none) to channel c's
 * plane `radiance` (columns x rows, in place), given the plane's noise-free brightness
 * temperatures tb_k. */
thz_status noise_apply(const thz_sensor *sn, size_t sensor, const thz_channel *ch, size_t c,
                       uint64_t seed, const float *tb_k, float *radiance, int threads,
                       thz_error *err);

#endif
