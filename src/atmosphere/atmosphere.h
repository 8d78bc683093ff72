/* The atmosphere: spectral attenuation alpha(nu) in 1/m along every free path
 * (physics.md eq. 7), and, when it emits, its thermal radiance.
 *
 * Models: none, constant, table (alpha given by the user), and two computed from
 * the state of the air (temperature, total pressure, humidity):
 *   itu-p676  ITU-R P.676-13 Annex 1 line-by-line, 1-1000 GHz (atm_itu_p676.c);
 *   lines     line-by-line from spectral line catalogues (am 14.0 / HITRAN CSV or
 *             HITRAN .par files) with the MT_CKD water-vapour continuum, O2 line
 *             mixing and a dry-air collision-induced continuum (atm_lines.c).
 * docs/atmosphere.md describes the physics and the choices made.
 *
 * Summing thousands of lines per photon is far too slow, so atmosphere_prepare
 * tabulates alpha over each channel's band (centre +- 6 sigma) on a grid fine
 * enough for the line widths and atmosphere_alpha_per_m interpolates it (cubic,
 * < 1e-5 relative error by construction, checked at every grid midpoint). Outside
 * the prepared bands alpha is evaluated directly (exact, slower).
 */
#ifndef THZ_ATMOSPHERE_ATMOSPHERE_H
#define THZ_ATMOSPHERE_ATMOSPHERE_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "physics/channel.h"
#include "physics/spectrum.h"

/* clang-format off */
typedef enum atm_model {
    ATM_NONE = 0,
    ATM_CONSTANT,
    ATM_TABLE,
    ATM_ITU_P676,
    ATM_LINES
} atm_model;
/* clang-format on */

/* How the humidity of the air was given (scene keys of the same names). */
typedef enum atm_humidity_kind {
    ATM_HUMIDITY_NONE = 0,     /* dry air */
    ATM_HUMIDITY_RELATIVE,     /* relative_humidity, 0..1 over liquid water */
    ATM_HUMIDITY_DENSITY_G_M3, /* water_vapour_g_m3 */
    ATM_HUMIDITY_VMR           /* h2o_vmr, relative to total air */
} atm_humidity_kind;

/* The state of the air. pressure_hpa is the total barometric pressure (dry air plus
 * water vapour); h2o_pressure_hpa is the water-vapour partial pressure e derived
 * from the humidity (atm_air.c). */
typedef struct atm_air_state {
    double temperature_k;
    double pressure_hpa;
    double h2o_pressure_hpa;
} atm_air_state;

/* Files and switches of the `lines` model. NULL paths mean the shipped catalogues
 * in the data directory. A path ending in ".par" is read as a HITRAN 160-character
 * line list (molecule 1 = H2O, 7 = O2; other molecules are skipped). */
typedef struct atm_lines_options {
    const char *h2o_lines_file;
    const char *o2_lines_file;
    const char *o2_coupled_lines_file;
    const char *h2o_partition_sums_file;
    const char *o2_partition_sums_file;
    const char *continuum_file;
    bool continuum;       /* MT_CKD on (default): H2O lines then use the 750 GHz cut-off
                             shape MT_CKD is defined against; off: full far wings */
    const char *data_dir; /* NULL: the rule of core/data_dir.h */
} atm_lines_options;

/* Contributions to alpha at one frequency, in 1/m (what `thzmap atmosphere` lists). */
typedef struct atm_alpha_parts {
    double h2o_lines_per_m;     /* lines: H2O lines; itu-p676: the whole H2O sum */
    double h2o_continuum_per_m; /* lines: MT_CKD self + foreign; itu-p676: 0 */
    double o2_per_m;            /* O2 lines (incl. the non-resonant Debye term) */
    double dry_continuum_per_m; /* N2-dominated collision-induced absorption */
    double other_per_m;         /* none/constant/table: the whole alpha */
} atm_alpha_parts;

/* alpha in 1/m: the sum of the parts. */
double atmosphere_alpha_parts_sum(const atm_alpha_parts *parts);

/* 10 / ln 10: dB per neper (alpha in 1/m times this times 1000 is dB/km). */
#define ATM_NEPER_TO_DB 4.342944819032518

typedef struct atm_itu_data atm_itu_data;     /* atm_itu_p676.c */
typedef struct atm_lines_data atm_lines_data; /* atm_lines.c */

/* alpha tabulated on a uniform grid over one band: alpha(lo + i*step), i < n. */
typedef struct atm_band_table {
    double lo_hz, step_hz;
    size_t n;
    double *alpha_per_m;
} atm_band_table;

typedef struct thz_atmosphere {
    atm_model model;
    thz_spectrum attenuation_per_m; /* constant and table models */

    /* The air (itu-p676, lines; also the emitting atmosphere's temperature). */
    bool has_air;
    atm_air_state air;

    atm_itu_data *itu;     /* owned, itu-p676 */
    atm_lines_data *lines; /* owned, lines */

    /* Filled by atmosphere_prepare for itu-p676 and lines: one per channel, in the
     * order of the channels it was given (bands may overlap; the first that covers a
     * frequency is used). */
    size_t n_tables;
    atm_band_table *tables;

    /* Emitting atmosphere (physics.md extension): the air at air.temperature_k
     * emits B_nu(T_air) per unit optical depth; rays that leave the extent (an
     * axis-aligned box) see a black background at background_temperature_k. */
    bool emitting;
    double background_temperature_k;
    bool has_extent;
    double extent_min_m[3], extent_max_m[3];
} thz_atmosphere;

/* ---- Air state (atm_air.c) -------------------------------------------------- */

/* Saturation vapour pressure over liquid water in hPa at temperature_k and total
 * pressure_hpa: ITU-R P.453-14 eq. 9-10 (Buck 1981/1996 form with the enhancement
 * factor EF), stated for -40..+50 deg C and used outside that range as is. */
