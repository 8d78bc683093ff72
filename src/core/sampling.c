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

vec3 sampling_direction(vec3 n, double mu, double u)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    double phi = 2.0 * M_PI * u;
    vec3 d = v3_scale(n, mu);
    d = v3_madd(d, s * cos(phi), t);
    d = v3_madd(d, s * sin(phi), b);
    return v3_normalize(d);
}
