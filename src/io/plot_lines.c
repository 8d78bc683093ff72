/* PLplot line plots (plot_lines: per-object spectra against frequency, and any curves
 * over a count), drawn in a child: the curves with a marker at each point, a legend, y
 * labels with the digits their ticks need, and a title wrapped to the figure's width.
 * plot.c starts and ends the figure (plot_draw.h).
 */
#include "io/plot_draw.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot/plplot.h>

#include "core/alloc.h"

/* A filled circle (U+25CF) marks each data point; cairo renders UTF-8 text. */
#define PLOT_MARK "\xe2\x97\x8f"

enum { PLOT_GRID_COLOR = 15 };

/* Distinguishable line colours (a common qualitative palette), cmap0 indices 2..11. */
static const unsigned char plot_lines_palette[10][3] = {
    {31, 119, 180}, {255, 127, 14},  {44, 160, 44},   {214, 39, 40},  {148, 103, 189},
    {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207},
};

enum { PLOT_TITLE_LINES = 8 };

/* The width of PLplot text in mm at character height ht_mm, estimated: PLplot has no
 * public call that measures text (plstrl is internal). The advances are the sans-serif
 * face pngcairo draws with, in ems, measured at the figures' size (an em 1.34 character
 * heights); unlisted bytes take a wide letter's, UTF-8 continuation bytes nothing; 4 %
 * to spare. "##" is one '#' (plot_escape). */
static double plot_text_width_mm(const char *text, double ht_mm)
{
    static const struct {
        const char *chars;
        double em;
    } advances[] = {
        {"ijlIJ'", 0.287},   {"f .,:;/|", 0.335},
        {"rt()-[]!", 0.385}, {"_*\"", 0.478},
        {"csz?", 0.526},     {"kvxyFLT", 0.575},
        {"BKRVXZ", 0.67},    {"ACU", 0.718},
        {"DGHNOQ&", 0.766},  {"w=+<>~^", 0.813},
        {"M", 0.861},        {"m%#", 0.957},
        {"W", 1.005},        {"abdeghnopqu0123456789EPSY{}", 0.622},
    };
    double em = 0.0;
    for (const char *p = text; *p; p++) {
        unsigned char c = (unsigned char)*p;
        if (c == '#' && p[1] == '#')
            p++;
        if ((c & 0xC0) == 0x80)
            continue;
        double a = 0.8;
        for (size_t k = 0; c < 0x80 && k < sizeof advances / sizeof advances[0]; k++)
            if (strchr(advances[k].chars, c)) {
                a = advances[k].em;
                break;
            }
        em += a;
    }
    return 1.04 * 1.34 * ht_mm * em;
}

/* Appends `len` bytes of text to line (PLOT_TEXT bytes), after a space if it is not
 * empty; true if the result fits in max_mm at character height ht_mm (it is only
 * tried, in out). */
static bool plot_line_try(const char *line, const char *text, size_t len, double max_mm,
                          double ht_mm, char out[PLOT_TEXT])
{
    snprintf(out, PLOT_TEXT, "%s%s%.*s", line, line[0] ? " " : "", (int)len, text);
    return plot_text_width_mm(out, ht_mm) <= max_mm;
}

/* Splits title (PLplot text) into at most PLOT_TITLE_LINES lines of at most max_mm each
 * at character height ht_mm: at "; " where a clause does not fit on the line, else at
 * spaces (a word longer than a line gets a line of its own; the last line takes what is
 * left). Returns the number of lines, each in lines[i] (PLOT_TEXT bytes). */
static size_t plot_wrap_title(const char *title, double max_mm, double ht_mm,
                              char lines[][PLOT_TEXT])
{
    size_t n = 0;
    lines[0][0] = '\0';
    bool clause_start = true;
    char candidate[PLOT_TEXT];
    for (const char *p = title; *p;) {
        while (*p == ' ')
            p++;
        if (!*p)
            break;
        size_t len = strcspn(p, " ");
        bool room = n + 1 < PLOT_TITLE_LINES;
        if (clause_start && lines[n][0] && room) { /* the whole clause, or a new line */
            const char *end = strchr(p, ';');
            size_t clause = end ? (size_t)(end - p) + 1 : strlen(p);
            if (!plot_line_try(lines[n], p, clause, max_mm, ht_mm, candidate))
                lines[++n][0] = '\0';
        }
        if (!plot_line_try(lines[n], p, len, max_mm, ht_mm, candidate) && lines[n][0] &&
            n + 1 < PLOT_TITLE_LINES) {
            lines[++n][0] = '\0';
            plot_line_try(lines[n], p, len, max_mm, ht_mm, candidate);
        }
        snprintf(lines[n], PLOT_TEXT, "%s", candidate);
        clause_start = p[len - 1] == ';';
        p += len;
    }
    return n + 1;
}

