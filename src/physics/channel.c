/* Channel responses (Gaussian or a measured table), sampling and band-mean quadrature
 * (physics.md "Channels"). Every function handles both: the Gaussian's arithmetic is
 * that of before tables existed (Box-Muller's log and cos since computed without libm,
 * to ~1e-16); a table's is exact for its piecewise-linear g. */
#include "physics/channel.h"

#include <float.h>
#include <stdbool.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/sampling.h"
#include "physics/spectrum.h"

/* ---- measured response tables ---------------------------------------------------- */

/* The piece i of the table, [f_i, f_i+1]: its width and end weights. */
static void channel_piece(const thz_channel *ch, size_t i, double *h, double *a, double *b)
{
    *h = ch->response_hz[i + 1] - ch->response_hz[i];
    *a = ch->response_weight[i];
    *b = ch->response_weight[i + 1];
}

/* Index of the piece holding freq_hz (inside the table): the last i < n - 1 with
 * f_i <= freq_hz. */
static size_t channel_piece_at(const thz_channel *ch, double freq_hz)
{
    return spectrum_interval(ch->response_hz, ch->n_response, freq_hz);
}

thz_status channel_set_response(thz_channel *ch, size_t n, const double *freq_hz,
                                const double *weight, double centre_hz, thz_error *err)
{
    double peak = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (!(weight[i] >= 0.0) || !isfinite(weight[i]) || !(freq_hz[i] > 0.0) ||
            (i > 0 && !(freq_hz[i] > freq_hz[i - 1])))
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "channel '%s': bad response table at point %zu", ch->name, i + 1);
        peak = weight[i] > peak ? weight[i] : peak;
    }
    if (n < 2 || !(peak > 0.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "channel '%s': a response needs 2 points and a weight > 0", ch->name);
    double *f = thz_malloc_array(n, sizeof *f);
    double *w = thz_malloc_array(n, sizeof *w);
    double *area = thz_malloc_array(n, sizeof *area);
    if (!f || !w || !area) {
        free(f);
        free(w);
        free(area);
        return thz_error_set(err, THZ_ERR_NOMEM, "channel '%s': out of memory", ch->name);
    }
    double moment = 0.0; /* int nu g dnu, Simpson: exact for the quadratic nu g */
    double g2 = 0.0;     /* int g^2 dnu (the noise bandwidth's), exact on each piece */
    area[0] = 0.0;
    for (size_t i = 0; i < n; i++) {
        f[i] = freq_hz[i];
        w[i] = weight[i];
        if (i == 0)
            continue;
        double h = f[i] - f[i - 1];
        area[i] = area[i - 1] + 0.5 * h * (w[i - 1] + w[i]);
        moment += h / 6.0 * (w[i - 1] * (2.0 * f[i - 1] + f[i]) + w[i] * (f[i - 1] + 2.0 * f[i]));
        g2 += h * (w[i - 1] * w[i - 1] + w[i - 1] * w[i] + w[i] * w[i]) / 3.0;
    }
    /* B_c = int g dnu is the table's own (physics.md: g_c is the table), so its scale
     * counts: weights whose integrals leave the doubles' normal range (1e308, 1e-320) would
     * give an infinite or NaN centre and bandwidths */
    double b_c = area[n - 1];
    if (!isnormal(b_c) || !isnormal(moment) || !isnormal(g2)) {
        free(f);
        free(w);
        free(area);
        bool named = ch->name[0] != '\0'; /* a scene's channel is named after this */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s%s%sthe response's integrals (int g dnu = %g Hz, int g^2 dnu = %g "
                             "Hz) leave the range of double precision; give weights of order 1",
                             named ? "channel '" : "", named ? ch->name : "", named ? "': " : "",
                             b_c, g2);
    }
    channel_fini(ch);
    ch->n_response = n;
    ch->response_hz = f;
    ch->response_weight = w;
    ch->response_area_hz = area;
    ch->relative_width = 0.0;
    ch->center_hz = centre_hz > 0.0 ? centre_hz : moment / area[n - 1];
    return THZ_OK;
}

void channel_fini(thz_channel *ch)
{
    if (!ch)
        return;
    free(ch->response_hz);
    free(ch->response_weight);
    free(ch->response_area_hz);
    ch->n_response = 0;
    ch->response_hz = ch->response_weight = ch->response_area_hz = NULL;
}

