/* thzmap public API: atmosphere models on their own (include thzmap/thzmap.h, which
 * includes this), for tabulating and plotting attenuation as `thzmap atmosphere` does.
 *
 * A thz_atm is an attenuation model alpha(nu) in air of a given temperature, pressure
 * and humidity: "lines" (line-by-line from catalogues), "itu-p676" (1-1000 GHz) or
 * "none"; or a scene's atmosphere, whatever its model. Read-only once made.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_ATMOSPHERE_H
#define THZMAP_ATMOSPHERE_H

#ifdef __cplusplus
extern "C" {
#endif

/* Limits of the air state (K, hPa) and nepers to decibels (dB = NEPER_TO_DB * Np). */
#define THZ_AIR_MIN_TEMPERATURE_K 100.0
#define THZ_AIR_MAX_TEMPERATURE_K 400.0
#define THZ_AIR_MAX_PRESSURE_HPA 2000.0
#define THZ_NEPER_TO_DB 4.342944819032518

typedef enum thz_humidity_kind {
    THZ_HUMIDITY_DRY = 0,
    THZ_HUMIDITY_RELATIVE,     /* 0..1 over liquid water (ITU-R P.453-14) */
    THZ_HUMIDITY_DENSITY_G_M3, /* water-vapour density, g/m^3 */
    THZ_HUMIDITY_VMR           /* water-vapour volume mixing ratio of the total air */
} thz_humidity_kind;

typedef struct thz_atm_options {
    const char *model;    /* "lines", "itu-p676" or "none"; NULL: "lines" */
    double temperature_k; /* default 288.15 */
    double pressure_hpa;  /* total (dry air + water vapour), default 1013.25 */
    thz_humidity_kind humidity_kind;
    double humidity;            /* default 7.5 g/m^3 */
    const char *h2o_lines_file; /* lines: H2O catalogue (am CSV or HITRAN .par); NULL: built in */
    const char *o2_lines_file;  /* lines: uncoupled O2 catalogue; NULL: built in */
    int no_continuum;           /* lines: no MT_CKD continuum (full H2O line wings) */
} thz_atm_options;

typedef struct thz_atm thz_atm;

/* Fills *opt with the defaults above (model "lines"). */
THZ_API void thz_atm_options_init(thz_atm_options *opt);
/* THZ_OK when the options' air state is valid, else THZ_ERR_INPUT saying why. */
THZ_API thz_status thz_atm_check_air(const thz_atm_options *opt, thz_error *err);
/* Makes the model opt->model in the options' air, or in the air of `air_from` when it
 * is not NULL and has air (to compare two models in the same air). *out is owned. */
THZ_API thz_status thz_atm_create(const thz_atm_options *opt, const thz_atm *air_from,
                                  thz_atm **out, thz_error *err);
/* The scene's atmosphere (borrowed: the scene must outlive *out). */
THZ_API thz_status thz_atm_from_scene(const thz_scene *scene, thz_atm **out, thz_error *err);
THZ_API void thz_atm_destroy(thz_atm *atm);

typedef struct thz_atm_info {
    const char *model; /* static */
    int has_air;       /* itu-p676 and lines; 0: the five fields after it are 0 */
    double temperature_k, pressure_hpa, h2o_pressure_hpa, h2o_density_g_m3, h2o_vmr;
    /* (added with the emission's fields; the library fills the whole struct: a program
     * built against an older header must be rebuilt, the ABI is not stable before 1.0) */
    int emitting;                    /* the air emits B_nu(T) per optical depth (any model) */
    double emission_temperature_k;   /* that T, K: a scene's default is its enclosure's */
    double background_temperature_k; /* what rays leaving the scene see, K */
} thz_atm_info;
THZ_API void thz_atm_get_info(const thz_atm *atm, thz_atm_info *out);

/* THZ_ERR_INPUT when [lo_hz, hi_hz] leaves the model's range, is not finite or runs
 * backwards (lo_hz > hi_hz); `what` names the range in the message (e.g. an option). */
THZ_API thz_status thz_atm_check_range(const thz_atm *atm, double lo_hz, double hi_hz,
                                       const char *what, thz_error *err);

/* alpha at freq_hz in 1/m, per part (parts a model lacks are 0; itu-p676 puts all of
 * its water vapour into h2o_lines_per_m); total_per_m is their sum. Every part is NaN
 * at a negative or non-finite freq_hz or for a NULL atm. */
typedef struct thz_atm_attenuation {
    double total_per_m;
    double h2o_lines_per_m, h2o_continuum_per_m, o2_per_m, dry_continuum_per_m;
} thz_atm_attenuation;
THZ_API void thz_atm_attenuation_parts(const thz_atm *atm, double freq_hz,
                                       thz_atm_attenuation *out);
/* alpha at freq_hz in 1/m, computed directly (no tabulation); NaN at a negative or non-finite
 * freq_hz or for a NULL atm. */
THZ_API double thz_atm_attenuation_per_m(const thz_atm *atm, double freq_hz);

/* THZ_OK when PLplot's pngcairo device is there, else THZ_ERR_IO naming the package. */
THZ_API thz_status thz_plot_check(thz_error *err);

/* The attenuation figure of `thzmap atmosphere --plot`: the parts of `atm` and its
 * total (and compare_db's, if not NULL) in dB/km on a log axis against THz, the
 * scene's channels (if scene is not NULL) shaded. Arrays have n > 0 entries; f_thz and
 * total_db are required, and the parts atm's model has (lines: all four; itu-p676:
 * h2o_lines_db, o2_db, dry_db); else, or without a path, THZ_ERR_INPUT. NULL names:
 * the models' own. Draws with PLplot, serialised process-wide. */
typedef struct thz_atm_plot {
    const char *path; /* PNG file */
    const thz_atm *atm;
    const char *model_name;
    const thz_atm *compare; /* may be NULL */
    const char *compare_name;
    const thz_scene *scene; /* may be NULL */
    size_t n;
    const double *f_thz, *total_db, *h2o_lines_db, *h2o_continuum_db, *o2_db, *dry_db;
    const double *compare_db; /* may be NULL */
} thz_atm_plot;
THZ_API thz_status thz_atm_draw_plot(const thz_atm_plot *plot, thz_error *err);

#ifdef __cplusplus
}
#endif
#endif
