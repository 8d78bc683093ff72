/* final-gather's photon guide: see guide.h. */
#include "sensor/guide.h"

#include <math.h>
#include <string.h>

#include "photon/photon_map.h"

/* The photons of a radius query binned by the cell they come from (u_polar, u_azimuth),
 * in two halves (by the parity of their place in the map: independent of where they come
 * from), each with its sums of |power|, of power and of power squared. */
typedef struct guide_bins {
    vec3 n, t, b; /* the seen side's normal and sampling_direction's tangents */
    const photon_record *records;
    double abs[2][GUIDE_CELLS], sum[2][GUIDE_CELLS], sq[2][GUIDE_CELLS];
    size_t count;
} guide_bins;

_Static_assert(GUIDE_AZIMUTH == 8, "guide_octant bins the azimuth in eighths");

/* The azimuth's eighth of the circle, floor(8 phi / 2 pi) for phi = atan2(y, x) in
 * [0, 2 pi), by comparisons: atan2 was 6 % of final-gather's render. (On a boundary,
 * measure zero, the comparison's side and atan2's rounding may differ.) */
static int guide_octant(double x, double y)
{
    double ax = fabs(x), ay = fabs(y);
    if (ay == 0.0)
        return signbit(x) ? 4 : 0; /* atan2(+-0, x): 0 or pi */
    if (y >= 0.0 && x > 0.0)
        return ay < ax ? 0 : 1;
    if (y > 0.0)
        return ay > ax ? 2 : 3;
    if (x < 0.0)
        return ay < ax ? 4 : 5;
    return ay > ax ? 6 : 7;
}

static void guide_visit(void *vb, const photon_record *p, double distance2_m2)
{
    (void)distance2_m2;
    guide_bins *g = vb;
    vec3 from = v3_scale(photon_decode_direction(p->dir_oct), -1.0); /* towards its source */
    double mu = v3_dot(from, g->n);
    if (!(mu > 0.0))
        return;
    double u_polar = 1.0 - mu * mu;
    int row = (int)(u_polar * GUIDE_POLAR);
    row = row < 0 ? 0 : (row >= GUIDE_POLAR ? GUIDE_POLAR - 1 : row);
    int col = guide_octant(v3_dot(from, g->t), v3_dot(from, g->b));
    int cell = row * GUIDE_AZIMUTH + col, half = (int)((size_t)(p - g->records) & 1u);
    double phi = (double)p->power_w_per_hz;
    g->abs[half][cell] += fabs(phi);
    g->sum[half][cell] += phi;
    g->sq[half][cell] += phi * phi;
    g->count++;
}

/* Cell probabilities from summed |power| abs[] (uniform where it holds none). */
static void guide_probabilities(const double *abs, double *p)
{
    double total = 0.0;
    for (int c = 0; c < GUIDE_CELLS; c++)
        total += abs[c];
    for (int c = 0; c < GUIDE_CELLS; c++)
        p[c] = total > 0.0 && isfinite(total)
                   ? (1.0 - GUIDE_DEFENSIVE) * abs[c] / total + GUIDE_DEFENSIVE / GUIDE_CELLS
                   : 1.0 / GUIDE_CELLS;
}

/* Whether the guide lowers the gather rays' variance here, judged across the halves: with
 * m_c the mean power arriving from cell c, a cosine ray's second moment is proportional to
 * sum m_c^2 / N and a guided one's to sum m_c^2 / (N^2 P_c). (sum phi)^2 - sum phi^2 of
 * one half estimates m_c^2 (up to a factor) without bias, and the other half's guide is
 * independent of it: from the same photons, the guide would look better than it is (it
 * chose its cells where they happened to fall), and in a field of even radiance the
 * guided rays' noise would replace the cosine rays' none. */
static bool guide_helps(const guide_bins *g)
{
    double p[2][GUIDE_CELLS];
    guide_probabilities(g->abs[0], p[0]);
    guide_probabilities(g->abs[1], p[1]);
    double guided = 0.0, cosine = 0.0;
    for (int h = 0; h < 2; h++)
        for (int c = 0; c < GUIDE_CELLS; c++) {
            double m2 = g->sum[h][c] * g->sum[h][c] - g->sq[h][c];
            guided += m2 / (GUIDE_CELLS * p[1 - h][c]);
            cosine += m2;
        }
    return cosine > 0.0 && guided < cosine;
}

