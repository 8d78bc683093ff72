/* Fresnel optics of a complex index seen from air: see fresnel.h. */
#include "physics/fresnel.h"

#include <complex.h>
#include <math.h>
#include <stddef.h>

/* mu clamped into [0, 1]. */
static double fresnel_mu(double mu)
{
    mu = fabs(mu);
    return mu > 1.0 ? 1.0 : mu;
}

void fresnel_interface(double n, double k, double mu, double *r_s, double *r_p, double *cos_t)
{
    mu = fresnel_mu(mu);
    double s2 = (1.0 - mu) * (1.0 + mu); /* sin^2 theta_i, accurate near mu = 1 */
    double complex eps = (n + I * k) * (n + I * k);
    double complex q = csqrt(eps - s2);
    if (cimag(q) < 0.0)
        q = -q; /* the decaying wave */
    if (r_s) {
        double complex rs = (mu - q) / (mu + q);
        *r_s = creal(rs) * creal(rs) + cimag(rs) * cimag(rs);
    }
    if (r_p) {
        double complex rp = (eps * mu - q) / (eps * mu + q);
        *r_p = creal(rp) * creal(rp) + cimag(rp) * cimag(rp);
    }
    if (cos_t) {
        double re = fabs(creal(q));
        double len = sqrt(s2 + re * re);
        *cos_t = len > 0.0 ? re / len : 1.0;
    }
}

double fresnel_reflectance(double n, double k, double mu)
{
    double rs, rp;
    fresnel_interface(n, k, mu, &rs, &rp, NULL);
    return 0.5 * (rs + rp);
}

/* R and T of a slab of one polarisation with interface reflectance r and internal
 * transmittance tau. */
static void fresnel_slab_one(double r, double tau, double *refl, double *trans)
{
    double denom = 1.0 - r * r * tau * tau;
    if (!(denom > 0.0)) { /* r = 1 (grazing) or tau = 1 with r = 1: all reflected */
        *refl = 1.0;
        *trans = 0.0;
        return;
    }
    double c = (1.0 - r) * (1.0 - r);
    *refl = r + c * r * tau * tau / denom;
    *trans = c * tau / denom;
}

void fresnel_slab(double n, double k, double mu, double alpha_per_m, double thickness_m,
                  double *reflectance, double *transmittance)
{
    double rs, rp, cos_t;
    fresnel_interface(n, k, mu, &rs, &rp, &cos_t);
    double depth = alpha_per_m * thickness_m;
    double tau = depth > 0.0 ? (cos_t > 0.0 ? exp(-depth / cos_t) : 0.0) : 1.0;
    double refl_s, trans_s, refl_p, trans_p;
    fresnel_slab_one(rs, tau, &refl_s, &trans_s);
    fresnel_slab_one(rp, tau, &refl_p, &trans_p);
    *reflectance = 0.5 * (refl_s + refl_p);
    *transmittance = 0.5 * (trans_s + trans_p);
}
