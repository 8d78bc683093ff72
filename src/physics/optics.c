/* Surface optics at one frequency (physics.md "Surfaces").
 *
 * With c = 1 - R and tau = alpha_M t, a shell transmits T(mu) = min(exp(-tau/mu), c).
 * The cap is reached for mu >= mu* = tau / (-ln c); below it T = exp(-tau/mu). With
 * m = min(mu*, 1), the hemispherical mean has the exact form
 *     T-bar = 2 m^2 E3(tau/m) + c (1 - m^2),
 * since 2 int_0^m exp(-tau/mu) mu dmu = 2 m^2 E3(tau/m) (substitute mu = m/t).
 */
#include "physics/optics.h"

#include <float.h>
#include <math.h>

#include "physics/fresnel.h"
#include "physics/gauss_legendre.h"

#define OPTICS_C_M_PER_S 299792458.0

#define OPTICS_EULER_GAMMA 0.57721566490153286061
#define OPTICS_EXPINT_MAXIT 200
#define OPTICS_E3_CHEB 20

/* Exponential integral E3(x) = int_1^inf exp(-x t) t^-3 dt, x >= 0, to ~1e-15 relative.
 * It is evaluated once per photon drawn from a shell and per diffuse transmission, so
 * it avoids iterating where it can:
 * - x <= 1: its series E3 = 1/2 - x + x^2/2 (3/2 - gamma - ln x)
 *   + sum_{i>=3} (-1)^(i+1) x^i / (i! (i - 2)), the sum to i = 18 (the rest < 1e-18);
 * - 1 < x <= 8: e^x E3(x) by Chebyshev series of 20 terms on [1, 2], [2, 4] and [4, 8]
 *   (interpolated at 22 Chebyshev points in 60-digit arithmetic by
 *   scripts/e3_chebyshev.py; E3's only singularity, the logarithm's at 0, bounds their
 *   decay to 1 / 5.8 per term: the 21st is below 1e-17 of e^x E3);
 * - x > 8: the modified Lentz continued fraction (Numerical Recipes "expint" for
 *   n = 3), 20 iterations or fewer there. */
