/* The `lines` model's data at the air's state, shared by its set-up and direct sums
 * (atm_lines.c) and its fast evaluation over one band (atm_lines_band.c): the lines and
 * one line's contribution to alpha. Nothing outside src/atmosphere/ includes this. */
#ifndef THZ_ATMOSPHERE_ATM_LINES_DATA_H
#define THZ_ATMOSPHERE_ATM_LINES_DATA_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "atmosphere/atm_internal.h"

#define H2O_CUTOFF_GHZ 750.0 /* 25 cm^-1: MT_CKD's line cut-off */
/* Voigt within this many gamma_D of the centre; beyond, Voigt = Lorentz to ~3e-7
 * relative */
#define VOIGT_WINDOW 3000.0

/* A line at the air's state. */
typedef struct lbl_line {
    double nu_ghz;      /* shifted centre */
    double amp;         /* n S(T) / pi in cm^-1 GHz: alpha = amp * shape [1/GHz] */
    double inv_vvh0;    /* 1 / (nu0 tanh(h nu0 / 2kT)), the VVH normalisation */
    double gamma_ghz;   /* Lorentz HWHM */
    double gamma_d_ghz; /* Doppler HWHM */
    double y, g;        /* mixing: Y (dimensionless) and G (1 for uncoupled) */
    double pedestal;    /* cut-off shapes: L(cutoff) */
    bool voigt;
} lbl_line;

typedef enum lbl_shape { SHAPE_VVH_CUTOFF, SHAPE_VVH, SHAPE_GROSS, SHAPE_COUPLED } lbl_shape;

typedef struct lbl_species {
    lbl_shape shape;
    size_t n;
    lbl_line *lines; /* sorted by nu_ghz */
} lbl_species;

struct atm_lines_data {
    atm_air_state air;
    double half_h_over_kt; /* h / (2 k T) in 1/GHz */
    lbl_species h2o, o2, o2_coupled;
    bool continuum;
    const struct atm_inputs *inputs; /* the files read (atm_inputs.h), held while d lives:
                                        their MT_CKD table */
    double n_h2o, n_foreign, n_ref;  /* cm^-3 */
    double dry_hpa;
};

static inline double lorentz(double d, double gamma)
{
    return gamma / (d * d + gamma * gamma);
}

/* The resonant core, scaled like lorentz(): pi times the area-normalised profile. */
static inline double core(const struct lbl_line *l, double d)
{
    if (l->voigt && fabs(d) < VOIGT_WINDOW * l->gamma_d_ghz)
        return M_PI * atm_voigt(d, l->gamma_ghz, l->gamma_d_ghz);
    return lorentz(d, l->gamma_ghz);
}

/* The Van Vleck-Huber factor f tanh(h f / 2kT) at f GHz, which the lines' shapes but
 * Gross's carry (lbl_line_alpha's vvh). */
static inline double lbl_vvh(const atm_lines_data *d, double f)
{
    return f * tanh(f * d->half_h_over_kt);
}

/* Line l's alpha in 1/cm at f GHz, for a species of the given shape; vvh = f tanh(h f /
 * 2kT). */
static inline double lbl_line_alpha(lbl_shape shape, const lbl_line *l, double f, double vvh)
{
    double d1 = f - l->nu_ghz, d2 = f + l->nu_ghz;
    double g = l->gamma_ghz;
    double term;
    switch (shape) {
    case SHAPE_COUPLED:
        /* where Doppler matters, the resonant absorption G L(d1) becomes G times the
         * Voigt core; the dispersive d1 Y / (d1^2 + g^2) stays (Y grows with pressure:
         * it is negligible there) */
        if (l->voigt)
            term = l->g * core(l, d1) + d1 * l->y / (d1 * d1 + g * g);
        else
            term = (g * l->g + d1 * l->y) / (d1 * d1 + g * g);
        term += (g * l->g - d2 * l->y) / (d2 * d2 + g * g);
        break;
    case SHAPE_VVH_CUTOFF:
        term = 0.0;
        if (fabs(d1) < H2O_CUTOFF_GHZ)
            term += core(l, d1) - l->pedestal;
        if (d2 < H2O_CUTOFF_GHZ)
            term += lorentz(d2, g) - l->pedestal;
        break;
    case SHAPE_GROSS: {
        /* Gross: (1/pi) 4 nu^2 gamma / ((nu^2 - nu0^2)^2 + 4 nu^2 gamma^2); where
         * Doppler matters, times Voigt / Lorentz of the resonant core */
        double dd = f * f - l->nu_ghz * l->nu_ghz;
        term = 4.0 * f * f * g / (dd * dd + 4.0 * f * f * g * g);
        if (l->voigt)
            term *= core(l, d1) / lorentz(d1, g);
        return l->amp * term;
    }
    case SHAPE_VVH:
    default:
        term = core(l, d1) + lorentz(d2, g);
        break;
    }
    return l->amp * term * vvh * l->inv_vvh0;
}

/* The continua's alpha in 1/cm at f GHz: MT_CKD's water vapour and dry air's. */
double atm_lines_continua_per_cm(const atm_lines_data *d, double f_ghz);

#endif
