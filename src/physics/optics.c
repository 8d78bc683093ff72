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

/* Exponential integral E3(x) = int_1^inf exp(-x t) t^-3 dt, x >= 0, to ~1e-15 relative:
 * power series for x <= 1, modified Lentz continued fraction above (Numerical Recipes
 * "expint" specialised to n = 3). */
static double optics_expint3(double x)
{
    const int n = 3, nm1 = 2;
    if (x <= 0.0)
        return 0.5;
    if (x > 1.0) {
        const double tiny = DBL_MIN / DBL_EPSILON;
        double b = x + n, c = 1.0 / tiny, d = 1.0 / b, h = d;
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
    double ans = 1.0 / nm1, fact = 1.0;
    for (int i = 1; i <= OPTICS_EXPINT_MAXIT; i++) {
        double del;
        fact *= -x / i;
        if (i != nm1) {
            del = -fact / (i - nm1);
        } else {
            double psi = -OPTICS_EULER_GAMMA;
            for (int ii = 1; ii <= nm1; ii++)
                psi += 1.0 / ii;
            del = fact * (-log(x) + psi);
        }
        ans += del;
        if (fabs(del) < fabs(ans) * DBL_EPSILON * 0.5)
            break;
    }
    return ans;
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

/* 2 int_0^1 X(mu) mu dmu by Gauss-Legendre, X = R (which = 0) or T (which = 1). */
static double optics_index_mean(const optics_point *o, int which)
{
    double sum = 0.0;
    for (int i = 0; i < GAUSS_LEGENDRE_NODES; i++) {
        double mu = gauss_legendre_x[i], r, t;
        optics_index_rt(o, mu, &r, &t);
        sum += gauss_legendre_w[i] * (which == 0 ? r : t) * mu;
    }
    return 2.0 * sum;
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
 * the cosine law (acceptance = the law's hemispherical mean). */
static bool optics_reject(const optics_point *o, optics_law_fn law, optics_uniform_fn next,
                          void *ctx, double *mu)
{
    for (long i = 0; i < OPTICS_MAX_TRIES; i++) {
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
    return optics_reject(o, optics_reflectance, next, ctx, mu);
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
        return optics_reject(o, optics_transmission, next, ctx, mu);
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

bool optics_sample_emission_mu(const optics_point *o, optics_uniform_fn next, void *ctx, double *mu)
{
    if (o->has_index && !o->explicit_emissivity)
        return optics_reject(o, optics_absorption, next, ctx, mu);
    double c = optics_cap(o);
    double tau = optics_tau(o);
    if (o->explicit_emissivity || !optics_is_shell(o) || tau == 0.0) {
        /* eps does not depend on angle: cosine distribution. */
        double eps = optics_emissivity(o, 1.0);
        if (!(eps > 0.0))
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