/* The title (PLplot text) above a viewport of normalised x vx0..vx1 whose top is to be at
 * vy1: wrapped to the subpage's width, each line centred over the viewport unless that
 * would cut it at the page's edge (then moved in). Returns the viewport's top lowered as
 * far as the lines need. Call before plvpor; draws nothing (plot_draw_title does). */
static double plot_title_layout(const char *title, double vy1, char lines[][PLOT_TEXT],
                                size_t *n_lines)
{
    PLFLT sx0, sx1, sy0, sy1, def_mm, ht_mm;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    plgchr(&def_mm, &ht_mm);
    *n_lines = plot_wrap_title(title, (sx1 - sx0) - 2.0 * ht_mm, ht_mm, lines);
    /* lines 1.5 character heights apart, the lowest 2 above the viewport (as pllab's),
     * the highest's top a character height below the figure's */
    double need = (3.5 + 1.5 * (double)(*n_lines - 1)) * ht_mm / (sy1 - sy0);
    return fmin(vy1, 1.0 - need);
}

static void plot_draw_title(char lines[][PLOT_TEXT], size_t n_lines, double vx0, double vx1)
{
    PLFLT sx0, sx1, sy0, sy1, def_mm, ht_mm;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    plgchr(&def_mm, &ht_mm);
    double w = sx1 - sx0, margin = ht_mm;
    for (size_t i = 0; i < n_lines; i++) {
        double len = plot_text_width_mm(lines[i], ht_mm), centre = 0.5 * (vx0 + vx1) * w;
        if (len <= w - 2.0 * margin)
            centre = fmin(fmax(centre, 0.5 * len + margin), w - 0.5 * len - margin);
        else
            centre = 0.5 * w;
        double pos = (centre / w - vx0) / (vx1 - vx0);
        plmtex("t", 2.0 + 1.5 * (double)(n_lines - 1 - i), pos, 0.5, lines[i]);
    }
}

int plot_label_digits(double lo, double hi)
{
    double mag = fmax(fabs(lo), fabs(hi)), span = hi - lo;
    if (!(span > 0.0) || !(mag > 0.0))
        return 4;
    double d = ceil(log10(mag / (span / 8.0))) + 1.0;
    return d > 4.0 ? (d < 12.0 ? (int)d : 12) : 4;
}

double plot_whole_tick(double span)
{
    /* about 4 to 10 labelled ticks, at 1, 2 or 5 times a power of ten, never below 1 */
    double raw = span / 8.0, decade = raw > 1.0 ? pow(10.0, floor(log10(raw))) : 1.0;
    double tick = decade;
    if (raw > 5.0 * decade)
        tick = 10.0 * decade;
    else if (raw > 2.0 * decade)
        tick = 5.0 * decade;
    else if (raw > decade)
        tick = 2.0 * decade;
    return tick;
}

