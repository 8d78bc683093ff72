/* The emitting atmosphere as a photon source (docs/atmosphere.md "Emitting atmosphere";
 * beyond the paper): the air in a box, and the radiance that enters the box from
 * outside it.
 *
 * The box is the atmosphere's extent, or without one the bounding box of every mesh
 * widened by 1 % of its diagonal on each side. Two source classes join the surfaces:
 *
 * - the air: 4 pi alpha(nu) B_nu(T_air) per unit volume, isotropic, uniform in the box;
 * - the boundary: each face of the box emits inwards, Lambertian, with the radiance L_b a
 *   ray leaving the box sees (the renderer's escape radiance there): B_nu(T_bg) with an
 *   extent; without one the air beyond, B_nu(T_air) where alpha > 0 (else B_nu(T_bg)).
 *   L_b = 0 when the atmosphere does not emit (or there is none).
 *
 * Deviation maps (reference temperature T0 > 0, emission.h): the sources become
 * 4 pi alpha (B(T_air) - B0) per volume, with T_air = 0 for a non-emitting atmosphere
 * (absorbing air is air at 0 K), and L_b - B0 at the boundary (-B0 where a scene without
 * an emitting atmosphere is open). Both classes may then fire without an emitting
 * atmosphere, with signed powers; the class probabilities follow the magnitudes (the
 * air's source has one sign over the band; the boundary's band mean of |L_b - B0|),
 * the boundary's times the share of its photons that reach a surface (reach_share): a
 * boundary whose photons never meet a surface (a closed room inside the widened box,
 * whose faces see only the room's outside and the gap around it) fires nothing, as it
 * would store nothing. That changes the power fired, never the map.
 *
 * Scheme (unbiased for the band mean, as physics.md "Photon phase" allows): each photon
 * picks a class with probability proportional to its band-mean power, then divides its
 * power by that probability. An air photon's frequency is drawn from a histogram q of
 * |g_c(nu) P_air(nu)| over nu_c +- 6 sigma (AIR_EMISSION_BINS bins: the air's power
 * follows alpha's lines) and it carries Phi = g_c P_air Q / (q B_c p_air K), P_air exact
 * at its frequency, Q the integral of q; a boundary photon's frequency is drawn from g_c
 * and it carries pi A L_b(nu) / (p_b K) (pi A (L_b - B0) / (p_b K) when T0 > 0). Their object is
 * ACCEL_NO_OBJECT (trace_photon starts them from their point).
 *
 * Where there is no air or no opening, nothing is emitted: an air photon whose first hit
 * is the back face of a one-sided solid (it was born inside a solid) is dropped by
 * trace_photon, and so is a boundary photon whose point is hidden from outside (a ray
 * back out of the box from just inside it meets a surface) or that first meets a back
 * face. Photons carry the power of the whole box and faces, so the rest fire the true
 * power in expectation. The reported band powers are multiplied by the shares kept,
 * estimated from AIR_EMISSION_SHARE_RAYS points by the same rules (they enter only the
 * statistics and the class probabilities, never the photons' expected power).
 *
 * Without an emitting atmosphere and with T0 = 0 no class uniform is drawn: photon
 * streams are those of a scene without it. With T0 = 0 everything is as above,
 * bit for bit.
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
#define AIR_EMISSION_SHARE_RAYS 16384

typedef struct air_emission {
    bool active; /* the air or the boundary fires photons in this channel */
    const thz_scene *scene;
    const accel *acc;
    size_t channel;
    uint64_t n_photons;        /* K */
    double min_m[3], max_m[3]; /* the box */
    double eps_m;              /* step inside the box for the boundary's visibility test */
    bool faces_clear;          /* every mesh keeps clear of the faces: the test always
                                  passes and casts no ray */
    /* the air */
    double volume_m3;
    double air_share;          /* estimated share of air photons kept (not in solids) */
    double air_power_w_per_hz; /* band mean of P_air over the box, times air_share */
    double lo_hz, bin_hz;      /* bin i covers [lo + i bin, lo + (i + 1) bin) */
    double *q;                 /* AIR_EMISSION_BINS histogram densities (> 0), or NULL */
    double *cdf;               /* cumulative q_i bin_hz; last = Q */
    /* the boundary */
    double area_m2;                 /* of the box's six faces */
    double face_cdf[6];             /* cumulative face areas */
    double open_share;              /* estimated share of boundary photons kept */
    double reach_share;             /* T0 > 0: ... and that reach a surface (else open_share) */
    double boundary_power_w_per_hz; /* pi A band mean of L_b, times open_share */
    /* class probabilities: air, boundary, surfaces */
    double p_air, p_boundary, p_surfaces;
    double band_power_w_per_hz; /* air + boundary: to add to the surfaces' Pbar_A (the
                                   physical emission, also when T0 > 0) */
    /* deviation map (T0 > 0; equal to the powers above when T0 = 0) */
    double t0_k;                        /* reference temperature T0 */
    double air_deviation_w_per_hz;      /* band mean of the air's source, signed, x share */
    double boundary_deviation_w_per_hz; /* pi A band mean of L_b - B0, x open_share */
} air_emission;

/* Prepares channel `channel`'s air and boundary sources for K = n_photons photons of
 * the map of L - B_nu(t0_k) (t0_k = 0: of L), beside surfaces of band-mean power
 * surface_power_w_per_hz (with T0 > 0: the band mean of the magnitude of their signed
 * power, emission_band_magnitude_w_per_hz). Inactive (no class is drawn) when neither
 * the air nor the boundary has a source in the band: with T0 = 0, when the atmosphere
 * does not emit. */
thz_status air_emission_init(air_emission *a, const thz_scene *scene, const accel *acc,
                             size_t channel, uint64_t n_photons, double surface_power_w_per_hz,
                             double t0_k, thz_error *err);
void air_emission_fini(air_emission *a);

/* One photon of any class (see above), in two parts around a surface photon's own draws
 * (the caller draws many photons' at once): the class draw, and an air or boundary
 * photon whole (*surface false; the return as emission_sample's: false if nothing could
 * be drawn); then, after emission_sample's draws for a surface photon, its power's share
 * (air_emission_surface_share). Allocate nothing. */
bool air_emission_draw_class(const air_emission *a, rng_stream *rng, emission_photon *out,
                             bool *surface);
void air_emission_surface_share(const air_emission *a, emission_photon *out);

#endif
