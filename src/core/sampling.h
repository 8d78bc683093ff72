/* Sampling helpers shared by the photon phase, the photon tracer and the renderer:
 * directions about a normal, and rng_uniform in the shape optics.h's samplers take.
 */
#ifndef THZ_CORE_SAMPLING_H
#define THZ_CORE_SAMPLING_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec3.h"

/* A unit direction about unit normal n with cos(theta) = mu and azimuth 2 pi u. */
vec3 sampling_direction(vec3 n, double mu, double u);
struct rng_stream;
/* A cosine-distributed direction about unit normal n from the next two 32-bit uniforms
 * of rng: the azimuth's word first, then the polar angle's (mu = sqrt(1 - u)). The order
 * is fixed here, not left to the order a compiler evaluates a call's arguments in. */
vec3 sampling_cosine32(vec3 n, struct rng_stream *rng);
/* A set of at most SAMPLING_STRATA_MAX directions stratified together (the first
 * scattered directions of a pixel's samples, render_stratum): member `which` of a set of
 * `count` draws its polar uniform in [lo, lo + width) = [p, p + 1) / count, p its place in
 * a random permutation of 0..count-1, and takes the azimuth uniform (phi0 + which / count)
 * mod 1, phi0 shared. Alone, every member is uniform on [0, 1)^2, so the law it samples is
 * unchanged; together the members meet each polar band once and are spread evenly in
 * azimuth. */
#define SAMPLING_STRATA_MAX 16u
typedef struct sampling_stratum {
    double polar_lo, polar_width; /* the polar uniform is polar_lo + polar_width u */
    double azimuth;               /* the azimuth uniform itself */
} sampling_stratum;
/* Member which < count <= SAMPLING_STRATA_MAX of the set drawn from `set` (every member
 * draws the same count words from a stream started the same way). */
sampling_stratum sampling_stratum_of(struct rng_stream *set, uint32_t count, uint32_t which);
/* sampling_stratum_of in two steps, for a caller that keeps the set for its members:
 * what the members share (phi0 and the permutation, drawn from `set`), then one member's
 * stratum; the same numbers. */
typedef struct sampling_set {
    double phi0;
    uint32_t count;
    uint8_t place[SAMPLING_STRATA_MAX];
} sampling_set;
void sampling_set_draw(struct rng_stream *set, uint32_t count, sampling_set *out);
sampling_stratum sampling_set_member(const sampling_set *s, uint32_t which);

/* sampling_direction for count photons at once: the same directions, in a loop the
 * compiler vectorises. */
void sampling_direction_many(const vec3 *n, const double *mu, const double *u, size_t count,
                             vec3 *out);

/* sampling_cos_sin_turn's body, inline for loops the compiler vectorises (its quadrant
 * chosen by selects, not branches). */
static inline void sampling_cos_sin_turn_inline(double u, double *c, double *s)
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
    int q = k & 3; /* quadrant: (c, s) = (cx, sx), (-sx, cx), (-cx, -sx), (sx, -cx) */
    double a = (q & 1) ? sx : cx, b = (q & 1) ? cx : sx;
    *c = (q == 1 || q == 2) ? -a : a;
    *s = (q >= 2) ? -b : b;
}

/* cos(2 pi u) and sin(2 pi u) for u in [0, 1] without libm, to 1e-16 (a quadrant
 * reduction of 4u, exact, and Taylor polynomials on |x| <= pi/4). */
void sampling_cos_sin_turn(double u, double *cos_out, double *sin_out);

/* Adapter: rng_uniform as an optics_uniform_fn (rng is the rng_stream). */
double sampling_uniform(void *rng);

/* Adapter: rng_uniform32 (32-bit uniforms, the photon phase's) as an optics_uniform_fn. */
double sampling_uniform32(void *rng);

#endif