thz_status plot_lines_draw(const char *path, size_t n_x, const double *x, size_t n_lines,
                           const char *const *names, const double *y, const char *title,
                           const char *x_label, const char *y_label, bool whole_x, thz_error *err)
{
    thz_status status = THZ_OK;
    PLFLT *px = thz_malloc_array(n_x ? n_x : 1, sizeof *px);
    PLFLT *py = thz_malloc_array(n_x ? n_x : 1, sizeof *py);
    size_t n_legend = n_lines ? n_lines : 1;
    char **texts = thz_calloc(n_legend, sizeof *texts);
    PLINT *opts = thz_calloc(n_legend, sizeof *opts);
    PLINT *colors = thz_calloc(n_legend, sizeof *colors);
    PLINT *text_colors = thz_calloc(n_legend, sizeof *text_colors);
    PLINT *styles = thz_calloc(n_legend, sizeof *styles);
    PLFLT *widths = thz_calloc(n_legend, sizeof *widths);
    PLFLT *symbol_scales = thz_calloc(n_legend, sizeof *symbol_scales);
    PLINT *symbol_numbers = thz_calloc(n_legend, sizeof *symbol_numbers);
    const char **symbols = thz_calloc(n_legend, sizeof *symbols);
    if (!px || !py || !texts || !opts || !colors || !text_colors || !styles || !widths ||
        !symbol_scales || !symbol_numbers || !symbols) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
        goto cleanup;
    }
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t j = 0; j < n_x; j++) {
        if (isfinite(x[j])) {
            xmin = fmin(xmin, x[j]);
            xmax = fmax(xmax, x[j]);
        }
    }
    for (size_t i = 0; i < n_lines * n_x; i++) {
        if (isfinite(y[i])) {
            ymin = fmin(ymin, y[i]);
            ymax = fmax(ymax, y[i]);
        }
    }
    if (!(xmin <= xmax)) {
        xmin = 0.0;
        xmax = 1.0;
    }
    if (!(ymin <= ymax)) {
        ymin = 0.0;
        ymax = 1.0;
    }
    double xpad = xmax > xmin ? 0.05 * (xmax - xmin) : fmax(0.05 * fabs(xmax), 0.01);
    double ypad = ymax > ymin ? 0.08 * (ymax - ymin) : fmax(0.05 * fabs(ymax), 0.01);
    for (size_t i = 0; i < n_lines; i++) {
        texts[i] = malloc(PLOT_TEXT);
        if (!texts[i]) {
            status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
            goto cleanup;
        }
        plot_escape(texts[i], PLOT_TEXT, names[i] ? names[i] : "");
        opts[i] = PL_LEGEND_LINE | PL_LEGEND_SYMBOL;
        colors[i] = 2 + (PLINT)(i % 10);
        text_colors[i] = 1;
        styles[i] = 1 + (PLINT)((i / 10) % 8);
        widths[i] = 2.0;
        symbol_scales[i] = 0.6;
        symbol_numbers[i] = 1;
        symbols[i] = PLOT_MARK; /* a filled circle marks each channel */
    }
    char t_title[PLOT_TEXT], title_lines[PLOT_TITLE_LINES][PLOT_TEXT];
    plot_escape(t_title, sizeof t_title, title);
    /* whole x values (counts): ticks at whole numbers only, none at 1.5 */
    double x_tick = whole_x ? plot_whole_tick(xmax - xmin + 2.0 * xpad) : 0.0;
    PLINT x_sub = whole_x ? (x_tick <= 10.0 ? (PLINT)x_tick : 2) : 0;

    status = plot_begin(path, 960, 600, err);
    if (status == THZ_OK) {
        for (int i = 0; i < 10; i++)
            plscol0(2 + i, plot_lines_palette[i][0], plot_lines_palette[i][1],
                    plot_lines_palette[i][2]);
        plscol0(PLOT_GRID_COLOR, 210, 210, 210);
        size_t n_title = 0;
        double top = plot_title_layout(t_title, 0.90, title_lines, &n_title);
        /* longer y labels: the axis title further out, the viewport narrower to keep it
         * on the figure (a label's character is about 0.76 character heights wide, a
         * character height 1.6 % of the figure's width) */
        int y_digits = plot_label_digits(ymin - ypad, ymax + ypad);
        double y_title = y_digits > 4 ? 2.0 + 0.76 * (y_digits + 1 + (ymin - ypad < 0.0)) : 5.0;
        double left = 0.10 + 0.0163 * fmax(y_title - 5.0, 0.0);
        plvpor(left, 0.66, 0.12, top);
        plwind(xmin - xpad, xmax + xpad, ymin - ypad, ymax + ypad);
        if (y_digits > 4)
            plsyax(y_digits, 0);
        plcol0(PLOT_GRID_COLOR);
        plbox("g", x_tick, x_sub, "g", 0.0, 0);
        plcol0(1);
        plbox("bcnst", x_tick, x_sub, "bcnstv", 0.0, 0);
        pllab(x_label, "", "");
        plmtex("l", y_title, 0.5, 0.5, y_label);
        plot_draw_title(title_lines, n_title, left, 0.66);
        for (size_t i = 0; i < n_lines; i++) {
            PLINT m = 0;
            for (size_t j = 0; j < n_x; j++) {
                if (isfinite(x[j]) && isfinite(y[i * n_x + j])) {
                    px[m] = x[j];
                    py[m] = y[i * n_x + j];
                    m++;
                }
            }
            plcol0(colors[i]);
            pllsty(styles[i]);
            plwidth(widths[i]);
            if (m > 1)
                plline(m, px, py);
            if (m > 0) {
                plschr(0.0, 0.6);
                plstring(m, px, py, PLOT_MARK);
                plschr(0.0, 1.0);
            }
        }
        pllsty(1);
        plwidth(1.0);
        plcol0(1);
        if (n_lines > 0) {
            PLFLT legend_w, legend_h;
            pllegend(&legend_w, &legend_h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                     PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.02, 0.0,
                     0.06, 0, 1, 1, 0, 0, (PLINT)n_lines, opts, 1.0, 0.8, 1.6, 0.0, text_colors,
                     (PLCHAR_MATRIX)texts, NULL, NULL, NULL, NULL, colors, styles, widths, colors,
                     symbol_scales, symbol_numbers, (PLCHAR_MATRIX)symbols);
        } else {
            plptex(0.5 * (xmin + xmax), 0.5 * (ymin + ymax), 1.0, 0.0, 0.5, "no object in view");
        }
        status = plot_end(path, err);
    }
cleanup:
    if (texts)
        for (size_t i = 0; i < n_lines; i++)
            free(texts[i]);
    free(texts);
    free(opts);
    free(colors);
    free(text_colors);
    free(styles);
    free(widths);
    free(symbol_scales);
    free(symbol_numbers);
    free(symbols);
    free(px);
    free(py);
    return status;
}
