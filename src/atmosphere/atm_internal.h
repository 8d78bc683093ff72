/* Internals of the atmosphere module shared between its files: the CSV table
 * reader, the data directory, and the two line-by-line models' entry points.
 * Nothing outside src/atmosphere/ includes this. */
#ifndef THZ_ATMOSPHERE_ATM_INTERNAL_H
#define THZ_ATMOSPHERE_ATM_INTERNAL_H

#include <stddef.h>

#include "atmosphere/atmosphere.h"

/* 1 hPa = 1 mbar; 1 cm^-1 = 29.9792458 GHz; 1 atm = 1013.25 hPa. */
#define ATM_GHZ_PER_CM1 29.9792458
#define ATM_HPA_PER_ATM 1013.25

/* A numeric CSV table as in data/atmosphere/: '#' comment lines, one header line,
 * then rows of numbers separated by commas (empty field: NaN). */
typedef struct atm_csv {
    char *path;
    size_t n_cols, n_rows;
    char **names;
    double *values;  /* n_rows * n_cols, row-major */
    size_t *line_of; /* file line number of each row, for messages */
} atm_csv;

thz_status atm_csv_read(atm_csv *csv, const char *path, thz_error *err);
void atm_csv_fini(atm_csv *csv);
/* Index of the column called name; THZ_ERR_INPUT naming the file if absent. */
thz_status atm_csv_column(const atm_csv *csv, const char *name, size_t *col, thz_error *err);
static inline double atm_csv_at(const atm_csv *csv, size_t row, size_t col)
{
    return csv->values[row * csv->n_cols + col];
}

/* itu-p676 (atm_itu_p676.c). */
thz_status atm_itu_create(atm_itu_data **out, const char *data_dir, thz_error *err);
void atm_itu_destroy(atm_itu_data *itu);
void atm_itu_parts(const atm_itu_data *itu, const atm_air_state *air, double freq_hz,
                   atm_alpha_parts *parts);

/* lines (atm_lines.c). */
thz_status atm_lines_create(atm_lines_data **out, const atm_air_state *air,
                            const atm_lines_options *opt, thz_error *err);
void atm_lines_destroy(atm_lines_data *lines);
void atm_lines_parts(const atm_lines_data *lines, double freq_hz, atm_alpha_parts *parts);
/* Grid step in Hz for tabulating alpha over [lo_hz, hi_hz] to ~6e-6 relative with
 * cubic interpolation, from the widths of the lines near the band and their share
 * of alpha; INFINITY if no line shapes the band. */
double atm_lines_grid_step_hz(const atm_lines_data *lines, double lo_hz, double hi_hz);

/* The Voigt profile (area 1, in 1/Hz units of its arguments) at offset x from the
 * centre, for Lorentz HWHM gamma_l and Doppler HWHM gamma_d; Weideman's (1994)
 * 32-term rational series for the Faddeeva function (atm_voigt.c). */
double atm_voigt(double x, double gamma_l, double gamma_d);

#endif
