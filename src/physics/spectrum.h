/* A spectral property of a material: a constant, or a table of (frequency, value)
 * with strictly increasing frequencies, linear interpolation, and the end value
 * beyond the ends (scene-format.md "materials"). */
#ifndef THZ_PHYSICS_SPECTRUM_H
#define THZ_PHYSICS_SPECTRUM_H

#include <stdbool.h>
#include <stddef.h>

typedef struct thz_spectrum {
    size_t n;        /* 0: not given; 1: constant value[0]; >1: table */
    double *freq_hz; /* n entries for a table, NULL for a constant */
    double *value;   /* n entries */
    /* A table on an even grid (spectrum_set_table checks): 1 / spacing, so that
     * spectrum_eval guesses the interval and corrects it by comparisons instead of a
     * bisection (the photon phase evaluates spectra per photon and per hit); 0: bisect. */
    double inv_step_per_hz;
} thz_spectrum;

/* The interval of an ascending table t[0 .. n-1] (n >= 2) that holds x: the last
 * lo < n - 1 with t[lo] <= x, by bisection (0 when x < t[1]). The interval lookups in tables of
 * spectra, complex indices, channel responses and quadrature nodes goes through it. */
size_t spectrum_interval(const double *t, size_t n, double x);

/* Value at freq_hz. An absent spectrum (n == 0) evaluates to 0. */
double spectrum_eval(const thz_spectrum *s, double freq_hz);

/* Makes s a constant. Returns false on allocation failure. */
bool spectrum_set_constant(thz_spectrum *s, double value);

/* Makes s a table, copying the n pairs. Returns false on allocation failure. The
 * caller has checked that frequencies strictly increase. */
bool spectrum_set_table(thz_spectrum *s, size_t n, const double *freq_hz, const double *value);

/* Deep copy; false on allocation failure. */
bool spectrum_copy(thz_spectrum *dst, const thz_spectrum *src);

/* Frees the arrays and leaves s absent. */
void spectrum_fini(thz_spectrum *s);

/* Smallest and largest value over all frequencies. Absent: both 0. */
void spectrum_range(const thz_spectrum *s, double *min_value, double *max_value);

/* True if s is a table and [lo_hz, hi_hz] reaches beyond its first or last frequency. */
bool spectrum_table_exceeded(const thz_spectrum *s, double lo_hz, double hi_hz);

#endif
