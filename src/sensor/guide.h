/* final-gather's photon guide (docs/integrators.md "Photon guide"): gather rays of the
 * cosine law importance-sampled by where the photons stored near the hit come from
 * (Jensen's importance sampling with the photon map). A cosine direction is a point
 * (u_polar, u_azimuth) of the unit square (mu = sqrt(1 - u_polar), phi = 2 pi u_azimuth);
 * the guide divides the square into GUIDE_POLAR x GUIDE_AZIMUTH equal cells, N in all,
 * each of probability
 *   P_c = (1 - GUIDE_DEFENSIVE) w_c / sum w + GUIDE_DEFENSIVE / N
 * from the summed |power| w_c of the photons that came from cell c. A uniform point warped
 * to the density N P_c carries the weight 1 / (N P_c), at most 1 / GUIDE_DEFENSIVE, so
 * each gather ray's estimate stays unbiased for any guide. The guide depends on the photon
 * map only, never on the gather rays, so a pixel's estimates stay independent. It is drawn
 * only from a deviation map (L - B(T0)), and only where the photons show it lowers the
 * noise: render_guide_warp leaves the rest to the cosine law.
 * Internal to src/sensor/.
 */
#ifndef THZ_SENSOR_GUIDE_H
#define THZ_SENSOR_GUIDE_H

#include <stdbool.h>

#include "core/vec3.h"
#include "sensor/render_context.h"

#define GUIDE_POLAR 4
#define GUIDE_AZIMUTH 8
/* The share of the guide's density spread evenly (the cosine law's). */
#define GUIDE_DEFENSIVE 0.25
/* Photons the guide is drawn from: those of the seen side within the disk that holds this
 * many at the side's mean density; no guide from fewer than GUIDE_MIN_PHOTONS. */
#define GUIDE_PHOTONS 128
#define GUIDE_MIN_PHOTONS 16
#define GUIDE_CELLS (GUIDE_POLAR * GUIDE_AZIMUTH)

/* A hit's guide, drawn when a gather ray first asks for it (zero-initialised: not yet). */
typedef struct render_guide {
    int state;                                  /* 0: not drawn yet, 1: drawn, -1: none */
    double row_cdf[GUIDE_POLAR + 1];            /* over the polar rows */
    double cdf[GUIDE_POLAR][GUIDE_AZIMUTH + 1]; /* within each row */
} render_guide;

/* A drawn guide from cell weights (GUIDE_CELLS, row by row: polar row r, azimuth column c
 * at r GUIDE_AZIMUTH + c; >= 0, uniform where all are 0), with the defensive share. */
void render_guide_from_weights(render_guide *g, const double *weights);

/* Warps a uniform point (u_polar, u_azimuth) of the unit square to the guide's density in
 * place, drawing the guide from the photons at `hit` (seen side, normal_seen towards the
 * sensor's side) on its first call; returns the weight 1 / (N P_c) of the cell it lands
 * in, or 1 (the point unchanged) where too few photons arrive there to draw a guide. */
double render_guide_warp(render_guide *g, const render_context *ctx, const accel_hit *hit,
                         vec3 normal_seen, double *u_polar, double *u_azimuth);

#endif