void channel_support_hz(const thz_channel *ch, double sigmas, double *lo_hz, double *hi_hz)
{
    if (!channel_has_response(ch)) {
        double sigma = channel_sigma_hz(ch);
        *lo_hz = ch->center_hz - sigmas * sigma;
        *hi_hz = ch->center_hz + sigmas * sigma;
        return;
    }
    size_t n = ch->n_response, first = 0, last = n - 1;
    while (first < n - 1 && !(ch->response_weight[first] > 0.0))
        first++;
    while (last > 0 && !(ch->response_weight[last] > 0.0))
        last--;
    *lo_hz = ch->response_hz[first > 0 ? first - 1 : 0];
    *hi_hz = ch->response_hz[last < n - 1 ? last + 1 : n - 1];
}

/* The width of a table's support (Hz). */
static double channel_support_width_hz(const thz_channel *ch)
{
    double lo, hi;
    channel_support_hz(ch, 0.0, &lo, &hi);
    return hi - lo;
}

/* Composite Simpson panels given to table piece i when about `panels` are spread over
 * the pieces where g > 0 (support width `width_hz`) in proportion to their widths; 0 for
 * a piece where g = 0. */
static size_t channel_piece_panels(const thz_channel *ch, size_t i, size_t panels, double width_hz)
{
    double h, a, b;
    channel_piece(ch, i, &h, &a, &b);
    if (!(a + b > 0.0))
        return 0;
    double p = ceil((double)panels * h / width_hz);
    return p < 1.0 ? 1 : (size_t)p;
}

#define CHANNEL_SQRT_2PI 2.5066282746310002
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
    if (channel_has_response(ch))
        return channel_bandwidth_hz(ch) / CHANNEL_SQRT_2PI;
    return ch->relative_width * ch->center_hz / CHANNEL_FWHM_PER_SIGMA;
}

double channel_fwhm_hz(const thz_channel *ch)
{
    if (!channel_has_response(ch))
        return ch->relative_width * ch->center_hz;
    const double *f = ch->response_hz, *w = ch->response_weight;
    size_t n = ch->n_response, first = 0, last = n - 1;
    double half = 0.0;
    for (size_t i = 0; i < n; i++)
        half = w[i] > half ? w[i] : half;
    half *= 0.5;
    while (w[first] < half)
        first++; /* the peak is >= half: both loops stop */
    while (w[last] < half)
        last--;
    /* g rises through half its peak on the piece before `first` (or jumps there at the
     * table's start), falls through it after `last` */
    double lo = first == 0 ? f[0]
                           : f[first - 1] + (f[first] - f[first - 1]) * (half - w[first - 1]) /
                                                (w[first] - w[first - 1]);
    double hi = last == n - 1 ? f[n - 1]
                              : f[last] + (f[last + 1] - f[last]) * (w[last] - half) /
                                              (w[last] - w[last + 1]);
    return hi - lo;
}

double channel_bandwidth_hz(const thz_channel *ch)
{
    if (channel_has_response(ch))
        return ch->response_area_hz[ch->n_response - 1];
    return channel_sigma_hz(ch) * CHANNEL_SQRT_2PI;
}

double channel_noise_bandwidth_hz(const thz_channel *ch)
{
    if (channel_has_response(ch)) {
        double g2 = 0.0; /* int g^2 dnu, exact on each linear piece */
        for (size_t i = 0; i + 1 < ch->n_response; i++) {
            double h, a, b;
            channel_piece(ch, i, &h, &a, &b);
            g2 += h * (a * a + a * b + b * b) / 3.0;
        }
        double bc = channel_bandwidth_hz(ch);
        return bc * bc / g2;
    }
    return 2.0 * sqrt(M_PI) * channel_sigma_hz(ch);
}

double channel_response(const thz_channel *ch, double freq_hz)
{
    if (channel_has_response(ch)) {
        const double *f = ch->response_hz;
        if (!(freq_hz >= f[0]) || freq_hz > f[ch->n_response - 1])
            return 0.0;
        size_t i = channel_piece_at(ch, freq_hz);
        double h, a, b;
        channel_piece(ch, i, &h, &a, &b);
        return a + (b - a) * ((freq_hz - f[i]) / h);
    }
    double s = channel_sigma_hz(ch);
    double d = (freq_hz - ch->center_hz) / s;
    return exp(-0.5 * d * d);
}

/* A table's frequency: the piece whose cumulative area first exceeds u1 B_c, then the
 * root t in [0, 1] of a t + (b - a) t^2 / 2 = u2 (a + b) / 2 (the piece's linear
 * density inverted), in the form that stays accurate when b - a is small. */
