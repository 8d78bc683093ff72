/* Channels: spectral responses and band means (physics.md "Channels").
 *
 * A channel's response g_c is either the Gaussian
 * g_c(nu) = exp(-(nu - nu_c)^2 / (2 sigma_c^2)), sigma_c = w_c nu_c / (2 sqrt(2 ln 2)),
 * or a measured table (scene-format.md "Channels: measured spectral response"): linear
 * interpolation between its points, 0 outside them, the weights as given (so that B_c
 * keeps a filter's transmission; band means and B_n do not depend on their scale).
 * A channel value is the response-weighted mean X_c = int g X dnu / int g dnu.
 */
#ifndef THZ_PHYSICS_CHANNEL_H
#define THZ_PHYSICS_CHANNEL_H

#include <stddef.h>

#include "core/error.h"

typedef struct thz_channel {
    char name[64];
    double center_hz;      /* nu_c; of a table: as given, else the response-weighted mean */
    double relative_width; /* w_c = FWHM / nu_c, 0 < w <= 0.5; 0 for a table */
    /* The measured response (n_response == 0: the Gaussian): n_response >= 2 strictly
     * increasing frequencies, weights >= 0 not all 0, and the cumulative integral of g
     * from the first point to each point (Hz). Owned; channel_fini frees them. */
    size_t n_response;
    double *response_hz;
    double *response_weight;
    double *response_area_hz;
} thz_channel;

/* FWHM of a Gaussian in units of its sigma, 2 sqrt(2 ln 2). */
#define CHANNEL_FWHM_PER_SIGMA 2.3548200450309493

/* Makes ch a table channel: copies the n points (freq_hz > 0 strictly increasing,
 * weight >= 0 not all 0: the loader has checked) and, when centre_hz is not > 0, sets
 * nu_c to the response-weighted mean frequency int nu g dnu / int g dnu. THZ_ERR_NOMEM
 * or THZ_ERR_INPUT (a bad table). */
thz_status channel_set_response(thz_channel *ch, size_t n, const double *freq_hz,
                                const double *weight, double centre_hz, thz_error *err);

/* Frees a table channel's arrays (the channel becomes Gaussian); NULL does nothing. */
void channel_fini(thz_channel *ch);

/* Whether ch has a measured response table. */
static inline int channel_has_response(const thz_channel *ch)
{
    return ch->n_response > 0;
}

/* sigma_c in Hz. For a table, B_c / sqrt(2 pi) (the sigma of the peak-1 Gaussian of the
 * same area): a scale, never a span (spans come from channel_support_hz). */
double channel_sigma_hz(const thz_channel *ch);

/* The frequencies outside which g_c is 0 or negligible: the Gaussian's nu_c +- sigmas
 * sigma_c (lo may be <= 0: callers clamp), a table's span where g_c > 0 (`sigmas` does
 * not apply). */
void channel_support_hz(const thz_channel *ch, double sigmas, double *lo_hz, double *hi_hz);

/* Full width at half maximum in Hz: w_c nu_c for the Gaussian; for a table, between the
 * outermost frequencies where g_c crosses half its peak (ENVI's `fwhm`). */
double channel_fwhm_hz(const thz_channel *ch);

/* Equivalent bandwidth B_c = int g_c dnu in Hz: sigma_c sqrt(2 pi) for the Gaussian,
 * the (exact) trapezoid sum of a table. */
double channel_bandwidth_hz(const thz_channel *ch);

/* Noise bandwidth B_n = (int g_c dnu)^2 / int g_c^2 dnu in Hz (scene-format.md "Sensors:
 * optics and noise"): 2 sqrt(pi) sigma_c = 1.5054 FWHM for the Gaussian; exact for a table
 * (g^2 of a linear piece integrates to h (a^2 + ab + b^2) / 3). */
double channel_noise_bandwidth_hz(const thz_channel *ch);

/* g_c(freq_hz): 1 at the Gaussian's centre; a table's interpolated weight, 0 outside it. */
double channel_response(const thz_channel *ch, double freq_hz);

/* A frequency drawn from g_c (Gaussian) given two uniforms in [0,1); the non-positive
 * tail (1.2e-6 probable at w = 0.5, < 1e-20 at w = 0.2) is reflected, so the result is
 * always > 0. A table's piecewise-linear density is sampled exactly: u1 picks a piece by
 * its area, u2 the frequency within it by inverting the piece's linear density. */
double channel_sample_hz(const thz_channel *ch, double u1, double u2);
/* channel_sample_hz for n pairs (u1[j], u2[j]), u1 in [0, 1): the same frequencies, in a
 * loop the compiler vectorises (the photon phase's Box-Muller, one log, square root and
 * cosine per photon, was 5-7 % of its time one at a time). */
void channel_sample_many_hz(const thz_channel *ch, const double *u1, const double *u2, size_t n,
                            double *nu);

/* Deterministic quadrature of the band mean: nodes over nu_c +- 6 sigma_c (a table:
 * composite Simpson on each piece where g_c > 0, the table's points among the nodes,
 * about n nodes in all, spread in proportion to the pieces' widths), weights
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

/* Band mean of f over channel ch, adaptive (see CHANNEL_QUADRATURE_NODES): the
 * Gaussian's base grid is the default quadrature's, a table's about as many nodes over
 * its pieces where g_c > 0 (its points among them), refined where f has structure. */
double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx);

#endif
