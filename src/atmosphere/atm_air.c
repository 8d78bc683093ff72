/* The state of the air: temperature, total pressure and the water-vapour partial
 * pressure derived from whichever humidity the user gave. */
#include <math.h>

#include "atmosphere/atmosphere.h"

/* ITU-R P.453-14 eq. 9 and 10, over liquid water: t in deg C, P in hPa.
 * EF = 1 + 1e-4 (7.2 + P (0.0320 + 5.9e-6 t^2));
 * e_s = EF * 6.1121 exp((18.678 - t/234.5) t / (t + 257.14)). */
double atm_saturation_pressure_hpa(double temperature_k, double pressure_hpa)
{
    double t = temperature_k - 273.15;
    double ef = 1.0 + 1e-4 * (7.2 + pressure_hpa * (0.0320 + 5.9e-6 * t * t));
    return ef * 6.1121 * exp((18.678 - t / 234.5) * t / (t + 257.14));
}

thz_status atm_air_state_init(atm_air_state *air, double temperature_k, double pressure_hpa,
                              atm_humidity_kind kind, double value, thz_error *err)
{
    if (!(temperature_k >= ATM_AIR_MIN_TEMPERATURE_K && temperature_k <= ATM_AIR_MAX_TEMPERATURE_K))
        return thz_error_set(err, THZ_ERR_INPUT, "air temperature must be %g to %g K, got %g K",
                             ATM_AIR_MIN_TEMPERATURE_K, ATM_AIR_MAX_TEMPERATURE_K, temperature_k);
    if (!(pressure_hpa > 0.0 && pressure_hpa <= ATM_AIR_MAX_PRESSURE_HPA))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "air pressure must be above 0 and at most %g hPa, got %g hPa",
                             ATM_AIR_MAX_PRESSURE_HPA, pressure_hpa);
    double e = 0.0;
    switch (kind) {
    case ATM_HUMIDITY_NONE:
        break;
    case ATM_HUMIDITY_RELATIVE:
        if (!(value >= 0.0 && value <= 1.0))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "relative humidity must be 0 to 1 (a fraction, not per cent), "
                                 "got %g",
                                 value);
        e = value * atm_saturation_pressure_hpa(temperature_k, pressure_hpa);
        break;
    case ATM_HUMIDITY_DENSITY_G_M3:
        if (!(value >= 0.0 && isfinite(value)))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "water-vapour density must be >= 0 g/m^3, got %g g/m^3", value);
        e = value * temperature_k / 216.7; /* ITU-R P.453-14 eq. 4 */
        break;
    case ATM_HUMIDITY_VMR:
        if (!(value >= 0.0 && value < 1.0))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "H2O volume mixing ratio must be 0 to below 1, got %g", value);
        e = value * pressure_hpa;
        break;
    }
    if (e >= pressure_hpa)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "water-vapour pressure %g hPa is not below the total pressure %g hPa",
                             e, pressure_hpa);
    air->temperature_k = temperature_k;
    air->pressure_hpa = pressure_hpa;
    air->h2o_pressure_hpa = e;
    return THZ_OK;
}

double atm_air_h2o_density_g_m3(const atm_air_state *air)
{
    return air->h2o_pressure_hpa * 216.7 / air->temperature_k;
}

double atm_air_h2o_vmr(const atm_air_state *air)
{
    return air->h2o_pressure_hpa / air->pressure_hpa;
}
