/* Dispersive permittivity models (scene-format.md "Materials: optics from a complex
 * index"; formulas and sign convention in physics.md "Complex indices").
 *
 * Convention: fields vary as e^{-i omega t}, so a lossy medium has eps = eps' + i eps''
 * with eps'' > 0, and the index n + ik = sqrt(eps) is the root with k >= 0.
 *   debye:        eps = eps_inf + (eps_s - eps_inf) / (1 - i omega tau)
 *   double-debye: eps = eps_inf + (eps_s - eps_2) / (1 - i omega tau1)
 *                               + (eps_2 - eps_inf) / (1 - i omega tau2)
 *   lorentz:      eps = eps_inf + sum_j S_j f_j^2 / (f_j^2 - f^2 - i f g_j)
 *                 (f_j the resonance, S_j its strength, g_j its FWHM width, in Hz)
 *   drude:        eps = 1 - f_p^2 / (f^2 + i f f_c)   (f_p plasma, f_c collision, in Hz)
 *   itu-p2040:    eps' = a f_GHz^b, sigma = c f_GHz^d S/m, eps'' = sigma / (2 pi f eps0),
 *                 one row (a, b, c, d, frequency range) of ITU-R P.2040 Table 3 per range.
 */
#ifndef THZ_PHYSICS_PERMITTIVITY_H
#define THZ_PHYSICS_PERMITTIVITY_H

#include <stdbool.h>
#include <stddef.h>

typedef enum permittivity_kind {
    PERMITTIVITY_DEBYE = 0,
    PERMITTIVITY_DOUBLE_DEBYE,
    PERMITTIVITY_LORENTZ,
    PERMITTIVITY_DRUDE,
    PERMITTIVITY_P2040
} permittivity_kind;

/* The names of the kinds as the scene's "model" key spells them, NULL-terminated, in
 * the order of permittivity_kind. */
extern const char *const permittivity_kind_names[];

#define PERMITTIVITY_MAX_OSCILLATORS 32
#define PERMITTIVITY_MAX_RANGES 8

typedef struct permittivity_oscillator {
    double freq_hz;  /* f_j */
    double strength; /* S_j (dimensionless: the oscillator's contribution to eps(0)) */
    double width_hz; /* g_j */
} permittivity_oscillator;

/* One ITU-R P.2040 row: eps' = a f_GHz^b, sigma = c f_GHz^d over [lo_hz, hi_hz]. */
typedef struct permittivity_p2040_row {
    double lo_hz, hi_hz;
    double a, b, c, d;
} permittivity_p2040_row;

typedef struct permittivity_model {
    permittivity_kind kind;
    double eps_inf, eps_2, eps_s; /* debye (eps_2 unused), double-debye, lorentz (eps_inf) */
    double tau1_s, tau2_s;        /* debye: tau1_s only */
    size_t n_oscillators;
    permittivity_oscillator oscillators[PERMITTIVITY_MAX_OSCILLATORS];
    double plasma_hz, collision_hz; /* drude */
    char material[64];              /* itu-p2040: the material's name */
    size_t n_rows;                  /* itu-p2040: rows in file order */
    permittivity_p2040_row rows[PERMITTIVITY_MAX_RANGES];
} permittivity_model;

/* eps' and eps'' of m at freq_hz > 0. For itu-p2040 the first row (in file order)
 * whose range holds freq_hz is used, else the row with the nearest range end. */
void permittivity_eval(const permittivity_model *m, double freq_hz, double *re, double *im);

/* n + ik = sqrt(re + i im), the root with k >= 0 (n >= 0 too), computed without
 * cancellation for strongly absorbing media. */
void permittivity_to_index(double re, double im, double *n, double *k);

/* True if [lo_hz, hi_hz] lies within the model's stated validity (for itu-p2040: within
 * the union of its rows' ranges, without a gap); every other model has none (true). */
bool permittivity_covers(const permittivity_model *m, double lo_hz, double hi_hz);

/* The model's overall stated range (itu-p2040: lowest and highest row ends); false
 * (and 0, infinity) for models without one. */
bool permittivity_validity(const permittivity_model *m, double *lo_hz, double *hi_hz);

#endif
