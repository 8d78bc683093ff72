/* Band means over a channel (physics.md "Channels"): the fixed rules whose nodes the
 * renderers tabulate (composite Simpson, optionally split at a scene's spectral knots)
 * and the adaptive band mean of a function. */
#include "physics/channel.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "core/alloc.h"

/* The width of a table's support (Hz). */
static double channel_support_width_hz(const thz_channel *ch)
{
    double lo, hi;
    channel_support_hz(ch, 0.0, &lo, &hi);
    return hi - lo;
}

/* Composite Simpson panels given to table piece i when about `panels` are spread over
 * the pieces where g > 0 (support width `width_hz`) in proportion to their widths; 0 for
 * a piece where g = 0. */
static size_t channel_piece_panels(const thz_channel *ch, size_t i, size_t panels, double width_hz)
{
    double h, a, b;
    channel_piece(ch, i, &h, &a, &b);
    if (!(a + b > 0.0))
        return 0;
    double p = ceil((double)panels * h / width_hz);
    return p < 1.0 ? 1 : (size_t)p;
}

/* Node i of n (odd) in units of sigma from the centre: -6 .. +6, symmetric. */
static double channel_node_x(size_t i, size_t n)
{
    double h = 2.0 * CHANNEL_QUADRATURE_SIGMAS / (double)(n - 1);
    if (2 * i + 1 == n)
        return 0.0;
    if (2 * i + 1 < n)
        return -h * (double)((n - 1) / 2 - i);
    return h * (double)(i - (n - 1) / 2);
}

/* Composite Simpson weight (1, 4, 2, 4, ..., 4, 1) of node i of n (odd). */
static double channel_simpson_weight(size_t i, size_t n)
{
    if (i == 0 || i == n - 1)
        return 1.0;
    return (i % 2) ? 4.0 : 2.0;
}

/* ---- the fixed rules ------------------------------------------------------------ */

/* The knots strictly inside (lo_hz, hi_hz): knot j of `used` is hz[first + j * stride],
 * the stride thinning them to at most CHANNEL_QUADRATURE_MAX_KNOTS. */
typedef struct channel_knots {
    const double *hz;
    size_t first, used, stride;
} channel_knots;

static channel_knots channel_knots_inside(const double *knots, size_t n_knots, double lo_hz,
                                          double hi_hz)
{
    channel_knots k = {knots, 0, 0, 1};
    if (!knots)
        return k;
    size_t a = 0;
    while (a < n_knots && !(knots[a] > lo_hz))
        a++;
    size_t b = a;
    while (b < n_knots && knots[b] < hi_hz)
        b++;
    size_t count = b - a;
    k.first = a;
    k.stride = count > CHANNEL_QUADRATURE_MAX_KNOTS
                   ? (count + CHANNEL_QUADRATURE_MAX_KNOTS - 1) / CHANNEL_QUADRATURE_MAX_KNOTS
                   : 1;
    k.used = (count + k.stride - 1) / k.stride;
    return k;
}

static double channel_knot_hz(const channel_knots *k, size_t j)
{
    return k->hz[k->first + j * k->stride];
}

/* Refinement of a rule by a channel_structure: a Simpson panel whose halves disagree
 * with it on any test function by more than its share of CHANNEL_REFINE_REL_TOL of the
 * band's int g dnu is split, at most CHANNEL_REFINE_MAX_DEPTH times and
 * CHANNEL_QUADRATURE_MAX_SPLITS times in all (each split adds two nodes; beyond the
 * budget, panels further right stay as they are). */
#define CHANNEL_REFINE_REL_TOL 1e-7
#define CHANNEL_REFINE_MAX_DEPTH 10

/* A rule under construction: composite Simpson on pieces, about `panels` panels spread
 * over the support (width_hz) in proportion to the pieces' widths, at least one each,
 * refined by `s` when it is not NULL. With f == NULL the pieces only count their nodes
 * into m (an upper bound: adjacent pieces share an end node). */
typedef struct channel_rule {
    const thz_channel *ch;
    size_t panels;
    double width_hz;
    const channel_structure *s;
    double tol; /* a base panel's share of the refinement's tolerance */
    size_t splits;
    double *f, *w;
    size_t m;
    double sum;
} channel_rule;

