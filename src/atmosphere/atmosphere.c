/* Atmospheric attenuation: dispatch over the models. */
#include "atmosphere/atmosphere.h"

#include <math.h>

thz_status atmosphere_prepare(thz_atmosphere *atm, const thz_channel *channels, size_t n_channels,
                              thz_error *err)
{
    (void)atm;
    (void)channels;
    (void)n_channels;
    (void)err;
    return THZ_OK;
}

double atmosphere_alpha_per_m(const thz_atmosphere *atm, double freq_hz)
{
    switch (atm->model) {
    case ATM_NONE:
        return 0.0;
    case ATM_CONSTANT:
    case ATM_TABLE:
        return spectrum_eval(&atm->attenuation_per_m, freq_hz);
    case ATM_ITU_P676:
    case ATM_LINES:
        break;
    }
    return 0.0;
}

double atmosphere_transmittance(const thz_atmosphere *atm, double freq_hz, double distance_m)
{
    if (atm->model == ATM_NONE)
        return 1.0;
    return exp(-atmosphere_alpha_per_m(atm, freq_hz) * distance_m);
}

const char *atmosphere_model_name(atm_model model)
{
    switch (model) {
    case ATM_NONE:
        return "none";
    case ATM_CONSTANT:
        return "constant";
    case ATM_TABLE:
        return "table";
    case ATM_ITU_P676:
        return "itu-p676";
    case ATM_LINES:
        return "lines";
    }
    return "unknown";
}

void atmosphere_fini(thz_atmosphere *atm)
{
    spectrum_fini(&atm->attenuation_per_m);
    atm->model = ATM_NONE;
}
