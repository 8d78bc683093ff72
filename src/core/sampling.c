/* Sampling helpers: see sampling.h. */
#include "core/sampling.h"

#include <math.h>

#include "core/rng.h"

double sampling_uniform(void *rng)
{
    return rng_uniform(rng);
}

double sampling_uniform32(void *rng)
{
    return rng_uniform32(rng);
}

/* 4u = k + f with k an integer and |f| <= 1/2 (both exact), so 2 pi u = k pi/2 + x,
 * |x| <= pi/4, and the Taylor polynomials of degree 16 (cos) and 15 (sin) at x err by
 * less than (pi/4)^17 / 17! = 5e-17, below the rounding of 2 pi u itself. */
void sampling_cos_sin_turn(double u, double *c, double *s)
{
    double t = 4.0 * u;
    int k = (int)(t + 0.5);
    double x = (t - (double)k) * (M_PI / 2.0), x2 = x * x;
    /* Horner in x^2, written out (a loop over a table is not unrolled at -O2). */
    double sx = -1.0 / 1307674368000.0;
    sx = sx * x2 + 1.0 / 6227020800.0;
    sx = sx * x2 - 1.0 / 39916800.0;
    sx = sx * x2 + 1.0 / 362880.0;
    sx = sx * x2 - 1.0 / 5040.0;
    sx = sx * x2 + 1.0 / 120.0;
    sx = sx * x2 - 1.0 / 6.0;
    sx = sx * x2 + 1.0;
    double cx = 1.0 / 20922789888000.0;
    cx = cx * x2 - 1.0 / 87178291200.0;
    cx = cx * x2 + 1.0 / 479001600.0;
    cx = cx * x2 - 1.0 / 3628800.0;
    cx = cx * x2 + 1.0 / 40320.0;
    cx = cx * x2 - 1.0 / 720.0;
    cx = cx * x2 + 1.0 / 24.0;
    cx = cx * x2 - 0.5;
    cx = cx * x2 + 1.0;
    sx *= x;
    switch (k & 3) {
    case 0:
        *c = cx, *s = sx;
        break;
    case 1:
        *c = -sx, *s = cx;
        break;
    case 2:
        *c = -cx, *s = -sx;
        break;
    default:
        *c = sx, *s = -cx;
        break;
    }
}

vec3 sampling_direction(vec3 n, double mu, double u)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    double cos_phi, sin_phi;
    sampling_cos_sin_turn(u, &cos_phi, &sin_phi);
    vec3 d = v3_scale(n, mu);
    d = v3_madd(d, s * cos_phi, t);
    d = v3_madd(d, s * sin_phi, b);
    return v3_normalize(d);
}
