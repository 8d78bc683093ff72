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
    sampling_cos_sin_turn_inline(u, c, s);
}

/* sampling_direction's body (fmax(0, x) as a select: the same for every x, NaN too, and
 * 1 - mu^2 is never -0), inline for sampling_direction_many's loop. */
static inline vec3 sampling_direction_inline(vec3 n, double mu, double u)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    double s2 = 1.0 - mu * mu;
    double s = sqrt(s2 > 0.0 ? s2 : 0.0);
    double cos_phi, sin_phi;
    sampling_cos_sin_turn_inline(u, &cos_phi, &sin_phi);
    vec3 d = v3_scale(n, mu);
    d = v3_madd(d, s * cos_phi, t);
    d = v3_madd(d, s * sin_phi, b);
    return v3_normalize(d);
}

vec3 sampling_direction(vec3 n, double mu, double u)
{
    return sampling_direction_inline(n, mu, u);
}

vec3 sampling_cosine32(vec3 n, rng_stream *rng)
{
    double azimuth = rng_uniform32(rng);
    double mu = sqrt(1.0 - rng_uniform32(rng));
    return sampling_direction_inline(n, mu, azimuth);
}

void sampling_set_draw(rng_stream *set, uint32_t count, sampling_set *out)
{
    out->count = count;
    for (uint32_t k = 0; k < count; k++)
        out->place[k] = (uint8_t)k;
    out->phi0 = rng_uniform(set);
    for (uint32_t k = count; k-- > 1;) { /* Fisher-Yates */
        uint32_t r = (uint32_t)(rng_uniform(set) * (double)(k + 1));
        uint8_t t = out->place[k];
        out->place[k] = out->place[r];
        out->place[r] = t;
    }
}

sampling_stratum sampling_set_member(const sampling_set *s, uint32_t which)
{
    double azimuth = s->phi0 + (double)which / (double)s->count;
    return (sampling_stratum){.polar_lo = (double)s->place[which] / (double)s->count,
                              .polar_width = 1.0 / (double)s->count,
                              .azimuth = azimuth < 1.0 ? azimuth : azimuth - 1.0};
}

sampling_stratum sampling_stratum_of(rng_stream *set, uint32_t count, uint32_t which)
{
    sampling_set s;
    sampling_set_draw(set, count, &s);
    return sampling_set_member(&s, which);
}

void sampling_direction_many(const vec3 *n, const double *mu, const double *u, size_t count,
                             vec3 *out)
{
    for (size_t j = 0; j < count; j++)
        out[j] = sampling_direction_inline(n[j], mu[j], u[j]);
}