static double channel_sample_table_hz(const thz_channel *ch, double u1, double u2)
{
    const double *area = ch->response_area_hz;
    size_t n = ch->n_response;
    double target = u1 * area[n - 1];
    size_t lo = spectrum_interval(area, n, target); /* the first i with area[i + 1] > target */
    while (lo > 0 && !(area[lo + 1] > area[lo]))
        lo--; /* u1 rounded onto the end of a zero piece: the last piece with area */
    double h, a, b;
    channel_piece(ch, lo, &h, &a, &b);
    double c = u2 * 0.5 * (a + b);
    double root = a * a + 2.0 * (b - a) * c;
    double t = c > 0.0 ? 2.0 * c / (a + sqrt(root > 0.0 ? root : 0.0)) : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return ch->response_hz[lo] + t * h;
}

/* ln x for normal x > 0 without libm (relative error ~2e-16): x = 2^e m with
 * m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s) = 2 (s + s^3/3 + ...) with
 * s = (m - 1) / (m + 1), |s| <= 0.172, so 11 terms leave s^22 / 23 < 1e-17; e ln 2 in
 * two parts (fdlibm's ln2_hi has trailing zeros, so e ln2_hi is exact). */
static inline double channel_log_normal(double x);

static double channel_log(double x)
{
    if (!(x >= DBL_MIN && x <= DBL_MAX))
        return log(x);
    return channel_log_normal(x);
}

/* channel_log for a normal, finite x > 0; inline and branch-free, for loops the compiler
 * vectorises. */