/* A node of a panel: its frequency, its fraction of the table's piece (unused for the
 * Gaussian) and g there. */
typedef struct channel_point {
    double nu, t, g;
} channel_point;

static channel_point channel_rule_point(const channel_rule *r, size_t piece, double nu, double t)
{
    const thz_channel *ch = r->ch;
    channel_point p = {nu, t, 0.0};
    if (channel_has_response(ch)) {
        double h, a, b;
        channel_piece(ch, piece, &h, &a, &b);
        p.g = a + (b - a) * t;
    } else {
        double x = (nu - ch->center_hz) / channel_sigma_hz(ch);
        p.g = exp(-0.5 * x * x);
    }
    return p;
}

static void channel_rule_node(channel_rule *r, double nu, double wk, bool first)
{
    if (!(nu > 0.0))
        return; /* g is defined for nu > 0 only (wide channels reach below 0) */
    if (first && r->m > 0 && r->f[r->m - 1] == nu) {
        r->w[r->m - 1] += wk; /* the end node of the previous panel or piece */
    } else {
        r->f[r->m] = nu;
        r->w[r->m] = wk;
        r->m++;
    }
    r->sum += wk;
}

/* Whether Simpson on [p0, p2] (midpoint p1) disagrees with its halves on a test
 * function by more than 15 tol (the halves' error is then above tol). Points at or
 * below 0 Hz count 0, as the rule drops them (the test functions are not asked there:
 * the air's attenuation is NaN below 0 Hz, and NaN splitting every panel of a wide
 * channel's negative tail spent the whole budget there); a NaN elsewhere splits
 * nothing. */
static bool channel_rule_split(const channel_rule *r, const channel_point p[5], double tol)
{
    enum { most = CHANNEL_STRUCTURE_MAX };
    double v[5][most], g[5];
    for (int i = 0; i < 5; i++) {
        g[i] = p[i].nu > 0.0 ? p[i].g : 0.0;
        for (size_t j = 0; j < r->s->m; j++)
            v[i][j] = 0.0;
        if (p[i].nu > 0.0)
            r->s->eval(p[i].nu, r->s->ctx, v[i]);
    }
    if (!(g[4] > 0.0 || g[0] > 0.0))
        return false; /* wholly below 0 Hz */
    double h = p[4].nu - p[0].nu;
    for (size_t j = 0; j < r->s->m; j++) {
        double one = h / 6.0 * (g[0] * v[0][j] + 4.0 * g[2] * v[2][j] + g[4] * v[4][j]);
        double two = h / 12.0 *
                     (g[0] * v[0][j] + 4.0 * g[1] * v[1][j] + 2.0 * g[2] * v[2][j] +
                      4.0 * g[3] * v[3][j] + g[4] * v[4][j]);
        if (fabs(two - one) > 15.0 * tol)
            return true;
    }
    return false;
}

/* The Simpson panel p0, p1, p2 of a refined rule, split while channel_rule_split says
 * so. */
static void channel_rule_panel(channel_rule *r, size_t piece, channel_point p0, channel_point p1,
                               channel_point p2, double tol, int depth)
{
    if (depth < CHANNEL_REFINE_MAX_DEPTH && r->splits < CHANNEL_QUADRATURE_MAX_SPLITS) {
        channel_point p[5] = {
            p0, channel_rule_point(r, piece, 0.5 * (p0.nu + p1.nu), 0.5 * (p0.t + p1.t)), p1,
            channel_rule_point(r, piece, 0.5 * (p1.nu + p2.nu), 0.5 * (p1.t + p2.t)), p2};
        if (channel_rule_split(r, p, tol)) {
            r->splits++;
            channel_rule_panel(r, piece, p[0], p[1], p[2], 0.5 * tol, depth + 1);
            channel_rule_panel(r, piece, p[2], p[3], p[4], 0.5 * tol, depth + 1);
            return;
        }
    }
    if (!r->f) {
        r->m += 3;
        return;
    }
    double h6 = (p2.nu - p0.nu) / 6.0;
    channel_rule_node(r, p0.nu, h6 * p0.g, true);
    channel_rule_node(r, p1.nu, 4.0 * h6 * p1.g, false);
    channel_rule_node(r, p2.nu, h6 * p2.g, false);
}