void render_guide_from_weights(render_guide *g, const double *weights)
{
    double p[GUIDE_CELLS], rows[GUIDE_POLAR], sum = 0.0;
    guide_probabilities(weights, p);
    for (int r = 0; r < GUIDE_POLAR; r++) {
        rows[r] = 0.0;
        for (int c = 0; c < GUIDE_AZIMUTH; c++)
            rows[r] += p[r * GUIDE_AZIMUTH + c];
        sum += rows[r];
    }
    g->state = 1;
    g->row_cdf[0] = 0.0;
    for (int r = 0; r < GUIDE_POLAR; r++) {
        g->row_cdf[r + 1] = r + 1 < GUIDE_POLAR ? g->row_cdf[r] + rows[r] / sum : 1.0;
        g->cdf[r][0] = 0.0;
        for (int c = 0; c < GUIDE_AZIMUTH; c++)
            g->cdf[r][c + 1] =
                c + 1 < GUIDE_AZIMUTH ? g->cdf[r][c] + p[r * GUIDE_AZIMUTH + c] / rows[r] : 1.0;
    }
}

/* Draws the guide at `hit` from the photons there; false where too few arrive, or where
 * it would not lower the noise. */
static bool guide_build(render_guide *g, const render_context *ctx, const accel_hit *hit,
                        vec3 normal_seen)
{
    if (!ctx->map || !ctx->deviation || !ctx->guided)
        return false;
    const thz_object *obj = &ctx->scene->objects[hit->object];
    size_t available = photon_map_object_count(ctx->map, hit->object, 1u << hit->side);
    double area = obj->mesh.total_area_m2;
    if (available < GUIDE_MIN_PHOTONS || !(area > 0.0))
        return false;
    guide_bins bins = {.n = normal_seen, .records = photon_map_records(ctx->map)};
    v3_basis(normal_seen, &bins.t, &bins.b);
    /* the disk that holds GUIDE_PHOTONS at the side's mean density: one radius query (a
     * k-nearest search cost twice as much for the same noise) */
    double r2 = (double)GUIDE_PHOTONS * area / ((double)available * M_PI);
    photon_map_radius_in(ctx->map, ctx->dir, hit->object, hit->side, hit->position_m, r2,
                         guide_visit, &bins);
    if (bins.count < GUIDE_MIN_PHOTONS || !guide_helps(&bins))
        return false;
    double abs[GUIDE_CELLS];
    for (int c = 0; c < GUIDE_CELLS; c++)
        abs[c] = bins.abs[0][c] + bins.abs[1][c];
    render_guide_from_weights(g, abs);
    return true;
}

/* The cell of u in cdf[0..n] (cdf[0] = 0, cdf[n] = 1) and u's place within it, in [0, 1). */
static int guide_pick(const double *cdf, int n, double u, double *frac)
{
    int k = 0;
    while (k < n - 1 && u >= cdf[k + 1])
        k++;
    double f = (u - cdf[k]) / (cdf[k + 1] - cdf[k]);
    *frac = f < 0.0 ? 0.0 : (f < 1.0 ? f : nextafter(1.0, 0.0));
    return k;
}

double render_guide_warp(render_guide *g, const render_context *ctx, const accel_hit *hit,
                         vec3 normal_seen, double *u_polar, double *u_azimuth)
{
    if (g->state == 0)
        g->state = guide_build(g, ctx, hit, normal_seen) ? 1 : -1;
    if (g->state < 0)
        return 1.0;
    double fr, fc;
    int r = guide_pick(g->row_cdf, GUIDE_POLAR, *u_polar, &fr);
    int c = guide_pick(g->cdf[r], GUIDE_AZIMUTH, *u_azimuth, &fc);
    *u_polar = ((double)r + fr) / GUIDE_POLAR;
    *u_azimuth = ((double)c + fc) / GUIDE_AZIMUTH;
    /* the density of the cell drawn, relative to the square's: from the very widths that
     * drew it (every cell has at least GUIDE_DEFENSIVE / N of the probability) */
    double cell = (g->row_cdf[r + 1] - g->row_cdf[r]) * (g->cdf[r][c + 1] - g->cdf[r][c]);
    return 1.0 / ((double)GUIDE_CELLS * cell);
}
