/* The `lines` model over one band, for its tabulation (atm_internal.h: atm_lines_band).
 *
 * A table of a band at low pressure or of a wide band needs 10^4 to 10^6 points
 * (docs/atmosphere.md, "Band tabulation"), and a direct sum visits every line at each:
 * all ~3,000 O2 lines (their wings are not cut) and the H2O lines within 750 GHz, 90 %
 * of a load's time there (a dry 1 hPa atmosphere took 36 s to load the paper's six
 * channels). Most of those lines are far from any one frequency, and their sum is
 * smooth there. So the lines are split twice:
 *
 *  - over the band: a line is near if a pole (its resonance, with its Voigt window, or
 *    the mirror at -nu0) or a kink (an H2O cut-off: f = nu0 +- 750 GHz, 750 GHz - nu0)
 *    lies within FAR half widths of the band's interval; the far lines' sum is taken
 *    at NODES Chebyshev nodes and evaluated as that Chebyshev series;
 *  - over pieces of the interval (as many as the table's points warrant): of the band's
 *    near lines, those near a piece by the same rule are summed at each frequency as
 *    atm_lines_parts does, the others as a series of NODES terms fitted over the piece.
 *
 * A far line's contribution is analytic across the interval it is far from: its poles
 * (nu0 +- i gamma, their mirrors; tanh's at +-i pi kT/h) lie at least FAR half widths
 * away, and a Voigt line's window is near, so that beyond it the line is a Lorentzian (a
 * Gaussian core within the window would need many more terms). The series then
 * converges like rho^-n with rho >= 2 + sqrt(3) = 3.7 (FAR = 1): 32 nodes leave the
 * sums' rounding (unit/test_atm_lines_tables: within 1e-10 of alpha, or of 1e-9 of the band's
 * peak where alpha is smaller, from 1 atm to 1e-10 hPa and bands of 0.02 % to 50 %).
 * The tables change in their last bits, not more.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "atmosphere/atm_internal.h"
#include "atmosphere/atm_lines_data.h"
#include "core/alloc.h"

#define NODES 32
#define FAR 1.0
#define SPECIES 3
#define PIECES_MAX 65536
#define SPECIES_SHIFT 30 /* a line's reference: species << SPECIES_SHIFT | index */

struct atm_lines_band {
    const atm_lines_data *d;
    double lo_ghz, hw_ghz, c_ghz; /* the interval's start, half width and centre */
    const lbl_species *species[SPECIES];
    size_t n_all;
    uint32_t *near; /* the band's near lines (references), ascending */
    size_t n_near;
    double coef[NODES]; /* the far lines' alpha, 1/cm, as Chebyshev coefficients */
    size_t n_pieces;
    double piece_hw_ghz;
    size_t *piece_start;  /* n_pieces + 1 */
    uint32_t *piece_near; /* per piece, positions in near[] of its near lines, ascending */
    double *piece_coef;   /* n_pieces x NODES: the band's other near lines over the piece */
};

static const lbl_line *band_line(const atm_lines_band *b, uint32_t ref, lbl_shape *shape)
{
    const lbl_species *sp = b->species[ref >> SPECIES_SHIFT];
    *shape = sp->shape;
    return &sp->lines[ref & ((1u << SPECIES_SHIFT) - 1u)];
}

/* Whether line l has a pole, a kink or its Voigt window within `reach` of c (GHz). */
static bool line_near(lbl_shape shape, const lbl_line *l, double c, double reach)
{
    double nu = l->nu_ghz;
    double window = l->voigt ? VOIGT_WINDOW * l->gamma_d_ghz : 0.0;
    if (!(fabs(nu - c) > reach + window) || !(nu + c > reach + window))
        return true; /* the resonance or its mirror (NaN: near, summed as before) */
    if (shape == SHAPE_VVH_CUTOFF)
        return fabs(nu + H2O_CUTOFF_GHZ - c) <= reach || fabs(nu - H2O_CUTOFF_GHZ - c) <= reach ||
               fabs(H2O_CUTOFF_GHZ - nu - c) <= reach;
    return false;
}

/* The node x_k = cos(pi (k + 1/2) / N) of the interval c +- hw, in GHz. */
static double node_ghz(double c, double hw, int k)
{
    return c + hw * cos(M_PI * (k + 0.5) / NODES);
}

/* Chebyshev coefficients c_j = 2/N sum_k F(x_k) cos(pi j (k + 1/2) / N) from F at the
 * nodes. */