static double optics_expint3(double x)
{
    static const double series[16] = {
        0.16666666666666666,     -0.020833333333333332,   0.0027777777777777779,
        -0.00034722222222222224, 3.9682539682539683e-05,  -4.1335978835978839e-06,
        3.9367598891408415e-07,  -3.444664902998236e-08,  2.7835675983824134e-09,
        -2.0876756987868099e-10, 1.4599130760746922e-11,  -9.5589546647747697e-13,
        5.8824336398613975e-14,  -3.4139123802767039e-15, 1.8743048362303472e-16,
        -9.7620043553663908e-18};
    static const double cheb[3][OPTICS_E3_CHEB] = {
        {0.25732494694903008,     -0.037478768146611337,   0.0030630337249575972,
         -0.00027656000416436592, 2.7153742255613089e-05,  -2.8577646998041328e-06,
         3.1845988334913719e-07,  -3.7200266363362458e-08, 4.5184394233513101e-09,
         -5.6699772477249535e-10, 7.3129391384826795e-11,  -9.6545676076907202e-12,
         1.3003572338377127e-12,  -1.7820084558028273e-13, 2.4792078585786906e-14,
         -3.4952381298486672e-15, 4.9858267301827739e-16,  -7.1867934309328636e-17,
         1.0456740352922309e-17,  -1.5343012904214548e-18},
        {0.18299862935811378,     -0.035541833762701987,   0.0036665346597896981,
         -0.00039872668505824534, 4.538374059086709e-05,   -5.3724725025737431e-06,
         6.5782124657110653e-07,  -8.2921146650887862e-08, 1.0718357368730831e-08,
         -1.4159686283770168e-09, 1.9064737105461289e-10,  -2.6100130193428955e-11,
         3.6260353831468642e-12,  -5.1035641751681437e-13, 7.2669233217226962e-14,
         -1.0455287116679519e-14, 1.5183675892086091e-15,  -2.2237317308957696e-16,
         3.2818050292416171e-17,  -4.8771598672393604e-18},
        {0.11827926820815908,     -0.028454587865582904,   0.0035187235222198655,
         -0.00044600456373894518, 5.7789291727820075e-05,  -7.6360856965392384e-06,
         1.0268161124679807e-06,  -1.4025150603948305e-07, 1.9427179947300955e-08,
         -2.7250971018034646e-09, 3.8661968871068192e-10,  -5.5416938888250482e-11,
         8.0175653402622492e-12,  -1.1698194055415556e-12, 1.7200839292414245e-13,
         -2.5471261389328183e-14, 3.796374296973972e-15,   -5.6922117663124631e-16,
         8.5819571364250452e-17,  -1.3004707314078664e-17},
    };
    if (x <= 0.0)
        return 0.5;
    if (x <= 1.0) {
        double sum = series[15];
        for (int i = 14; i >= 0; i--)
            sum = sum * x + series[i];
        return 0.5 - x + 0.5 * x * x * (1.5 - OPTICS_EULER_GAMMA - log(x)) + x * x * x * sum;
    }
    if (x <= 8.0) {
        int piece = x <= 2.0 ? 0 : x <= 4.0 ? 1 : 2;
        double a = piece == 0 ? 1.0 : piece == 1 ? 2.0 : 4.0;
        double t = 2.0 * x / a - 3.0; /* [a, 2a] onto [-1, 1] */
        const double *c = cheb[piece];
        double b1 = 0.0, b2 = 0.0; /* Clenshaw */
        for (int k = OPTICS_E3_CHEB - 1; k >= 1; k--) {
            double b0 = 2.0 * t * b1 - b2 + c[k];
            b2 = b1;
            b1 = b0;
        }
        return (t * b1 - b2 + c[0]) * exp(-x);
    }
    const int nm1 = 2;
    const double tiny = DBL_MIN / DBL_EPSILON;
    double b = x + 3.0, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i <= OPTICS_EXPINT_MAXIT; i++) {
        double an = -(double)i * (double)(nm1 + i);
        b += 2.0;
        d = 1.0 / (an * d + b);
        c = b + an / c;
        double del = c * d;
        h *= del;
        if (fabs(del - 1.0) < DBL_EPSILON)
            break;
    }
    return h * exp(-x);
}

/* 1 - R clamped to [0, 1]. */
static double optics_cap(const optics_point *o)
{
    double c = 1.0 - o->reflectivity;
    if (c < 0.0)
        return 0.0;
    return c > 1.0 ? 1.0 : c;
}

static bool optics_is_shell(const optics_point *o)
{
    return o->thickness_m > 0.0;
}

/* Optical depth at normal incidence, tau = alpha_M t >= 0. */
static double optics_tau(const optics_point *o)
{
    double tau = o->attenuation_per_m * o->thickness_m;
    return tau > 0.0 ? tau : 0.0;
}

/* min(mu*, 1) for a shell with tau > 0 and 0 < c. */
static double optics_kink(double tau, double c)
{
    if (c >= 1.0)
        return 1.0; /* exp(-tau/mu) < 1 = cap for every mu */
    double mstar = tau / -log(c);
    return mstar < 1.0 ? mstar : 1.0;
}

/* ---- Optics from a complex index (has_index) ---- */

bool optics_reflectance_varies(const optics_point *o)
{
    return o->has_index && !o->reflectivity_given;
}

/* The slab's internal attenuation, 1/m: alpha_M when given, else 4 pi k nu / c. */
static double optics_index_alpha(const optics_point *o)
{
    if (o->attenuation_given)
        return o->attenuation_per_m > 0.0 ? o->attenuation_per_m : 0.0;
    double a = 4.0 * M_PI * o->k * o->freq_hz / OPTICS_C_M_PER_S;
    return a > 0.0 ? a : 0.0;
}

/* R(mu) and T(mu) with an index. */
static void optics_index_rt(const optics_point *o, double mu, double *r, double *t)
{
    mu = fabs(mu);
    if (mu > 1.0)
        mu = 1.0;
    if (!optics_is_shell(o)) {
        *r = o->reflectivity_given ? o->reflectivity : fresnel_reflectance(o->n, o->k, mu);
        *t = 0.0;
        return;
    }
    double rs, ts;
    fresnel_slab(o->n, o->k, mu, optics_index_alpha(o), o->thickness_m, &rs, &ts);
    if (o->reflectivity_given) {
        double c = optics_cap(o);
        *r = o->reflectivity;
        *t = ts < c ? ts : c;
        return;
    }
    *r = rs;
    *t = ts;
}

