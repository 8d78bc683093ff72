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

#include <stdbool.h>
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

/* The piece i of a table, [f_i, f_i+1]: its width and end weights. */
static inline void channel_piece(const thz_channel *ch, size_t i, double *h, double *a, double *b)
{
    *h = ch->response_hz[i + 1] - ch->response_hz[i];
    *a = ch->response_weight[i];
    *b = ch->response_weight[i + 1];
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
 * that the band mean of a constant is that constant. `even`: the nodes are evenly
 * spaced (the Gaussian's rule without knots), so a frequency's node is found by
 * division. */
typedef struct channel_quadrature {
    size_t n;
    double *freq_hz;
    double *weight;
    bool even;
} channel_quadrature;

/* The span of the Gaussian's fixed rule: nu_c +- this many sigma_c. */
#define CHANNEL_QUADRATURE_SIGMAS 6.0

/* Default number of nodes of the fixed rule. The fixed rule resolves features of about
 * a tenth of sigma to ~3 %; channel_band_mean refines adaptively and reaches 1e-6 on
 * lines of sigma/10. Callers that integrate narrow lines with the fixed nodes must use
 * more of them, or name the lines' kinks (channel_quadrature_init_knots). Nodes below
 * 0 Hz (w > 0.39) are dropped. */
#define CHANNEL_QUADRATURE_NODES 401

/* The most knots channel_quadrature_init_knots places inside one band; more are
 * thinned evenly (taking every k-th), so a rule has at most about n + 3 x this many
 * nodes before refinement. A table denser than that is finer than the 401 nodes, and
 * the renderers' per-sample band sums cost a node each. */
#define CHANNEL_QUADRATURE_MAX_KNOTS 512

/* At most this many splits of a panel refine one rule (channel_structure). */
#define CHANNEL_QUADRATURE_MAX_SPLITS (4 * CHANNEL_QUADRATURE_NODES)

thz_status channel_quadrature_init(channel_quadrature *q, const thz_channel *ch, size_t n,
                                   thz_error *err);

/* Test functions of an integrand's structure between the knots, for a rule that refines
 * where they vary faster than its panels resolve (an atmosphere's transmittance over
 * long paths): eval writes m <= CHANNEL_STRUCTURE_MAX values at freq_hz, each of
 * magnitude at most about 1. */
#define CHANNEL_STRUCTURE_MAX 8
typedef struct channel_structure {
    size_t m;
    void (*eval)(double freq_hz, void *ctx, double *values);
    void *ctx;
} channel_structure;

/* channel_quadrature_init with the frequencies where the integrand may have a kink:
 * `knots` (n_knots, ascending; NULL when 0), the points of a scene's spectral tables,
 * which are linear in between. Each knot inside the band ends a piece of the rule, so
 * that composite Simpson integrates the tables' kinks exactly instead of with the
 * O(h^2) error of a kink between two nodes (0.1 % of a band mean for a line sigma/5 wide
 * in the air). The pieces share about n nodes in proportion to their widths, at least
 * one Simpson panel each. With `s` (may be NULL), a panel is split in two while its
 * halves change the band mean of a test function by more than 1e-7 (each split halving
 * the tolerance; at most CHANNEL_QUADRATURE_MAX_SPLITS splits). Without knots inside
 * the band and without s the rule is channel_quadrature_init's, node for node. */
thz_status channel_quadrature_init_knots(channel_quadrature *q, const thz_channel *ch, size_t n,
                                         const double *knots, size_t n_knots,
                                         const channel_structure *s, thz_error *err);
void channel_quadrature_fini(channel_quadrature *q);

/* An upper bound on the nodes of channel_quadrature_init_knots with at most n_knots
 * knots inside the band, refined by a structure or not (the memory estimate's). */
size_t channel_quadrature_max_nodes(const thz_channel *ch, size_t n, size_t n_knots, bool refined);

/* Band mean of f over channel ch, adaptive (see CHANNEL_QUADRATURE_NODES): the
 * Gaussian's base grid is the default quadrature's, a table's about as many nodes over
 * its pieces where g_c > 0 (its points among them), refined where f has structure. */
double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx);

#endif
