/* Gaussian channel responses, sampling and band-mean quadrature (physics.md
 * "Channels"). */
#include "physics/channel.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"

/* 2 sqrt(2 ln 2): FWHM of a Gaussian in units of sigma. */
#define CHANNEL_FWHM_PER_SIGMA 2.3548200450309493
#define CHANNEL_SQRT_2PI 2.5066282746310002
#define CHANNEL_TWO_PI 6.283185307179586
#define CHANNEL_HALF_SPAN_SIGMAS 6.0

/* Node i of n (odd) in units of sigma from the centre: -6 .. +6, symmetric. */
static double channel_node_x(size_t i, size_t n)
{
    double h = 2.0 * CHANNEL_HALF_SPAN_SIGMAS / (double)(n - 1);
    if (2 * i + 1 == n)
        return 0.0;
    if (2 * i + 1 < n)
        return -h * (double)((n - 1) / 2 - i);
    return h * (double)(i - (n - 1) / 2);
}

/* Composite Simpson weight (1, 4, 2, 4, ..., 4, 1) of node i of n (odd). */
static double channel_simpson_weight(size_t i, size_t n)
{
    if (i == 0 || i == n - 1)
        return 1.0;
    return (i % 2) ? 4.0 : 2.0;
}

double channel_sigma_hz(const thz_channel *ch)
{
    return ch->relative_width * ch->center_hz / CHANNEL_FWHM_PER_SIGMA;
}

double channel_bandwidth_hz(const thz_channel *ch)
{
    return channel_sigma_hz(ch) * CHANNEL_SQRT_2PI;
}

double channel_response(const thz_channel *ch, double freq_hz)
{
    double s = channel_sigma_hz(ch);
    double d = (freq_hz - ch->center_hz) / s;
    return exp(-0.5 * d * d);
}

double channel_sample_hz(const thz_channel *ch, double u1, double u2)
{
    /* Box-Muller; 1 - u1 lies in (0, 1] so the log is finite. */
    double r = sqrt(-2.0 * log(1.0 - u1));
    double z = r * cos(CHANNEL_TWO_PI * u2);
    double nu = ch->center_hz + channel_sigma_hz(ch) * z;
    if (!(nu > 0.0)) {
        /* Reflect the (practically unreachable) non-positive tail about the centre. */
        nu = ch->center_hz - channel_sigma_hz(ch) * z;
        if (!(nu > 0.0))
            nu = ch->center_hz;
    }
    return nu;
}

thz_status channel_quadrature_init(channel_quadrature *q, const thz_channel *ch, size_t n,
                                   thz_error *err)
{
    q->n = 0;
    q->freq_hz = NULL;
    q->weight = NULL;
    if (n < 3)
        n = 3;
    if (n % 2 == 0)
        n++; /* composite Simpson needs an odd node count */
    double *f = thz_malloc_array(n, sizeof *f);
    double *w = thz_malloc_array(n, sizeof *w);
    if (!f || !w) {
        free(f);
        free(w);
        return thz_error_set(err, THZ_ERR_NOMEM,
                             "channel quadrature: cannot allocate %zu nodes", n);
    }
    double sigma = channel_sigma_hz(ch);
    double sum = 0.0;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        double x = channel_node_x(i, n);
        double nu = ch->center_hz + sigma * x;
        if (!(nu > 0.0))
            continue; /* g is defined for nu > 0 only (wide channels reach below 0) */
        f[m] = nu;
        w[m] = channel_simpson_weight(i, n) * exp(-0.5 * x * x);
        sum += w[m];
        m++;
    }
    for (size_t i = 0; i < m; i++)
        w[i] /= sum;
    q->n = m;
    q->freq_hz = f;
    q->weight = w;
    return THZ_OK;
}

void channel_quadrature_fini(channel_quadrature *q)
{
    if (!q)
        return;
    free(q->freq_hz);
    free(q->weight);
    q->n = 0;
    q->freq_hz = NULL;
    q->weight = NULL;
}

double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx)
{
    /* Allocation-free: nodes and weights are computed on the fly with the same formula
     * as channel_quadrature_init, normalised at the end. */
    const size_t n = CHANNEL_QUADRATURE_NODES;
    double sigma = channel_sigma_hz(ch);
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++) {
        double x = channel_node_x(i, n);
        double nu = ch->center_hz + sigma * x;
        if (!(nu > 0.0))
            continue;
        double w = channel_simpson_weight(i, n) * exp(-0.5 * x * x);
        num += w * f(nu, ctx);
        den += w;
    }
    return num / den;
}
