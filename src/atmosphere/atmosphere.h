/* The atmosphere: spectral attenuation alpha(nu) in 1/m along every free path
 * (physics.md eq. 7). Models: none, constant, table; the line-by-line models
 * (itu-p676, lines) and the emitting atmosphere are added by the atmosphere module.
 */
#ifndef THZ_ATMOSPHERE_ATMOSPHERE_H
#define THZ_ATMOSPHERE_ATMOSPHERE_H

#include <stdbool.h>

#include "core/error.h"
#include "physics/channel.h"
#include "physics/spectrum.h"

typedef enum atm_model {
    ATM_NONE = 0,
    ATM_CONSTANT,
    ATM_TABLE,
    ATM_ITU_P676,
    ATM_LINES
} atm_model;

typedef struct thz_atmosphere {
    atm_model model;
    thz_spectrum attenuation_per_m; /* constant and table models */
} thz_atmosphere;

/* Prepares the model for a run over these channels (e.g. tabulates line-by-line
 * alpha over each channel's band); the scene loader calls it once after loading.
 * Thread-safe use of atmosphere_alpha_per_m needs it done. */
thz_status atmosphere_prepare(thz_atmosphere *atm, const thz_channel *channels, size_t n_channels,
                              thz_error *err);

/* alpha(freq_hz) in 1/m; 0 for ATM_NONE. Thread-safe (read only). */
double atmosphere_alpha_per_m(const thz_atmosphere *atm, double freq_hz);

/* exp(-alpha(freq_hz) * distance_m): the transmittance of a free path. */
double atmosphere_transmittance(const thz_atmosphere *atm, double freq_hz, double distance_m);

/* The model's name as in the scene file ("none", "constant", ...). */
const char *atmosphere_model_name(atm_model model);

void atmosphere_fini(thz_atmosphere *atm);

#endif
