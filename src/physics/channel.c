/* Channel responses (Gaussian or a measured table) and sampling (physics.md
 * "Channels"; the band-mean quadratures are in channel_quadrature.c). Every function
 * handles both: the Gaussian's arithmetic is that of before tables existed (Box-Muller's
 * log and cos since computed without libm, to ~1e-16); a table's is exact for its
 * piecewise-linear g. */
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

#define CHANNEL_SQRT_2PI 2.5066282746310002

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
