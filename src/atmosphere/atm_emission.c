/* The emitting atmosphere: the air at temperature T_air emits B_nu(T_air) per unit
 * optical depth (Kirchhoff's law for a non-scattering gas in local thermodynamic
 * equilibrium), inside an optional box-shaped extent beyond which a black
 * background at T_bg is seen. These are the atmosphere-side pieces; the photon phase
 * (src/photon/air_emission.c) and the renderer (render_air in src/sensor/render_terms.c,
 * band means over the channel's quadrature) call them. */
#include <math.h>

#include "atmosphere/atmosphere.h"
#include "physics/planck.h"

thz_status atmosphere_set_emitting(thz_atmosphere *atm, double temperature_k,
                                   double background_temperature_k, thz_error *err)
{
    if (!(temperature_k > 0.0 && temperature_k <= 1000.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "emitting atmosphere: temperature must be above 0 and at most "
                             "1000 K, got %g K",
                             temperature_k);
    if (!(background_temperature_k >= 0.0 && background_temperature_k <= 10000.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "emitting atmosphere: background temperature must be 0 to 10000 K, "
                             "got %g K",
                             background_temperature_k);
    if (atm->has_air && atm->air.temperature_k != temperature_k)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "emitting atmosphere: temperature %g K differs from the air's %g K",
                             temperature_k, atm->air.temperature_k);
    atm->air.temperature_k = temperature_k;
    atm->emitting = true;
    atm->background_temperature_k = background_temperature_k;
    return THZ_OK;
}

thz_status atmosphere_set_extent(thz_atmosphere *atm, const double min_m[3], const double max_m[3],
                                 thz_error *err)
{
    for (int i = 0; i < 3; i++)
        if (!(min_m[i] < max_m[i]) || !isfinite(min_m[i]) || !isfinite(max_m[i]))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "atmosphere extent: min must be below max on every axis "
                                 "(axis %d: %g m, %g m)",
                                 i, min_m[i], max_m[i]);
    for (int i = 0; i < 3; i++) {
        atm->extent_min_m[i] = min_m[i];
        atm->extent_max_m[i] = max_m[i];
    }
    atm->has_extent = true;
    return THZ_OK;
}

double atmosphere_volume_emission_w_per_m3_hz(const thz_atmosphere *atm, double freq_hz)
{
    if (!atm->emitting)
        return 0.0;
    return 4.0 * M_PI * atmosphere_alpha_per_m(atm, freq_hz) *
           planck_radiance(freq_hz, atm->air.temperature_k);
}

double atmosphere_extent_exit_m(const thz_atmosphere *atm, const double origin_m[3],
                                const double direction[3])
{
    if (!atm->has_extent)
        return INFINITY;
    double t_exit = INFINITY;
    for (int i = 0; i < 3; i++) {
        double o = origin_m[i];
        if (o < atm->extent_min_m[i] || o > atm->extent_max_m[i])
            return 0.0;
        double d = direction[i];
        if (d > 0.0)
            t_exit = fmin(t_exit, (atm->extent_max_m[i] - o) / d);
        else if (d < 0.0)
            t_exit = fmin(t_exit, (atm->extent_min_m[i] - o) / d);
    }
    return t_exit;
}