/* Node k of k_n on [s0, s1] Hz (t0, t1: its ends as fractions of table piece `piece`):
 * its frequency (the ends exactly) and its point with g there. */
static channel_point channel_rule_at(const channel_rule *r, size_t piece, double s0, double s1,
                                     double t0, double t1, size_t k, size_t k_n)
{
    const thz_channel *ch = r->ch;
    bool table = channel_has_response(ch);
    double u = (double)k / (double)(k_n - 1);
    double t = table ? t0 + (t1 - t0) * u : 0.0;
    double h = ch->n_response ? ch->response_hz[piece + 1] - ch->response_hz[piece] : 0.0;
    double nu = k == 0         ? s0
                : k + 1 == k_n ? s1
                : table        ? ch->response_hz[piece] + t * h
                               : s0 + u * (s1 - s0);
    return channel_rule_point(r, piece, nu, t);
}

/* Composite Simpson on [s0, s1] Hz: a part of table piece `piece` (t0, t1 its ends as
 * fractions of the piece; g linear in between) or, for the Gaussian, of its support
 * (piece, t0 and t1 unused). The ends are nodes exactly. Refined (r->s): panel by
 * panel, each split as channel_rule_panel says. */
static void channel_rule_piece(channel_rule *r, size_t piece, double s0, double s1, double t0,
                               double t1)
{
    /* (the 1e-9: a single piece's width in Hz may round a hair above the support's) */
    double p = ceil((double)r->panels * (s1 - s0) / r->width_hz - 1e-9);
    size_t k_n = 2 * (p < 1.0 ? 1 : (size_t)p) + 1;
    if (r->s) {
        for (size_t k = 0; k + 1 < k_n; k += 2)
            channel_rule_panel(r, piece, channel_rule_at(r, piece, s0, s1, t0, t1, k, k_n),
                               channel_rule_at(r, piece, s0, s1, t0, t1, k + 1, k_n),
                               channel_rule_at(r, piece, s0, s1, t0, t1, k + 2, k_n), r->tol, 0);
        return;
    }
    if (!r->f) {
        r->m += k_n;
        return;
    }
    bool table = channel_has_response(r->ch);
    double h = table ? r->ch->response_hz[piece + 1] - r->ch->response_hz[piece] : s1 - s0;
    double d = (table ? (t1 - t0) * h : s1 - s0) / (double)(k_n - 1);
    for (size_t k = 0; k < k_n; k++) {
        channel_point q = channel_rule_at(r, piece, s0, s1, t0, t1, k, k_n);
        channel_rule_node(r, q.nu, d / 3.0 * channel_simpson_weight(k, k_n) * q.g, k == 0);
    }
}

/* Knots closer than this (relative) to a piece's end are taken as at it: a piece a
 * rounding wide had nodes that coincide. */
#define CHANNEL_KNOT_GAP 1e-9

/* The pieces of [lo_hz, hi_hz] between the knots inside it (from knot *next on), each
 * given to channel_rule_piece; t_lo, t_hi as there. */
static void channel_rule_span(channel_rule *r, size_t piece, double lo_hz, double hi_hz,
                              double t_lo, double t_hi, const channel_knots *k, size_t *next)
{
    double s0 = lo_hz, t0 = t_lo;
    while (*next < k->used && !(channel_knot_hz(k, *next) > s0))
        (*next)++;
    for (; *next < k->used && channel_knot_hz(k, *next) < hi_hz; (*next)++) {
        double s1 = channel_knot_hz(k, *next);
        if (s1 - s0 <= CHANNEL_KNOT_GAP * s1 || hi_hz - s1 <= CHANNEL_KNOT_GAP * s1)
            continue; /* a kink within 1e-9 of a piece's end is at it: no piece of nothing */
        double t1 = t_lo + (t_hi - t_lo) * (s1 - lo_hz) / (hi_hz - lo_hz);
        channel_rule_piece(r, piece, s0, s1, t0, t1);
        s0 = s1;
        t0 = t1;
    }
    channel_rule_piece(r, piece, s0, hi_hz, t0, t_hi);
}

/* Every piece of the rule: a table's pieces where g > 0, or the Gaussian's nu_c +- 6
 * sigma_c, split at the knots. */
