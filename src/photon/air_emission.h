/* The emitting atmosphere as a photon source (docs/atmosphere.md "Emitting atmosphere";
 * beyond the paper). The air inside the atmosphere's extent (the scene's bounding box
 * without one) emits P_air(nu) = 4 pi alpha(nu) B_nu(T_air) V, isotropically.
 *
 * Scheme (unbiased for the band mean, as physics.md "Photon phase" allows): the air is a
 * source class beside the surfaces. Each photon first picks the air with probability
 * p_air = Pbar_air / (Pbar_air + Pbar_A) (band means), else the surfaces by
 * emission_sample, and divides its power by the probability of its class. An air photon's
 * frequency is drawn from a histogram q of g_c(nu) P_air(nu) over nu_c +- 6 sigma
 * (AIR_EMISSION_BINS bins: the air's power follows alpha's lines), and it carries
 *     Phi = g_c(nu) P_air(nu) Q / (q(nu) B_c p_air K),   Q = integral of q,
 * with P_air exact at its own frequency; its point is uniform in the box, its direction
 * isotropic, its object ACCEL_NO_OBJECT (trace_photon starts it from the point itself).
 * A point inside a solid is not air: an air photon whose first hit is the back face of a
 * one-sided solid (solids are closed) is dropped by trace_photon, so the photons fire
 * 4 pi alpha B over the air's true volume in expectation. The reported band power is
 * Pbar_air times the air's share of the box, estimated from AIR_EMISSION_VOLUME_RAYS
 * points and isotropic directions tested by the same rule (it only enters the
 * statistics and p_air, never the photons' powers).
 * Without an emitting atmosphere nothing is drawn for the class, so photon streams are
 * those of a scene without air emission.
 */
#ifndef THZ_PHOTON_AIR_EMISSION_H
#define THZ_PHOTON_AIR_EMISSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "core/rng.h"
#include "photon/emission.h"
#include "scene/scene.h"

#define AIR_EMISSION_BINS 4096
#define AIR_EMISSION_SIGMAS 6.0
#define AIR_EMISSION_VOLUME_RAYS 16384

typedef struct air_emission {
    bool active;                /* the air emits in this channel */
    const thz_scene *scene;
    size_t channel;
    uint64_t n_photons;         /* K */
    double min_m[3], max_m[3];  /* the emitting box */
    double volume_m3;
    double air_share;           /* estimated share of the box that is air (not in solids) */
    double band_power_w_per_hz; /* Pbar_air: band mean of P_air, times air_share */
    double p_air;               /* probability of an air photon */
    double lo_hz, bin_hz;       /* bin i covers [lo + i bin, lo + (i + 1) bin) */
    double *q;                  /* AIR_EMISSION_BINS histogram densities q_i (> 0) */
    double *cdf;                /* cumulative q_i bin_hz; last = Q */
} air_emission;

/* Prepares channel `channel`'s air source for K = n_photons photons, beside surfaces of
 * band-mean power surface_power_w_per_hz. Inactive (and allocating nothing) when the
 * atmosphere does not emit or has no power in the band. */
thz_status air_emission_init(air_emission *a, const thz_scene *scene, const accel *acc,
                             size_t channel, uint64_t n_photons, double surface_power_w_per_hz,
                             thz_error *err);
void air_emission_fini(air_emission *a);

/* Draws one photon of either class (see above); the same contract as emission_sample,
 * which it calls for surface photons. Allocates nothing. */
bool air_emission_sample(const air_emission *a, const emission_table *t, rng_stream *rng,
                         double *scratch, emission_photon *out);

#endif
