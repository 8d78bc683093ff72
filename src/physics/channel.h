/* Channels: Gaussian spectral responses and band means (physics.md "Channels").
 *
 * g_c(nu) = exp(-(nu - nu_c)^2 / (2 sigma_c^2)), sigma_c = w_c nu_c / (2 sqrt(2 ln 2)).
 * A channel value is the response-weighted mean X_c = int g X dnu / int g dnu.
 */
#ifndef THZ_PHYSICS_CHANNEL_H
#define THZ_PHYSICS_CHANNEL_H

#include <stddef.h>

#include "core/error.h"

typedef struct thz_channel {
    char name[64];
    double center_hz;      /* nu_c */
    double relative_width; /* w_c = FWHM / nu_c, 0 < w <= 0.5 */
} thz_channel;

/* sigma_c in Hz. */
double channel_sigma_hz(const thz_channel *ch);

/* Equivalent bandwidth B_c = int g_c dnu = sigma_c sqrt(2 pi), in Hz. */
double channel_bandwidth_hz(const thz_channel *ch);

/* Noise bandwidth B_n = (int g_c dnu)^2 / int g_c^2 dnu in Hz (scene-format.md "Sensors:
 * optics and noise"): 2 sqrt(pi) sigma_c = 1.5054 FWHM for the Gaussian. */
double channel_noise_bandwidth_hz(const thz_channel *ch);

/* g_c(freq_hz), 1 at the centre. */
double channel_response(const thz_channel *ch, double freq_hz);

/* A frequency drawn from g_c (Gaussian) given two uniforms in [0,1); the non-positive
 * tail (1.2e-6 probable at w = 0.5, < 1e-20 at w = 0.2) is reflected, so the result is
 * always > 0. */
double channel_sample_hz(const thz_channel *ch, double u1, double u2);

/* Deterministic quadrature of the band mean: nodes over nu_c +- 6 sigma_c, weights
 * proportional to g_c times the rule's weights, normalised to sum to exactly 1 so
 * that the band mean of a constant is that constant. */
typedef struct channel_quadrature {
    size_t n;
    double *freq_hz;
    double *weight;
} channel_quadrature;

/* Default number of nodes of the fixed rule. The fixed rule resolves features of about
 * a tenth of sigma to ~3 %; channel_band_mean refines adaptively and reaches 1e-6 on
 * lines of sigma/10. Callers that integrate narrow lines with the fixed nodes must use
 * more of them. Nodes below 0 Hz (w > 0.39) are dropped. */
#define CHANNEL_QUADRATURE_NODES 401

thz_status channel_quadrature_init(channel_quadrature *q, const thz_channel *ch, size_t n,
                                   thz_error *err);
void channel_quadrature_fini(channel_quadrature *q);

/* Band mean of f over channel ch by the default quadrature. */
double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx);

#endif
