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

double channel_noise_bandwidth_hz(const thz_channel *ch)
{
    return 2.0 * sqrt(M_PI) * channel_sigma_hz(ch);
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
        return thz_error_set(err, THZ_ERR_NOMEM, "channel quadrature: cannot allocate %zu nodes",
                             n);
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

/* Adaptive refinement of the band mean: a Simpson panel whose halves disagree with it
 * by more than its share of the tolerance is split, so that lines narrower than the
 * base grid's node spacing (kinks of tabulated spectra) are integrated to ~1e-10 of
 * the band mean instead of the ~3 % a fixed 401-node rule gives for a line of width
 * sigma/10. Numerator and denominator use the same nodes, so constants stay exact. */
#define CHANNEL_ADAPT_REL_TOL 1e-10
#define CHANNEL_ADAPT_MAX_DEPTH 40

typedef struct channel_adapt {
    const thz_channel *ch;
    double sigma_hz;
    double (*f)(double freq_hz, void *ctx);
    void *ctx;
    double num, den; /* accumulated int g f dx and int g dx (x in sigma units) */
} channel_adapt;

/* g(x) f(nu(x)) and g(x) at x sigma from the centre; 0 for nu <= 0. */
static void channel_adapt_eval(const channel_adapt *a, double x, double *gf, double *g)
{
    double nu = a->ch->center_hz + a->sigma_hz * x;
    if (!(nu > 0.0)) {
        *gf = 0.0;
        *g = 0.0;
        return;
    }
    *g = exp(-0.5 * x * x);
    *gf = *g * a->f(nu, a->ctx);
}

/* Panel [x0, x2] with values at its ends and midpoint; s_num its Simpson estimate of
 * int g f. */
static void channel_adapt_panel(channel_adapt *a, double x0, double x2, const double fv[3],
                                const double gv[3], double s_num, double tol, int depth)
{
    double x1 = 0.5 * (x0 + x2);
    double xl = 0.5 * (x0 + x1), xr = 0.5 * (x1 + x2);
    double fl, gl, fr, gr;
    channel_adapt_eval(a, xl, &fl, &gl);
    channel_adapt_eval(a, xr, &fr, &gr);
    double h6 = (x1 - x0) / 6.0;
    double ln = h6 * (fv[0] + 4.0 * fl + fv[1]), rn = h6 * (fv[1] + 4.0 * fr + fv[2]);
    double ld = h6 * (gv[0] + 4.0 * gl + gv[1]), rd = h6 * (gv[1] + 4.0 * gr + gv[2]);
    if (depth >= CHANNEL_ADAPT_MAX_DEPTH || fabs(ln + rn - s_num) <= 15.0 * tol) {
        a->num += ln + rn;
        a->den += ld + rd;
        return;
    }
    const double lf[3] = {fv[0], fl, fv[1]}, lg[3] = {gv[0], gl, gv[1]};
    const double rf[3] = {fv[1], fr, fv[2]}, rg[3] = {gv[1], gr, gv[2]};
    channel_adapt_panel(a, x0, x1, lf, lg, ln, 0.5 * tol, depth + 1);
    channel_adapt_panel(a, x1, x2, rf, rg, rn, 0.5 * tol, depth + 1);
}

double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx)
{
    /* The base grid of CHANNEL_QUADRATURE_NODES nodes (as channel_quadrature_init),
     * kept on the stack: no allocation. */
    enum { n = CHANNEL_QUADRATURE_NODES };
    double fv[n], gv[n];
    channel_adapt a = {ch, channel_sigma_hz(ch), f, ctx, 0.0, 0.0};
    double scale = 0.0;
    for (size_t i = 0; i < n; i++) {
        channel_adapt_eval(&a, channel_node_x(i, n), &fv[i], &gv[i]);
        scale += channel_simpson_weight(i, n) * fabs(fv[i]);
    }
    double h = channel_node_x(1, n) - channel_node_x(0, n);
    scale *= h / 3.0;
    const size_t panels = (n - 1) / 2;
    double tol = CHANNEL_ADAPT_REL_TOL * scale / (double)panels;
    for (size_t j = 0; j < panels; j++) {
        size_t i = 2 * j;
        double x0 = channel_node_x(i, n), x2 = channel_node_x(i + 2, n);
        double s_num = (x2 - x0) / 6.0 * (fv[i] + 4.0 * fv[i + 1] + fv[i + 2]);
        channel_adapt_panel(&a, x0, x2, &fv[i], &gv[i], s_num, tol, 0);
    }
    return a.den > 0.0 ? a.num / a.den : 0.0;
}