static void channel_rule_pieces(channel_rule *r, const channel_knots *k)
{
    const thz_channel *ch = r->ch;
    size_t next = 0;
    if (!channel_has_response(ch)) {
        double sigma = channel_sigma_hz(ch);
        channel_rule_span(r, 0, ch->center_hz - CHANNEL_QUADRATURE_SIGMAS * sigma,
                          ch->center_hz + CHANNEL_QUADRATURE_SIGMAS * sigma, 0.0, 1.0, k, &next);
        return;
    }
    for (size_t i = 0; i + 1 < ch->n_response; i++) {
        double h, a, b;
        channel_piece(ch, i, &h, &a, &b);
        if (a + b > 0.0)
            channel_rule_span(r, i, ch->response_hz[i], ch->response_hz[i + 1], 0.0, 1.0, k, &next);
    }
}

/* The rule of a table, or of the Gaussian with knots inside its support or a structure
 * to refine by. */
static thz_status channel_quadrature_pieces(channel_quadrature *q, const thz_channel *ch, size_t n,
                                            const channel_knots *k, const channel_structure *s,
                                            thz_error *err)
{
    channel_rule r = {.ch = ch, .panels = n / 2, .s = s && s->m > 0 ? s : NULL};
    if (channel_has_response(ch)) {
        r.width_hz = channel_support_width_hz(ch);
    } else {
        r.panels = (n - 1) / 2;
        r.width_hz = 2.0 * CHANNEL_QUADRATURE_SIGMAS * channel_sigma_hz(ch);
    }
    r.tol = CHANNEL_REFINE_REL_TOL * channel_bandwidth_hz(ch) / (double)r.panels;
    channel_rule_pieces(&r, k);
    size_t count = r.m;
    r.m = 0;
    r.splits = 0;
    r.f = thz_malloc_array(count, sizeof *r.f);
    r.w = thz_malloc_array(count, sizeof *r.w);
    if (!r.f || !r.w) {
        free(r.f);
        free(r.w);
        return thz_error_set(err, THZ_ERR_NOMEM, "channel quadrature: cannot allocate %zu nodes",
                             count);
    }
    channel_rule_pieces(&r, k);
    for (size_t i = 0; i < r.m; i++)
        r.w[i] /= r.sum;
    q->n = r.m;
    q->freq_hz = r.f;
    q->weight = r.w;
    return THZ_OK;
}

/* The Gaussian's rule without knots: n evenly spaced nodes over nu_c +- 6 sigma_c. */
static thz_status channel_quadrature_even(channel_quadrature *q, const thz_channel *ch, size_t n,
                                          thz_error *err)
{
    double *f = thz_malloc_array(n, sizeof *f);
    double *w = thz_malloc_array(n, sizeof *w);
    if (!f || !w) {
        free(f);
        free(w);
        return thz_error_set(err, THZ_ERR_NOMEM, "channel quadrature: cannot allocate %zu nodes",
                             n);
    }
    double sigma = channel_sigma_hz(ch);
    double sum = 0.0;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        double x = channel_node_x(i, n);
        double nu = ch->center_hz + sigma * x;
        if (!(nu > 0.0))
            continue; /* g is defined for nu > 0 only (wide channels reach below 0) */
        f[m] = nu;
        w[m] = channel_simpson_weight(i, n) * exp(-0.5 * x * x);
        sum += w[m];
        m++;
    }
    for (size_t i = 0; i < m; i++)
        w[i] /= sum;
    q->n = m;
    q->freq_hz = f;
    q->weight = w;
    q->even = true;
    return THZ_OK;
}

/* n as the rules use it: at least 3, odd for the Gaussian. */
static size_t channel_rule_nodes(const thz_channel *ch, size_t n)
{
    if (n < 3)
        n = 3;
    if (!channel_has_response(ch) && n % 2 == 0)
        n++; /* composite Simpson needs an odd node count */
    return n;
}