static void chebyshev_fit(const double *at_node, double *coef)
{
    for (int j = 0; j < NODES; j++) {
        double c = 0.0;
        for (int k = 0; k < NODES; k++)
            c += at_node[k] * cos(M_PI * j * (k + 0.5) / NODES);
        coef[j] = 2.0 / NODES * c;
    }
}

/* sum_j c_j T_j(x) - c_0 / 2, by Clenshaw's recurrence. */
static double chebyshev_eval(const double *coef, double x)
{
    double b1 = 0.0, b2 = 0.0;
    for (int j = NODES - 1; j >= 1; j--) {
        double t = 2.0 * x * b1 - b2 + coef[j];
        b2 = b1;
        b1 = t;
    }
    return x * b1 - b2 + 0.5 * coef[0];
}

/* The far lines' alpha in 1/cm at f GHz: every line but the band's near ones. */
static double band_far_sum(const atm_lines_band *b, double f)
{
    double vvh = lbl_vvh(b->d, f), sum = 0.0;
    size_t k = 0;
    for (uint32_t s = 0; s < SPECIES; s++) {
        const lbl_species *sp = b->species[s];
        for (uint32_t i = 0; i < sp->n; i++) {
            if (k < b->n_near && b->near[k] == (s << SPECIES_SHIFT | i)) {
                k++;
                continue;
            }
            sum += lbl_line_alpha(sp->shape, &sp->lines[i], f, vvh);
        }
    }
    return sum;
}

static double piece_centre(const atm_lines_band *b, size_t p)
{
    return b->lo_ghz + (double)(2 * p + 1) * b->piece_hw_ghz;
}

/* Piece p's near lines: their count, and with `out` their positions in b->near. */
static size_t piece_near_lines(const atm_lines_band *b, size_t p, uint32_t *out)
{
    double c = piece_centre(b, p), reach = (1.0 + FAR) * b->piece_hw_ghz;
    size_t n = 0;
    for (size_t j = 0; j < b->n_near; j++) {
        lbl_shape shape;
        const lbl_line *l = band_line(b, b->near[j], &shape);
        if (line_near(shape, l, c, reach)) {
            if (out)
                out[n] = (uint32_t)j;
            n++;
        }
    }
    return n;
}

/* Piece p's series: the band's near lines that are not near the piece. */
static void piece_fit(atm_lines_band *b, size_t p)
{
    const uint32_t *mine = b->piece_near + b->piece_start[p];
    size_t n_mine = b->piece_start[p + 1] - b->piece_start[p];
    double at_node[NODES];
    for (int k = 0; k < NODES; k++) {
        double f = node_ghz(piece_centre(b, p), b->piece_hw_ghz, k), vvh = lbl_vvh(b->d, f);
        double sum = 0.0;
        size_t m = 0;
        for (size_t j = 0; j < b->n_near; j++) {
            if (m < n_mine && mine[m] == j) {
                m++;
                continue;
            }
            lbl_shape shape;
            const lbl_line *l = band_line(b, b->near[j], &shape);
            sum += lbl_line_alpha(shape, l, f, vvh);
        }
        at_node[k] = sum;
    }
    chebyshev_fit(at_node, b->piece_coef + p * NODES);
}

static thz_status band_pieces(atm_lines_band *b, size_t points, thz_error *err)
{
    /* a piece's fit costs NODES sums over the band's near lines; each of the table's
     * points and midpoints in it (2 points / n_pieces at least) saves most of one: the fits
     * cost at most a quarter of what they save (fewer pieces leave more lines near each) */
    size_t n = points / (8 * NODES);
    b->n_pieces = n < 1 ? 1 : n > PIECES_MAX ? PIECES_MAX : n;
    b->piece_hw_ghz = b->hw_ghz / (double)b->n_pieces;
    b->piece_start = thz_calloc(b->n_pieces + 1, sizeof *b->piece_start);
    b->piece_coef = thz_malloc_array(b->n_pieces * NODES, sizeof *b->piece_coef);
    if (!b->piece_start || !b->piece_coef)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
    long np = (long)b->n_pieces;
#pragma omp parallel for schedule(dynamic, 16) num_threads(atm_table_threads(points))
    for (long p = 0; p < np; p++)
        b->piece_start[p + 1] = piece_near_lines(b, (size_t)p, NULL);
    for (size_t p = 0; p < b->n_pieces; p++)
        b->piece_start[p + 1] += b->piece_start[p];
    b->piece_near = thz_malloc_array(b->piece_start[b->n_pieces] ? b->piece_start[b->n_pieces] : 1,
                                     sizeof *b->piece_near);
    if (!b->piece_near)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
#pragma omp parallel for schedule(dynamic, 16) num_threads(atm_table_threads(points))
    for (long p = 0; p < np; p++) {
        piece_near_lines(b, (size_t)p, b->piece_near + b->piece_start[p]);
        piece_fit(b, (size_t)p);
    }
    return THZ_OK;
}

