/* Sampling helpers shared by the photon phase, the photon tracer and the renderer:
 * directions about a normal, and rng_uniform in the shape optics.h's samplers take.
 */
#ifndef THZ_CORE_SAMPLING_H
#define THZ_CORE_SAMPLING_H

#include "core/vec3.h"

/* A unit direction about unit normal n with cos(theta) = mu and azimuth 2 pi u. */
vec3 sampling_direction(vec3 n, double mu, double u);

/* Adapter: rng_uniform as an optics_uniform_fn (rng is the rng_stream). */
double sampling_uniform(void *rng);

/* Adapter: rng_uniform32 (32-bit uniforms, the photon phase's) as an optics_uniform_fn. */
double sampling_uniform32(void *rng);

#endif