thz_status channel_quadrature_init_knots(channel_quadrature *q, const thz_channel *ch, size_t n,
                                         const double *knots, size_t n_knots,
                                         const channel_structure *s, thz_error *err)
{
    q->n = 0;
    q->freq_hz = NULL;
    q->weight = NULL;
    q->even = false;
    n = channel_rule_nodes(ch, n);
    double lo, hi;
    channel_support_hz(ch, CHANNEL_QUADRATURE_SIGMAS, &lo, &hi);
    channel_knots k = channel_knots_inside(knots, n_knots, lo, hi);
    if (s && s->m > CHANNEL_STRUCTURE_MAX)
        return thz_error_set(err, THZ_ERR_INTERNAL, "channel quadrature: %zu test functions", s->m);
    if (!channel_has_response(ch) && k.used == 0 && !(s && s->m > 0))
        return channel_quadrature_even(q, ch, n, err);
    return channel_quadrature_pieces(q, ch, n, &k, s, err);
}

thz_status channel_quadrature_init(channel_quadrature *q, const thz_channel *ch, size_t n,
                                   thz_error *err)
{
    return channel_quadrature_init_knots(q, ch, n, NULL, 0, NULL, err);
}

size_t channel_quadrature_max_nodes(const thz_channel *ch, size_t n, size_t n_knots, bool refined)
{
    n = channel_rule_nodes(ch, n);
    size_t k = n_knots < CHANNEL_QUADRATURE_MAX_KNOTS ? n_knots : CHANNEL_QUADRATURE_MAX_KNOTS;
    if (!channel_has_response(ch) && k == 0 && !refined)
        return n;
    /* each piece: 2 p + 1 nodes, p <= its share of the panels + 1; each split: 2 more */
    size_t pieces = k + (channel_has_response(ch) ? ch->n_response - 1 : 1);
    return 2 * (n / 2 + pieces) + pieces + (refined ? 2 * CHANNEL_QUADRATURE_MAX_SPLITS : 0);
}

void channel_quadrature_fini(channel_quadrature *q)
{
    if (!q)
        return;
    free(q->freq_hz);
    free(q->weight);
    q->n = 0;
    q->freq_hz = NULL;
    q->weight = NULL;
}

/* Adaptive refinement of the band mean: a Simpson panel whose halves disagree with it
 * by more than its share of the tolerance is split, so that lines narrower than the
 * base grid's node spacing (kinks of tabulated spectra) are integrated to ~1e-10 of
 * the band mean instead of the ~3 % a fixed 401-node rule gives for a line of width
 * sigma/10. Numerator and denominator use the same nodes, so constants stay exact. */
#define CHANNEL_ADAPT_REL_TOL 1e-10
#define CHANNEL_ADAPT_MAX_DEPTH 40

typedef struct channel_adapt {
    const thz_channel *ch;
    double sigma_hz; /* the Gaussian's; 0 for a table, whose x is the frequency in Hz */
    double (*f)(double freq_hz, void *ctx);
    void *ctx;
    double num, den; /* accumulated int g f dx and int g dx (x in sigma units) */
} channel_adapt;

/* g(x) f(nu(x)) and g(x) at x sigma from the centre (a table: at x Hz); 0 for nu <= 0
 * and where a table's g is 0. */
static void channel_adapt_eval(const channel_adapt *a, double x, double *gf, double *g)
{
    if (a->sigma_hz == 0.0) {
        *g = channel_response(a->ch, x);
        *gf = *g > 0.0 ? *g * a->f(x, a->ctx) : 0.0;
        return;
    }
    double nu = a->ch->center_hz + a->sigma_hz * x;
    if (!(nu > 0.0)) {
        *gf = 0.0;
        *g = 0.0;
        return;
    }
    *g = exp(-0.5 * x * x);
    *gf = *g * a->f(nu, a->ctx);
}

/* Panel [x0, x2] with values at its ends and midpoint; s_num its Simpson estimate of
 * int g f. */
