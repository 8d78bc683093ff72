/* Internals of the atmosphere module shared between its files: the two line-by-line
 * models' entry points (their CSV tables are read by core/csv.h).
 * Nothing outside src/atmosphere/ includes this. */
#ifndef THZ_ATMOSPHERE_ATM_INTERNAL_H
#define THZ_ATMOSPHERE_ATM_INTERNAL_H

#include <stddef.h>

#include "atmosphere/atm_table_cache.h"
#include "atmosphere/atmosphere.h"
#include "core/csv.h"
#include "core/threads.h"

/* 1 hPa = 1 mbar; 1 cm^-1 = 29.9792458 GHz; 1 atm = 1013.25 hPa. */
#define ATM_GHZ_PER_CM1 29.9792458
#define ATM_HPA_PER_ATM 1013.25
/* The second radiation constant hc/k, cm K (CODATA 2018). */
#define ATM_HC_OVER_K_CM_K 1.438776877

/* The threads a band's tabulation shares a loop over `points` table points among (the
 * lines' pieces: a piece per 8 x 32 points): all from ATM_PARALLEL_MIN_POINTS, else one.
 * A channel of 1 % at 1 atm tabulates 40 to 700 points, 1 to 5 ms of work: on two threads
 * the idle one spun in libgomp between those small loops, and checking a 48-frame
 * sequence with `lines` took 15-55 ms of CPU a frame instead of 5-14 (its wall time
 * 1.5-5 times one thread's on a loaded machine). */
#define ATM_PARALLEL_MIN_POINTS 4096
static inline int atm_table_threads(size_t points)
{
    return points >= ATM_PARALLEL_MIN_POINTS ? thz_threads_all() : 1;
}

/* itu-p676 (atm_itu_p676.c). */
thz_status atm_itu_create(atm_itu_data **out, const char *data_dir, thz_error *err);
void atm_itu_destroy(atm_itu_data *itu);
void atm_itu_parts(const atm_itu_data *itu, const atm_air_state *air, double freq_hz,
                   atm_alpha_parts *parts);
/* Appends to key the tables' inputs the P.676 line tables are (all their values). */
void atm_itu_table_key(const atm_itu_data *itu, atm_table_key *key);

/* lines (atm_lines.c). */
thz_status atm_lines_create(atm_lines_data **out, const atm_air_state *air,
                            const atm_lines_options *opt, thz_error *err);
void atm_lines_destroy(atm_lines_data *lines);
void atm_lines_parts(const atm_lines_data *lines, double freq_hz, atm_alpha_parts *parts);
/* Appends to key what the model's lines and continua are made from: the files' read (its
 * read_id, atm_inputs.h), the continuum switch and the air. */
void atm_lines_table_key(const atm_lines_data *lines, atm_table_key *key);
/* Grid step in Hz for tabulating alpha over [lo_hz, hi_hz] to ~6e-6 relative with
 * cubic interpolation, from the widths of the lines near the band and their share
 * of alpha; INFINITY if no line shapes the band. */
double atm_lines_grid_step_hz(const atm_lines_data *lines, double lo_hz, double hi_hz);

/* alpha of the `lines` model over one band [lo_hz, hi_hz] and an eighth of its width
 * beyond each end (a table's grid and midpoints), as atm_lines_parts sums it but faster:
 * the lines near each piece of the band summed at each frequency, the sums of the others,
 * smooth there, as Chebyshev series fitted once (atm_lines_band.c). points: about how many
 * frequencies will be asked (the table's first grid), which sets the number of pieces. */
typedef struct atm_lines_band atm_lines_band;
thz_status atm_lines_band_create(const atm_lines_data *lines, double lo_hz, double hi_hz,
                                 size_t points, atm_lines_band **out, thz_error *err);
void atm_lines_band_destroy(atm_lines_band *band);
/* alpha in 1/m at freq_hz (outside the band's interval: summed directly). */
double atm_lines_band_alpha_per_m(const atm_lines_band *band, double freq_hz);
/* The band's pieces, the lines summed directly over all pieces (a line near two pieces
 * counts twice), and the lines in all. */
void atm_lines_band_counts(const atm_lines_band *band, size_t *pieces, size_t *near, size_t *all);

/* The Voigt profile (area 1, in 1/Hz units of its arguments) at offset x from the
 * centre, for Lorentz HWHM gamma_l and Doppler HWHM gamma_d; Weideman's (1994)
 * 32-term rational series for the Faddeeva function (atm_voigt.c). */
double atm_voigt(double x, double gamma_l, double gamma_d);

#endif
