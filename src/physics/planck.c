/* Planck's law and its inverse (physics.md "Units"). */
#include "physics/planck.h"

#include <math.h>

double planck_radiance(double freq_hz, double temp_k)
{
    if (!(temp_k > 0.0) || !(freq_hz > 0.0))
        return 0.0;
    const double h = THZ_PLANCK_H, k = THZ_BOLTZMANN_K, c = THZ_SPEED_OF_LIGHT;
    double x = h * freq_hz / (k * temp_k);
    /* 2 h nu^3 / c^2, written to avoid overflow of nu^3 for large nu. */
    double prefactor = 2.0 * h * freq_hz / c * (freq_hz / c) * freq_hz;
    double denom = expm1(x);
    if (isinf(denom))
        return 0.0;
    /* h nu / k T underflowed to 0 (nu below about 1e-290 Hz): the Rayleigh-Jeans limit
     * 2 nu^2 k T / c^2, which underflows too, instead of 0/0. */
    if (!(denom > 0.0))
        return 2.0 * (freq_hz / c) * (freq_hz / c) * k * temp_k;
    return prefactor / denom;
}

double planck_brightness_temperature(double freq_hz, double radiance)
{
    if (!(radiance > 0.0) || !(freq_hz > 0.0))
        return 0.0;
    const double h = THZ_PLANCK_H, k = THZ_BOLTZMANN_K, c = THZ_SPEED_OF_LIGHT;
    double prefactor = 2.0 * h * freq_hz / c * (freq_hz / c) * freq_hz;
    return h * freq_hz / (k * log1p(prefactor / radiance));
}

double planck_dbdt(double freq_hz, double temp_k)
{
    if (!(temp_k > 0.0))
        return 0.0;
    double x = THZ_PLANCK_H * freq_hz / (THZ_BOLTZMANN_K * temp_k);
    double em1 = expm1(x);
    /* Beyond the Wien tail's overflow B and its derivative are 0; where x underflowed
     * the Rayleigh-Jeans limit 2 nu^2 k / c^2 (both instead of 0/0 or 0 inf). */
    if (isinf(em1))
        return 0.0;
    if (!(em1 > 0.0))
        return 2.0 * (freq_hz / THZ_SPEED_OF_LIGHT) * (freq_hz / THZ_SPEED_OF_LIGHT) *
               THZ_BOLTZMANN_K;
    return planck_radiance(freq_hz, temp_k) * x * (em1 + 1.0) / (em1 * temp_k);
}