static void channel_adapt_panel(channel_adapt *a, double x0, double x2, const double fv[3],
                                const double gv[3], double s_num, double tol, int depth)
{
    double x1 = 0.5 * (x0 + x2);
    double xl = 0.5 * (x0 + x1), xr = 0.5 * (x1 + x2);
    double fl, gl, fr, gr;
    channel_adapt_eval(a, xl, &fl, &gl);
    channel_adapt_eval(a, xr, &fr, &gr);
    double h6 = (x1 - x0) / 6.0;
    double ln = h6 * (fv[0] + 4.0 * fl + fv[1]), rn = h6 * (fv[1] + 4.0 * fr + fv[2]);
    double ld = h6 * (gv[0] + 4.0 * gl + gv[1]), rd = h6 * (gv[1] + 4.0 * gr + gv[2]);
    if (depth >= CHANNEL_ADAPT_MAX_DEPTH || fabs(ln + rn - s_num) <= 15.0 * tol) {
        a->num += ln + rn;
        a->den += ld + rd;
        return;
    }
    const double lf[3] = {fv[0], fl, fv[1]}, lg[3] = {gv[0], gl, gv[1]};
    const double rf[3] = {fv[1], fr, fv[2]}, rg[3] = {gv[1], gr, gv[2]};
    channel_adapt_panel(a, x0, x1, lf, lg, ln, 0.5 * tol, depth + 1);
    channel_adapt_panel(a, x1, x2, rf, rg, rn, 0.5 * tol, depth + 1);
}

/* A table's base panels (as the fixed rule's for CHANNEL_QUADRATURE_NODES, without knots),
 * each refined adaptively. Two passes: the first sums |g f| for the tolerance's scale
 * (no allocation; f is evaluated twice on the base nodes). */
static double channel_band_mean_table(const thz_channel *ch, double (*f)(double freq_hz, void *ctx),
                                      void *ctx)
{
    channel_adapt a = {ch, 0.0, f, ctx, 0.0, 0.0};
    const size_t panels = (CHANNEL_QUADRATURE_NODES - 1) / 2;
    double scale = 0.0, tol = 0.0, width = channel_support_width_hz(ch);
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i + 1 < ch->n_response; i++) {
            size_t p = channel_piece_panels(ch, i, panels, width);
            double lo = ch->response_hz[i], hi = ch->response_hz[i + 1];
            for (size_t j = 0; j < p; j++) {
                double x0 = lo + (hi - lo) * (double)j / (double)p;
                double x2 = j + 1 == p ? hi : lo + (hi - lo) * (double)(j + 1) / (double)p;
                double fv[3], gv[3];
                channel_adapt_eval(&a, x0, &fv[0], &gv[0]);
                channel_adapt_eval(&a, 0.5 * (x0 + x2), &fv[1], &gv[1]);
                channel_adapt_eval(&a, x2, &fv[2], &gv[2]);
                double s_num = (x2 - x0) / 6.0 * (fv[0] + 4.0 * fv[1] + fv[2]);
                if (pass == 0) {
                    scale += (x2 - x0) / 6.0 * (fabs(fv[0]) + 4.0 * fabs(fv[1]) + fabs(fv[2]));
                    total++;
                } else {
                    channel_adapt_panel(&a, x0, x2, fv, gv, s_num, tol, 0);
                }
            }
        }
        tol = CHANNEL_ADAPT_REL_TOL * scale / (double)(total ? total : 1);
    }
    return a.den > 0.0 ? a.num / a.den : 0.0;
}

double channel_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx), void *ctx)
{
    if (channel_has_response(ch))
        return channel_band_mean_table(ch, f, ctx);
    /* The base grid of CHANNEL_QUADRATURE_NODES nodes (as channel_quadrature_init),
     * kept on the stack: no allocation. */
    enum { n = CHANNEL_QUADRATURE_NODES };
    double fv[n], gv[n];
    channel_adapt a = {ch, channel_sigma_hz(ch), f, ctx, 0.0, 0.0};
    double scale = 0.0;
    for (size_t i = 0; i < n; i++) {
        channel_adapt_eval(&a, channel_node_x(i, n), &fv[i], &gv[i]);
        scale += channel_simpson_weight(i, n) * fabs(fv[i]);
    }
    double h = channel_node_x(1, n) - channel_node_x(0, n);
    scale *= h / 3.0;
    const size_t panels = (n - 1) / 2;
    double tol = CHANNEL_ADAPT_REL_TOL * scale / (double)panels;
    for (size_t j = 0; j < panels; j++) {
        size_t i = 2 * j;
        double x0 = channel_node_x(i, n), x2 = channel_node_x(i + 2, n);
        double s_num = (x2 - x0) / 6.0 * (fv[i] + 4.0 * fv[i + 1] + fv[i + 2]);
        channel_adapt_panel(&a, x0, x2, &fv[i], &gv[i], s_num, tol, 0);
    }
    return a.den > 0.0 ? a.num / a.den : 0.0;
}
