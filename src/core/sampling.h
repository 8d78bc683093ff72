/* Sampling helpers shared by the photon phase, the photon tracer and the renderer:
 * directions about a normal, and rng_uniform in the shape optics.h's samplers take.
 */
#ifndef THZ_CORE_SAMPLING_H
#define THZ_CORE_SAMPLING_H

#include "core/vec3.h"

/* A unit direction about unit normal n with cos(theta) = mu and azimuth 2 pi u. */
vec3 sampling_direction(vec3 n, double mu, double u);

/* cos(2 pi u) and sin(2 pi u) for u in [0, 1] without libm, to 1e-16 (a quadrant
 * reduction of 4u, exact, and Taylor polynomials on |x| <= pi/4). */
void sampling_cos_sin_turn(double u, double *cos_out, double *sin_out);

/* Adapter: rng_uniform as an optics_uniform_fn (rng is the rng_stream). */
double sampling_uniform(void *rng);

/* Adapter: rng_uniform32 (32-bit uniforms, the photon phase's) as an optics_uniform_fn. */
double sampling_uniform32(void *rng);

#endif