/* Where a slab's T_slab(mu), rising from 0 at grazing incidence, reaches the cap 1 - R
 * of a given reflectivity: there min(T_slab, 1 - R) has a kink, which a Gauss-Legendre
 * rule over [0, 1] integrates only to about 1e-4 (ε̄ 0.2 % low). 1 without a cap or a
 * crossing; bisection to double precision. */
static double optics_index_kink(const optics_point *o)
{
    if (!o->reflectivity_given || !optics_is_shell(o))
        return 1.0;
    double c = optics_cap(o), alpha = optics_index_alpha(o), rs, ts;
    fresnel_slab(o->n, o->k, 1.0, alpha, o->thickness_m, &rs, &ts);
    if (!(ts > c))
        return 1.0;
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 60 && hi - lo > 1e-15; i++) {
        double mid = 0.5 * (lo + hi);
        fresnel_slab(o->n, o->k, mid, alpha, o->thickness_m, &rs, &ts);
        *(ts < c ? &lo : &hi) = mid;
    }
    return 0.5 * (lo + hi);
}

/* 2 int_a^b X(mu) mu dmu by Gauss-Legendre, X = R (which = 0) or T (which = 1). */
static double optics_index_piece(const optics_point *o, int which, double a, double b)
{
    double sum = 0.0;
    for (int i = 0; i < GAUSS_LEGENDRE_NODES; i++) {
        double mu = a + (b - a) * gauss_legendre_x[i], r, t;
        optics_index_rt(o, mu, &r, &t);
        sum += gauss_legendre_w[i] * (which == 0 ? r : t) * mu;
    }
    return 2.0 * (b - a) * sum;
}

/* 2 int_0^1 X(mu) mu dmu: one rule on each side of T's kink (R has none). */
static double optics_index_mean(const optics_point *o, int which)
{
    double kink = which == 1 ? optics_index_kink(o) : 1.0;
    double mean = optics_index_piece(o, which, 0.0, kink);
    return kink < 1.0 ? mean + optics_index_piece(o, which, kink, 1.0) : mean;
}

void optics_prepare(optics_point *o)
{
    if (!o->has_index)
        return;
    o->means_ready = false;
    o->mean_r = optics_index_mean(o, 0);
    o->mean_t = optics_is_shell(o) ? optics_index_mean(o, 1) : 0.0;
    o->means_ready = true;
}

double optics_reflectance(const optics_point *o, double mu)
{
    if (!o->has_index)
        return o->reflectivity;
    double r, t;
    optics_index_rt(o, mu, &r, &t);
    return r;
}

double optics_mean_reflectance(const optics_point *o)
{
    if (!o->has_index)
        return o->reflectivity;
    return o->means_ready ? o->mean_r : optics_index_mean(o, 0);
}

typedef double (*optics_law_fn)(const optics_point *o, double mu);

/* Samples mu with density proportional to law(mu) mu, law in [0, 1], by rejection from
 * the cosine law (acceptance = the law's hemispherical mean, `mean`). After
 * OPTICS_QUICK_TRIES rejections it asks the mean: below OPTICS_MIN_MEAN (an index of 1, a
 * surface that reflects or absorbs next to nothing) it gives up at once, where the
 * proposals went on to OPTICS_MAX_TRIES for every sample (seconds a photon or gather
 * ray: final-gather on such a material ran for hours and ignored SIGTERM meanwhile).
 * Draws that succeed are the same as before, from the same numbers. */
static bool optics_reject(const optics_point *o, optics_law_fn law,
                          double (*mean)(const optics_point *), optics_uniform_fn next, void *ctx,
                          double *mu)
{
    for (long i = 0; i < OPTICS_MAX_TRIES; i++) {
        if (i == OPTICS_QUICK_TRIES && !(mean(o) >= OPTICS_MIN_MEAN))
            return false;
        double cand = sqrt(1.0 - next(ctx));
        if (cand > 0.0 && next(ctx) < law(o, cand)) {
            *mu = cand;
            return true;
        }
    }
    return false;
}

