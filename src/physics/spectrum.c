/* Spectral properties: constants and linearly interpolated tables. */
#include "physics/spectrum.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/cdf.h"

size_t spectrum_interval(const double *t, size_t n, double x)
{
    return cdf_search(t + 1, n - 1, x); /* the first lo with x < t[lo + 1], else n - 2 */
}

double spectrum_eval(const thz_spectrum *s, double freq_hz)
{
    if (!s || s->n == 0)
        return 0.0;
    if (s->n == 1 || !s->freq_hz)
        return s->value[0];
    const double *f = s->freq_hz;
    size_t n = s->n;
    if (!(freq_hz > f[0]))
        return s->value[0];
    if (!(freq_hz < f[n - 1]))
        return s->value[n - 1];
    size_t lo;
    if (s->inv_step_per_hz > 0.0) {
        /* f[0] < freq_hz < f[n - 1] here; the guess is off by at most one on an even
         * grid, and the comparisons make lo exactly spectrum_interval's. */
        lo = (size_t)((freq_hz - f[0]) * s->inv_step_per_hz);
        if (lo > n - 2)
            lo = n - 2;
        while (lo > 0 && f[lo] > freq_hz)
            lo--;
        while (lo < n - 2 && !(freq_hz < f[lo + 1]))
            lo++;
    } else {
        lo = spectrum_interval(f, n, freq_hz);
    }
    size_t hi = lo + 1;
    double t = (freq_hz - f[lo]) / (f[hi] - f[lo]);
    return s->value[lo] + t * (s->value[hi] - s->value[lo]);
}

/* 1 / spacing when the n >= 2 frequencies increase by steps equal to within 1e-6 of
 * their mean (so that a guess from the mean step is off by at most one interval), else
 * 0. */
static double spectrum_even_grid(const double *f, size_t n)
{
    double step = (f[n - 1] - f[0]) / (double)(n - 1);
    if (!(step > 0.0) || !isfinite(step))
        return 0.0;
    for (size_t i = 0; i + 1 < n; i++)
        if (!(fabs((f[i + 1] - f[i]) - step) <= 1e-6 * step))
            return 0.0;
    return 1.0 / step;
}

bool spectrum_set_constant(thz_spectrum *s, double value)
{
    double *v = thz_malloc_array(1, sizeof *v);
    if (!v)
        return false;
    v[0] = value;
    spectrum_fini(s);
    s->n = 1;
    s->value = v;
    return true;
}

bool spectrum_set_table(thz_spectrum *s, size_t n, const double *freq_hz, const double *value)
{
    if (n == 0) {
        spectrum_fini(s);
        return true;
    }
    if (n == 1)
        return spectrum_set_constant(s, value[0]);
    double *f = thz_malloc_array(n, sizeof *f);
    double *v = thz_malloc_array(n, sizeof *v);
    if (!f || !v) {
        free(f);
        free(v);
        return false;
    }
    memcpy(f, freq_hz, n * sizeof *f);
    memcpy(v, value, n * sizeof *v);
    spectrum_fini(s);
    s->n = n;
    s->freq_hz = f;
    s->value = v;
    s->inv_step_per_hz = spectrum_even_grid(f, n);
    return true;
}

bool spectrum_copy(thz_spectrum *dst, const thz_spectrum *src)
{
    if (dst == src)
        return true;
    if (!src || src->n == 0) {
        spectrum_fini(dst);
        return true;
    }
    if (src->n == 1 || !src->freq_hz)
        return spectrum_set_constant(dst, src->value[0]);
    return spectrum_set_table(dst, src->n, src->freq_hz, src->value);
}

void spectrum_fini(thz_spectrum *s)
{
    if (!s)
        return;
    free(s->freq_hz);
    free(s->value);
    s->inv_step_per_hz = 0.0;
    s->n = 0;
    s->freq_hz = NULL;
    s->value = NULL;
}

void spectrum_range(const thz_spectrum *s, double *min_value, double *max_value)
{
    double lo = 0.0, hi = 0.0;
    if (s && s->n > 0) {
        size_t n = s->freq_hz ? s->n : 1;
        lo = hi = s->value[0];
        for (size_t i = 1; i < n; i++) {
            if (s->value[i] < lo)
                lo = s->value[i];
            if (s->value[i] > hi)
                hi = s->value[i];
        }
    }
    if (min_value)
        *min_value = lo;
    if (max_value)
        *max_value = hi;
}

bool spectrum_table_exceeded(const thz_spectrum *s, double lo_hz, double hi_hz)
{
    if (!s || s->n < 2 || !s->freq_hz)
        return false;
    return lo_hz < s->freq_hz[0] || hi_hz > s->freq_hz[s->n - 1];
}