thz_status atm_lines_band_create(const atm_lines_data *d, double lo_hz, double hi_hz, size_t points,
                                 atm_lines_band **out, thz_error *err)
{
    *out = NULL;
    atm_lines_band *b = thz_calloc(1, sizeof *b);
    if (!b)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
    double margin = (hi_hz - lo_hz) / 8.0;
    b->d = d;
    b->lo_ghz = (lo_hz - margin) * 1e-9;
    b->hw_ghz = (0.5 * (hi_hz - lo_hz) + margin) * 1e-9;
    b->c_ghz = b->lo_ghz + b->hw_ghz;
    b->species[0] = &d->h2o;
    b->species[1] = &d->o2;
    b->species[2] = &d->o2_coupled;
    for (size_t s = 0; s < SPECIES; s++)
        b->n_all += b->species[s]->n;
    thz_status st = THZ_OK;
    if (b->n_all >= (1u << SPECIES_SHIFT))
        st = thz_error_set(err, THZ_ERR_LIMIT, "atmosphere: more than %u lines in a catalogue",
                           1u << SPECIES_SHIFT);
    b->near = st == THZ_OK ? thz_malloc_array(b->n_all ? b->n_all : 1, sizeof *b->near) : NULL;
    if (st == THZ_OK && !b->near)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory tabulating the atmosphere");
    if (st != THZ_OK) {
        atm_lines_band_destroy(b);
        return st;
    }
    for (uint32_t s = 0; s < SPECIES; s++) {
        const lbl_species *sp = b->species[s];
        for (uint32_t i = 0; i < sp->n; i++)
            if (line_near(sp->shape, &sp->lines[i], b->c_ghz, (1.0 + FAR) * b->hw_ghz))
                b->near[b->n_near++] = s << SPECIES_SHIFT | i;
    }
    double at_node[NODES];
    for (int k = 0; k < NODES; k++)
        at_node[k] = band_far_sum(b, node_ghz(b->c_ghz, b->hw_ghz, k));
    chebyshev_fit(at_node, b->coef);
    st = band_pieces(b, points, err);
    if (st != THZ_OK) {
        atm_lines_band_destroy(b);
        return st;
    }
    *out = b;
    return THZ_OK;
}

void atm_lines_band_destroy(atm_lines_band *b)
{
    if (!b)
        return;
    free(b->near);
    free(b->piece_start);
    free(b->piece_near);
    free(b->piece_coef);
    free(b);
}

void atm_lines_band_counts(const atm_lines_band *b, size_t *pieces, size_t *near, size_t *all)
{
    *pieces = b->n_pieces;
    *near = b->piece_start[b->n_pieces];
    *all = b->n_all;
}

double atm_lines_band_alpha_per_m(const atm_lines_band *b, double freq_hz)
{
    double f = freq_hz * 1e-9;
    double x = (f - b->c_ghz) / b->hw_ghz;
    if (!(fabs(x) <= 1.0)) {
        atm_alpha_parts parts;
        atm_lines_parts(b->d, freq_hz, &parts);
        return atmosphere_alpha_parts_sum(&parts);
    }
    double at = (f - b->lo_ghz) / (2.0 * b->piece_hw_ghz);
    size_t p = at < 1.0 ? 0 : (size_t)at;
    if (p >= b->n_pieces)
        p = b->n_pieces - 1;
    double sum =
        chebyshev_eval(b->coef, x) +
        chebyshev_eval(b->piece_coef + p * NODES, (f - piece_centre(b, p)) / b->piece_hw_ghz);
    double vvh = lbl_vvh(b->d, f);
    for (size_t k = b->piece_start[p]; k < b->piece_start[p + 1]; k++) {
        lbl_shape shape;
        const lbl_line *l = band_line(b, b->near[b->piece_near[k]], &shape);
        sum += lbl_line_alpha(shape, l, f, vvh);
    }
    return 100.0 * (sum + atm_lines_continua_per_cm(b->d, f));
}