bool optics_sample_reflection_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                                 double *mu)
{
    if (!optics_reflectance_varies(o)) {
        if (!(optics_reflectance(o, 1.0) > 0.0))
            return false;
        *mu = sqrt(1.0 - next(ctx));
        return true;
    }
    return optics_reject(o, optics_reflectance, optics_mean_reflectance, next, ctx, mu);
}

double optics_transmission(const optics_point *o, double mu)
{
    if (!optics_is_shell(o))
        return 0.0;
    if (o->has_index) {
        double r, t;
        optics_index_rt(o, mu, &r, &t);
        return t;
    }
    double c = optics_cap(o);
    double tau = optics_tau(o);
    mu = fabs(mu);
    if (tau == 0.0)
        return c;
    if (!(mu > 0.0))
        return 0.0;
    double t = exp(-tau / mu);
    return t < c ? t : c;
}

double optics_absorption(const optics_point *o, double mu)
{
    if (o->has_index) {
        double r, t;
        optics_index_rt(o, mu, &r, &t);
        double a = 1.0 - r - t;
        return a > 0.0 ? a : 0.0;
    }
    double a = optics_cap(o) - optics_transmission(o, mu);
    return a > 0.0 ? a : 0.0;
}

double optics_emissivity(const optics_point *o, double mu)
{
    if (o->explicit_emissivity)
        return o->emissivity > 0.0 ? o->emissivity : 0.0;
    return optics_absorption(o, mu);
}

void optics_absorption_emissivity(const optics_point *o, double mu, double *a, double *eps)
{
    *a = optics_absorption(o, mu);
    *eps = o->explicit_emissivity ? optics_emissivity(o, mu) : *a;
}

double optics_mean_transmission(const optics_point *o)
{
    if (!optics_is_shell(o))
        return 0.0;
    if (o->has_index)
        return o->means_ready ? o->mean_t : optics_index_mean(o, 1);
    double c = optics_cap(o);
    double tau = optics_tau(o);
    if (c == 0.0)
        return 0.0;
    if (tau == 0.0)
        return c;
    double m = optics_kink(tau, c);
    return 2.0 * m * m * optics_expint3(tau / m) + c * (1.0 - m * m);
}

double optics_mean_emissivity(const optics_point *o)
{
    if (o->explicit_emissivity)
        return o->emissivity > 0.0 ? o->emissivity : 0.0;
    if (o->has_index) {
        double e = 1.0 - optics_mean_reflectance(o) - optics_mean_transmission(o);
        return e > 0.0 ? e : 0.0;
    }
    double e = optics_cap(o) - optics_mean_transmission(o);
    return e > 0.0 ? e : 0.0;
}

bool optics_sample_transmission_mu(const optics_point *o, optics_uniform_fn next, void *ctx,
                                   double *mu)
{
    if (!optics_is_shell(o))
        return false;
    if (o->has_index)
        return optics_reject(o, optics_transmission, optics_mean_transmission, next, ctx, mu);
    double c = optics_cap(o);
    double tau = optics_tau(o);
    if (c == 0.0)
        return false;
    if (tau == 0.0) {
        *mu = sqrt(1.0 - next(ctx)); /* cosine distribution, mu in (0, 1] */
        return true;
    }
    double m = optics_kink(tau, c);
    double x = tau / m;
    /* Masses of the two pieces of T(mu) mu: exp(-tau/mu) mu on (0, m], c mu on (m, 1]. */
    double mass_exp = m * m * optics_expint3(x);
    double mass_cap = 0.5 * c * (1.0 - m * m);
    double total = mass_exp + mass_cap;
    if (!(total > 0.0))
        return false;
    if (next(ctx) * total >= mass_exp) {
        *mu = sqrt(1.0 - next(ctx) * (1.0 - m * m));
        return true;
    }
    for (;;) {
        if (x <= 1.0) {
            /* Cosine proposal on (0, m], accepted with exp(-tau/mu) / exp(-tau/m). */
            double cand = m * sqrt(1.0 - next(ctx));
            if (next(ctx) < exp(-tau * (1.0 / cand - 1.0 / m))) {
                *mu = cand;
                return true;
            }
        } else {
            /* In s = 1/mu the density is exp(-tau s) s^-3 on [1/m, inf): propose
             * s = 1/m + Exp(tau), accept with (1/(m s))^3. */
            double s = 1.0 / m - log(1.0 - next(ctx)) / tau;
            double r = 1.0 / (m * s);
            if (next(ctx) < r * r * r) {
                *mu = 1.0 / s;
                return true;
            }
        }
    }
}

