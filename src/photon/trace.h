/* Propagation of one photon (physics.md "Photon phase", eq. 7-10, and "Surfaces").
 *
 * From its emission the photon flies to the next hit; its power is multiplied by the
 * atmosphere's transmittance exp(-alpha(nu) d); when it has fallen below
 * w_min = min_relative_power of the initial power it survives with probability w / w_min
 * at w_min (else it ends, "terminated"); the hit is recorded (incident power, position,
 * frequency, incoming direction, object << 1 | side, bounce count); then one uniform
 * picks reflection (p = R), transmission (p = T(theta), shells only) or absorption.
 * The back side of a one-sided solid absorbs (counted in back_face_hits; the record is
 * still stored, the renderer ignores it). Reflection is Lambertian on the side of
 * incidence (reciprocal and exact with an angle-dependent R: mu ~ R(mu) mu, brdf.h), a
 * mirror, or Ward's lobe (whose sample weight multiplies the power); `diffuse` transmission leaves
 * from the other side with mu ~ T(mu) mu, `straight` transmission goes on unchanged. Neither
 * changes the power: the sampling probabilities equal the BRDF/BTDF weights. A path is capped at
 * TRACE_MAX_BOUNCES hits (counted; it should never trigger).
 *
 * Photons of a deviation map (emission.h) may carry negative power: the path is the
 * same, traced with |power| (the roulette compares |w| with min_relative_power times the
 * initial |power| and a survivor keeps its sign); records and the power sums keep the
 * sign, so fired = absorbed + escaped + atmosphere + terminated still holds. Photons of
 * power 0 (or NaN) are counted and not traced.
 */
#ifndef THZ_PHOTON_TRACE_H
#define THZ_PHOTON_TRACE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "core/rng.h"
#include "photon/emission.h"
#include "photon/photon_map.h"
#include "scene/scene.h"

#define TRACE_MAX_BOUNCES 10000

/* Counters of the paths traced; summed over chunks in a fixed order. */
typedef struct trace_counters {
    uint64_t photons; /* photons started (including those of zero power) */
    uint64_t rays;    /* rays cast (hits, escapes and low-power stops) */
    uint64_t hits;
    uint64_t reflected;
    uint64_t transmitted;
    uint64_t absorbed;
    uint64_t escaped;
    uint64_t back_face_hits;
    uint64_t terminated;
    uint64_t capped;    /* paths stopped at TRACE_MAX_BOUNCES */
    double fired_power; /* sum of initial powers, W/Hz */
    double absorbed_power;
    double escaped_power;
    double atmosphere_power;
    double terminated_power; /* removed at termination minus added to survivors */
} trace_counters;

void trace_counters_add(trace_counters *sum, const trace_counters *c);

/* A growable array of records owned by one thread. */
typedef struct trace_buffer {
    photon_record *records;
    size_t count, capacity;
} trace_buffer;

void trace_buffer_fini(trace_buffer *b);

typedef enum trace_event { TRACE_REFLECT = 0, TRACE_TRANSMIT, TRACE_ABSORB } trace_event;

/* Russian roulette (eq. 8-10) with one uniform u in [0, 1): reflect if u < R(mu), transmit
 * if u < R + T(mu) (T = 0 for solids), else absorb. */
trace_event trace_roulette(const optics_point *o, double mu, double u);

/* Exit direction of diffuse transmission: mu ~ T(mu) mu about unit normal n_out (the
 * normal of the side the photon leaves from), uniform azimuth. */
vec3 trace_diffuse_transmission_dir(const optics_point *o, vec3 n_out, rng_stream *rng);

/* The objects' optics where they do not depend on frequency (a material without an index
 * whose reflectivity, attenuation and emissivity are constants): evaluated once for a
 * phase instead of at every hit (scene_object_optics gives the same point at any
 * frequency, its freq_hz aside, which only an index reads). */
typedef struct trace_optics {
    optics_point *optics; /* per object; meaningful where constant */
    bool *constant;       /* per object */
} trace_optics;

thz_status trace_optics_init(trace_optics *t, const thz_scene *scene, thz_error *err);
void trace_optics_fini(trace_optics *t);

/* Traces one emitted photon, appending its records to buf and its outcome to c; optics
 * (may be NULL) the scene's trace_optics. Returns false only when buf cannot grow (out of
 * memory). */
bool trace_photon(const thz_scene *scene, const accel *acc, const trace_optics *optics,
                  const emission_photon *e, rng_stream *rng, trace_buffer *buf, trace_counters *c);

#endif