double atm_saturation_pressure_hpa(double temperature_k, double pressure_hpa);

/* The air states the models accept: temperature in [MIN, MAX] K, total pressure in
 * (0, MAX] hPa. */
#define ATM_AIR_MIN_TEMPERATURE_K 100.0
#define ATM_AIR_MAX_TEMPERATURE_K 400.0
#define ATM_AIR_MAX_PRESSURE_HPA 2000.0

/* Fills *air from temperature, total pressure and a humidity of the given kind
 * (value ignored for ATM_HUMIDITY_NONE). Refuses, with THZ_ERR_INPUT and a message
 * naming the quantity, T and pressure outside the bounds above, negative humidity,
 * relative humidity above 1 and a vapour pressure above the total. */
thz_status atm_air_state_init(atm_air_state *air, double temperature_k, double pressure_hpa,
                              atm_humidity_kind kind, double value, thz_error *err);

/* Water-vapour density in g/m^3 (e = rho T / 216.7, ITU-R P.453) and volume mixing
 * ratio e/P of the air. */
double atm_air_h2o_density_g_m3(const atm_air_state *air);
double atm_air_h2o_vmr(const atm_air_state *air);

/* ---- Models ------------------------------------------------------------------ */

/* Frequency range of a model in Hz: itu-p676 1 GHz..1 THz; lines 1 GHz..15 THz
 * (the MT_CKD table ends at 15.6 THz); the others 0..infinity. */
void atmosphere_model_range_hz(atm_model model, double *lo_hz, double *hi_hz);

/* Makes atm an itu-p676 atmosphere for this air; reads the P.676-13 line tables from
 * data_dir (NULL: default). atm must be empty (zeroed or finalised). */
thz_status atmosphere_init_itu_p676(thz_atmosphere *atm, const atm_air_state *air,
                                    const char *data_dir, thz_error *err);

/* Makes atm a lines atmosphere for this air, reading the catalogues of opt (NULL:
 * all defaults). Errors name the file and line. */
thz_status atmosphere_init_lines(thz_atmosphere *atm, const atm_air_state *air,
                                 const atm_lines_options *opt, thz_error *err);

/* Fills opt with the defaults (shipped catalogues, continuum on). */
void atmosphere_lines_options_default(atm_lines_options *opt);

/* Refuses (THZ_ERR_INPUT) a frequency interval the model does not cover, naming it
 * with `what` (e.g. "channel '0.35 THz'"). */
thz_status atmosphere_check_range(const thz_atmosphere *atm, double lo_hz, double hi_hz,
                                  const char *what, thz_error *err);

/* Prepares the model for a run over these channels: checks that every band
 * (centre +- 6 sigma) lies in the model's range and tabulates line-by-line alpha
 * over each band. The scene loader calls it once after loading; thread-safe use
 * of atmosphere_alpha_per_m needs it done. Calling it again replaces the tables. A
 * table an atmosphere of the same inputs (model data, air, band) computed earlier in the
 * process is copied, the same bits (atm_table_cache.h). */
thz_status atmosphere_prepare(thz_atmosphere *atm, const thz_channel *channels, size_t n_channels,
                              thz_error *err);

/* alpha(freq_hz) in 1/m; 0 for ATM_NONE. Interpolated inside prepared bands, direct
 * evaluation elsewhere. Thread-safe (read only), allocates nothing. */
double atmosphere_alpha_per_m(const thz_atmosphere *atm, double freq_hz);

/* alpha evaluated directly (no tables), and its parts; for tests and the CLI. */
double atmosphere_alpha_direct_per_m(const thz_atmosphere *atm, double freq_hz);
void atmosphere_alpha_parts(const thz_atmosphere *atm, double freq_hz, atm_alpha_parts *parts);

/* exp(-alpha(freq_hz) * distance_m): the transmittance of a free path; 1 where
 * alpha = 0, also for distance_m = INFINITY (a ray that leaves an open scene). */
double atmosphere_transmittance(const thz_atmosphere *atm, double freq_hz, double distance_m);

/* The model's name as in the scene file ("none", "constant", ...), and back
 * (false for an unknown name). */
const char *atmosphere_model_name(atm_model model);
bool atmosphere_model_from_name(const char *name, atm_model *model);

/* ---- Emitting atmosphere (atm_emission.c) -------------------------------------
 * For the photon phase and the renderer. All radiances in W m^-2 sr^-1 Hz^-1. */

/* Makes atm emitting at the air temperature temperature_k (for none/constant/table,
 * which have no air state, this sets it), with a black background at
 * background_temperature_k (>= 0) seen by rays that leave the extent. */
thz_status atmosphere_set_emitting(thz_atmosphere *atm, double temperature_k,
                                   double background_temperature_k, thz_error *err);

/* Bounds the atmosphere to the box [min_m, max_m] (each min < max). */
thz_status atmosphere_set_extent(thz_atmosphere *atm, const double min_m[3], const double max_m[3],
                                 thz_error *err);

/* Spectral power emitted per unit volume, 4 pi alpha B_nu(T_air), W m^-3 Hz^-1
 * (isotropic; 0 when not emitting): the density with which the photon phase fires air
 * photons. */
double atmosphere_volume_emission_w_per_m3_hz(const thz_atmosphere *atm, double freq_hz);

/* Distance from origin_m along the unit direction to where the ray leaves the
 * extent; INFINITY without an extent, 0 if the origin is outside it. */
double atmosphere_extent_exit_m(const thz_atmosphere *atm, const double origin_m[3],
                                const double direction[3]);

void atmosphere_fini(thz_atmosphere *atm);

#endif