/* eps does not depend on angle: no index (or an explicit eps), and a solid, an explicit
 * eps or a shell of optical depth 0. */
static bool optics_emission_is_constant(const optics_point *o)
{
    if (o->has_index && !o->explicit_emissivity)
        return false;
    return o->explicit_emissivity || !optics_is_shell(o) || optics_tau(o) == 0.0;
}

bool optics_emission_is_cosine(const optics_point *o)
{
    return optics_emission_is_constant(o) && optics_emissivity(o, 1.0) > 0.0;
}

bool optics_sample_emission_mu(const optics_point *o, optics_uniform_fn next, void *ctx, double *mu)
{
    if (o->has_index && !o->explicit_emissivity)
        return optics_reject(o, optics_absorption, optics_mean_emissivity, next, ctx, mu);
    double c = optics_cap(o);
    double tau = optics_tau(o);
    if (optics_emission_is_constant(o)) {
        /* eps does not depend on angle: cosine distribution. */
        if (!optics_emission_is_cosine(o))
            return false;
        *mu = sqrt(1.0 - next(ctx));
        return true;
    }
    if (c == 0.0)
        return false;
    /* Kirchhoff shell: eps(mu) = c - exp(-tau/mu) on (0, m], 0 above. It is bounded by
     * b(mu) = min(c, tau/mu) (as 1 - exp(-y) <= y); propose from b(mu) mu, which is
     * c mu on (0, a] and tau on (a, m] with a = min(tau/c, m), and accept eps / b. */
    double m = optics_kink(tau, c);
    double a = tau / c < m ? tau / c : m;
    double mass_lin = 0.5 * c * a * a;
    double mass_flat = tau * (m - a);
    double total = mass_lin + mass_flat;
    for (;;) {
        double cand, bound;
        if (next(ctx) * total < mass_lin) {
            cand = a * sqrt(1.0 - next(ctx));
            bound = c;
        } else {
            cand = m - next(ctx) * (m - a);
            bound = tau / cand;
        }
        if (!(cand > 0.0))
            continue;
        double eps = (c - 1.0) - expm1(-tau / cand);
        if (next(ctx) * bound < eps) {
            *mu = cand;
            return true;
        }
    }
}

double optics_kirchhoff_violation(const optics_point *o)
{
    if (!o->explicit_emissivity)
        return 0.0;
    if (o->has_index) { /* A(mu) at the quadrature nodes and both ends */
        double eps = optics_emissivity(o, 1.0), worst = 0.0;
        for (int i = -1; i <= GAUSS_LEGENDRE_NODES; i++) {
            double mu = i < 0 ? 1e-9 : i == GAUSS_LEGENDRE_NODES ? 1.0 : gauss_legendre_x[i];
            double d = fabs(eps - optics_absorption(o, mu));
            worst = d > worst ? d : worst;
        }
        return worst;
    }
    /* A(mu) is monotone in mu (constant for solids, decreasing for shells), so the
     * largest |eps - A| is at an end of (0, 1]: A(0+) = c for a shell with tau > 0
     * (T -> 0), and A(1). */
    double eps = optics_emissivity(o, 1.0);
    double c = optics_cap(o);
    double a0 = (optics_is_shell(o) && optics_tau(o) == 0.0) ? 0.0 : c;
    double a1 = optics_absorption(o, 1.0);
    double d0 = fabs(eps - a0), d1 = fabs(eps - a1);
    return d0 > d1 ? d0 : d1;
}
