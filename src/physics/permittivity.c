/* Dispersive permittivity models (permittivity.h). */
#include "physics/permittivity.h"

#include <math.h>

const char *const permittivity_kind_names[] = {"debye", "double-debye", "lorentz",
                                               "drude", "itu-p2040",    NULL};

/* Vacuum permittivity in F/m (CODATA 2018). */
#define EPS0_F_PER_M 8.8541878128e-12

/* a / (1 - i x) = a (1 + i x) / (1 + x^2). */
static void relaxation(double a, double x, double *re, double *im)
{
    double d = 1.0 + x * x;
    *re += a / d;
    *im += a * x / d;
}

/* The row of an itu-p2040 model used at freq_hz (permittivity.h). */
static const permittivity_p2040_row *p2040_row(const permittivity_model *m, double freq_hz)
{
    const permittivity_p2040_row *best = &m->rows[0];
    double best_gap = INFINITY;
    for (size_t i = 0; i < m->n_rows; i++) {
        const permittivity_p2040_row *r = &m->rows[i];
        if (freq_hz >= r->lo_hz && freq_hz <= r->hi_hz)
            return r;
        double gap = freq_hz < r->lo_hz ? r->lo_hz - freq_hz : freq_hz - r->hi_hz;
        if (gap < best_gap) {
            best_gap = gap;
            best = r;
        }
    }
    return best;
}

void permittivity_eval(const permittivity_model *m, double freq_hz, double *re, double *im)
{
    double omega = 2.0 * M_PI * freq_hz;
    *re = m->eps_inf;
    *im = 0.0;
    switch (m->kind) {
    case PERMITTIVITY_DEBYE:
        relaxation(m->eps_s - m->eps_inf, omega * m->tau1_s, re, im);
        break;
    case PERMITTIVITY_DOUBLE_DEBYE:
        relaxation(m->eps_s - m->eps_2, omega * m->tau1_s, re, im);
        relaxation(m->eps_2 - m->eps_inf, omega * m->tau2_s, re, im);
        break;
    case PERMITTIVITY_LORENTZ:
        for (size_t j = 0; j < m->n_oscillators; j++) {
            const permittivity_oscillator *o = &m->oscillators[j];
            double f0 = o->freq_hz, a = f0 * f0 - freq_hz * freq_hz, b = freq_hz * o->width_hz;
            double s = o->strength * f0 * f0 / (a * a + b * b); /* S f0^2 / (a - i b) */
            *re += s * a;
            *im += s * b;
        }
        break;
    case PERMITTIVITY_DRUDE: {
        /* 1 - fp^2 / (f (f + i fc)) = 1 - fp^2 (f - i fc) / (f (f^2 + fc^2)) */
        double fp2 = m->plasma_hz * m->plasma_hz, fc = m->collision_hz;
        double d = freq_hz * (freq_hz * freq_hz + fc * fc);
        *re = 1.0 - fp2 * freq_hz / d;
        *im = fp2 * fc / d;
        break;
    }
    case PERMITTIVITY_P2040: {
        const permittivity_p2040_row *r = p2040_row(m, freq_hz);
        double ghz = freq_hz * 1e-9;
        double sigma = r->c * pow(ghz, r->d);
        *re = r->a * pow(ghz, r->b);
        *im = sigma / (omega * EPS0_F_PER_M);
        break;
    }
    }
}

void permittivity_to_index(double re, double im, double *n, double *k)
{
    double mod = hypot(re, im);
    im = fabs(im);
    if (re >= 0.0) {
        *n = sqrt(0.5 * (mod + re));
        *k = *n > 0.0 ? 0.5 * im / *n : 0.0;
    } else {
        *k = sqrt(0.5 * (mod - re));
        *n = 0.5 * im / *k;
    }
}

bool permittivity_covers(const permittivity_model *m, double lo_hz, double hi_hz)
{
    if (m->kind != PERMITTIVITY_P2040)
        return true;
    /* Grow [lo_hz, reach] through rows that touch it until nothing changes. */
    double reach = -INFINITY;
    for (size_t i = 0; i < m->n_rows; i++)
        if (m->rows[i].lo_hz <= lo_hz && m->rows[i].hi_hz >= lo_hz && m->rows[i].hi_hz > reach)
            reach = m->rows[i].hi_hz;
    for (bool grown = true; grown && reach < hi_hz;) {
        grown = false;
        for (size_t i = 0; i < m->n_rows; i++)
            if (m->rows[i].lo_hz <= reach && m->rows[i].hi_hz > reach) {
                reach = m->rows[i].hi_hz;
                grown = true;
            }
    }
    return reach >= hi_hz;
}

bool permittivity_validity(const permittivity_model *m, double *lo_hz, double *hi_hz)
{
    *lo_hz = 0.0;
    *hi_hz = INFINITY;
    if (m->kind != PERMITTIVITY_P2040 || m->n_rows == 0)
        return false;
    *lo_hz = INFINITY;
    *hi_hz = 0.0;
    for (size_t i = 0; i < m->n_rows; i++) {
        *lo_hz = fmin(*lo_hz, m->rows[i].lo_hz);
        *hi_hz = fmax(*hi_hz, m->rows[i].hi_hz);
    }
    return true;
}