static inline double channel_log_normal(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    int e = (int)(bits >> 52) - 1023;
    bits = (bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull;
    double m;
    memcpy(&m, &bits, sizeof m);
    bool high = m > M_SQRT2;
    m = high ? m * 0.5 : m;
    e += high;
    double s = (m - 1.0) / (m + 1.0), s2 = s * s;
    double p = 1.0 / 21.0; /* Horner in s^2, written out: constants, no divisions */
    p = p * s2 + 1.0 / 19.0;
    p = p * s2 + 1.0 / 17.0;
    p = p * s2 + 1.0 / 15.0;
    p = p * s2 + 1.0 / 13.0;
    p = p * s2 + 1.0 / 11.0;
    p = p * s2 + 1.0 / 9.0;
    p = p * s2 + 1.0 / 7.0;
    p = p * s2 + 1.0 / 5.0;
    p = p * s2 + 1.0 / 3.0;
    p = p * s2 + 1.0;
    const double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;
    return (double)e * ln2_hi + ((double)e * ln2_lo + 2.0 * s * p);
}

double channel_sample_hz(const thz_channel *ch, double u1, double u2)
{
    if (channel_has_response(ch))
        return channel_sample_table_hz(ch, u1, u2);
    /* Box-Muller; 1 - u1 lies in (0, 1] so the log is finite. Its log and cos without
     * libm (channel_log, sampling_cos_sin_turn): the photon phase draws one per photon. */
    double r = sqrt(-2.0 * channel_log(1.0 - u1));
    double cos_phi, sin_phi;
    sampling_cos_sin_turn(u2, &cos_phi, &sin_phi);
    double z = r * cos_phi;
    double nu = ch->center_hz + channel_sigma_hz(ch) * z;
    if (!(nu > 0.0)) {
        /* Reflect the (practically unreachable) non-positive tail about the centre. */
        nu = ch->center_hz - channel_sigma_hz(ch) * z;
        if (!(nu > 0.0))
            nu = ch->center_hz;
    }
    return nu;
}

void channel_sample_many_hz(const thz_channel *ch, const double *u1, const double *u2, size_t n,
                            double *nu)
{
    if (channel_has_response(ch)) {
        for (size_t j = 0; j < n; j++)
            nu[j] = channel_sample_table_hz(ch, u1[j], u2[j]);
        return;
    }
    /* channel_sample_hz's arithmetic, its branches as selects (1 - u1 >= 2^-32 is normal) */
    const double center = ch->center_hz, sigma = channel_sigma_hz(ch);
    for (size_t j = 0; j < n; j++) {
        double r = sqrt(-2.0 * channel_log_normal(1.0 - u1[j]));
        double cos_phi, sin_phi;
        sampling_cos_sin_turn_inline(u2[j], &cos_phi, &sin_phi);
        double z = r * cos_phi;
        double up = center + sigma * z, down = center - sigma * z;
        nu[j] = up > 0.0 ? up : (down > 0.0 ? down : center);
    }
}

/* A table's nodes: composite Simpson on each piece where g > 0 (panels as
 * channel_piece_panels for about n nodes), nodes shared by adjacent pieces merged. */
static thz_status channel_quadrature_table(channel_quadrature *q, const thz_channel *ch, size_t n,
                                           thz_error *err)
{
    size_t panels = n / 2, count = 0;
    double width = channel_support_width_hz(ch);
    for (size_t i = 0; i + 1 < ch->n_response; i++) {
        size_t p = channel_piece_panels(ch, i, panels, width);
        count += p ? 2 * p + 1 : 0;
    }
    double *f = thz_malloc_array(count, sizeof *f);
    double *w = thz_malloc_array(count, sizeof *w);
    if (!f || !w) {
        free(f);
        free(w);
        return thz_error_set(err, THZ_ERR_NOMEM, "channel quadrature: cannot allocate %zu nodes",
                             count);
    }
    size_t m = 0;
    double sum = 0.0;
    for (size_t i = 0; i + 1 < ch->n_response; i++) {
        size_t p = channel_piece_panels(ch, i, panels, width);
        if (!p)
            continue;
        double h, a, b;
        channel_piece(ch, i, &h, &a, &b);
        size_t k_n = 2 * p + 1;
        double d = h / (double)(k_n - 1);
        for (size_t k = 0; k < k_n; k++) {
            double t = (double)k / (double)(k_n - 1);
            double nu = k + 1 == k_n ? ch->response_hz[i + 1] : ch->response_hz[i] + t * h;
            double wk = d / 3.0 * channel_simpson_weight(k, k_n) * (a + (b - a) * t);
            if (k == 0 && m > 0 && f[m - 1] == nu) {
                w[m - 1] += wk; /* the end node of the previous piece */
            } else {
                f[m] = nu;
                w[m] = wk;
                m++;
            }
            sum += wk;
        }
    }
    for (size_t i = 0; i < m; i++)
        w[i] /= sum;
    q->n = m;
    q->freq_hz = f;
    q->weight = w;
    return THZ_OK;
}

thz_status channel_quadrature_init(channel_quadrature *q, const thz_channel *ch, size_t n,
                                   thz_error *err)
{
    q->n = 0;
    q->freq_hz = NULL;
    q->weight = NULL;
    if (channel_has_response(ch))
        return channel_quadrature_table(q, ch, n < 3 ? 3 : n, err);
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
    double sigma_hz; /* the Gaussian's; 0 for a table, whose x is the frequency in Hz */
    double (*f)(double freq_hz, void *ctx);
    void *ctx;
    double num, den; /* accumulated int g f dx and int g dx (x in sigma units) */
} channel_adapt;

/* g(x) f(nu(x)) and g(x) at x sigma from the centre (a table: at x Hz); 0 for nu <= 0
 * and where a table's g is 0. */
static void channel_adapt_eval(const channel_adapt *a, double x, double *gf, double *g)
{
    if (a->sigma_hz == 0.0) {
        *g = channel_response(a->ch, x);
        *gf = *g > 0.0 ? *g * a->f(x, a->ctx) : 0.0;
        return;
    }
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

/* A table's base panels (as channel_quadrature_table's for CHANNEL_QUADRATURE_NODES),
 * each refined adaptively. Two passes: the first sums |g f| for the tolerance's scale
 * (no allocation; f is evaluated twice on the base nodes). */
static double channel_band_mean_table(const thz_channel *ch, double (*f)(double freq_hz, void *ctx),
                                      void *ctx)
{
    channel_adapt a = {ch, 0.0, f, ctx, 0.0, 0.0};
    const size_t panels = (CHANNEL_QUADRATURE_NODES - 1) / 2;
    double scale = 0.0, tol = 0.0, width = channel_support_width_hz(ch);
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i + 1 < ch->n_response; i++) {
            size_t p = channel_piece_panels(ch, i, panels, width);
            double lo = ch->response_hz[i], hi = ch->response_hz[i + 1];
            for (size_t j = 0; j < p; j++) {
                double x0 = lo + (hi - lo) * (double)j / (double)p;
                double x2 = j + 1 == p ? hi : lo + (hi - lo) * (double)(j + 1) / (double)p;
                double fv[3], gv[3];
                channel_adapt_eval(&a, x0, &fv[0], &gv[0]);
                channel_adapt_eval(&a, 0.5 * (x0 + x2), &fv[1], &gv[1]);
                channel_adapt_eval(&a, x2, &fv[2], &gv[2]);
                double s_num = (x2 - x0) / 6.0 * (fv[0] + 4.0 * fv[1] + fv[2]);
                if (pass == 0) {
                    scale += (x2 - x0) / 6.0 * (fabs(fv[0]) + 4.0 * fabs(fv[1]) + fabs(fv[2]));
                    total++;
                } else {
                    channel_adapt_panel(&a, x0, x2, fv, gv, s_num, tol, 0);
                }
            }
        }
        tol = CHANNEL_ADAPT_REL_TOL * scale / (double)(total ? total : 1);
    }
    return a.den > 0.0 ? a.num / a.den : 0.0;
}

double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx)
{
    if (channel_has_response(ch))
        return channel_band_mean_table(ch, f, ctx);
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
