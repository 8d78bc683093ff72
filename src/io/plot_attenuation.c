/* The attenuation spectrum of `thzmap atmosphere --plot`, drawn in a child: curves on a
 * logarithmic axis, the channels shaded with their names written upwards beside them.
 * plot.c starts and ends the figure (plot_draw.h).
 */
#include "io/plot_draw.h"

#include <math.h>
#include <stdlib.h>

#include <plplot/plplot.h>

#include "core/alloc.h"

/* log10 of a value for a logarithmic axis, floored at the axis bottom. */
static double plot_log(double v, double floor_log)
{
    return v > 0.0 ? fmax(log10(v), floor_log) : floor_log;
}

thz_status plot_attenuation_draw(const char *path, size_t n_x, const double *x, size_t n_curves,
                                 const plot_curve *curves, size_t n_bands, const plot_band *bands,
                                 const char *title, const char *x_label, const char *y_label,
                                 thz_error *err)
{
    if (n_x == 0 || n_curves == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: nothing to plot", path);
    thz_status status = THZ_OK;
    PLFLT *py = thz_malloc_array(n_x, sizeof *py);
    const char **texts = thz_calloc(n_curves, sizeof *texts);
    const char **symbols = thz_calloc(n_curves, sizeof *symbols);
    PLINT *opts = thz_calloc(n_curves, sizeof *opts);
    PLINT *colors = thz_calloc(n_curves, sizeof *colors);
    PLINT *styles = thz_calloc(n_curves, sizeof *styles);
    PLINT *zeros = thz_calloc(n_curves, sizeof *zeros);
    PLFLT *widths = thz_calloc(n_curves, sizeof *widths);
    PLFLT *zeros_f = thz_calloc(n_curves, sizeof *zeros_f);
    if (!py || !texts || !symbols || !opts || !colors || !styles || !zeros || !widths || !zeros_f) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
        goto cleanup;
    }
    /* cmap0 (16 colours): 0 background, 1 text and axes, 2 band shading, 3 band
     * lines, 4.. the curves */
    enum { BAND_FILL = 2, BAND_LINE = 3, FIRST_CURVE = 4 };
    if (n_curves > PLOT_MAX_CURVES) {
        status =
            thz_error_set(err, THZ_ERR_INTERNAL, "%s: more than %d curves", path, PLOT_MAX_CURVES);
        goto cleanup;
    }
    double top = -INFINITY;
    for (size_t c = 0; c < n_curves; c++)
        for (size_t i = 0; i < n_x; i++)
            top = fmax(top, plot_log(curves[c].y[i], -300.0));
    if (!isfinite(top) || top < -5.0)
        top = 0.0;
    double y_hi = ceil(top + 0.3) + 2.0, y_lo = y_hi - 9.0;
    double x_lo = x[0], x_hi = x[n_x - 1];
    if (!(x_hi > x_lo))
        x_hi = x_lo + 1e-3;
    for (size_t c = 0; c < n_curves; c++) {
        texts[c] = curves[c].name ? curves[c].name : "";
        symbols[c] = "";
        opts[c] = PL_LEGEND_LINE;
        colors[c] = FIRST_CURVE + (PLINT)c;
        styles[c] = curves[c].dashed ? 2 : 1;
        widths[c] = curves[c].width;
    }
    char t_title[PLOT_TEXT], t_band[PLOT_TEXT];
    plot_escape(t_title, sizeof t_title, title);

    status = plot_begin(path, 1200, 750, err);
    if (status == THZ_OK) {
        plscol0a(BAND_FILL, 200, 200, 200, 0.35);
        plscol0(BAND_LINE, 150, 150, 150);
        for (size_t c = 0; c < n_curves; c++)
            plscol0(FIRST_CURVE + (PLINT)c, curves[c].rgb[0], curves[c].rgb[1], curves[c].rgb[2]);
        plschr(0.0, 1.1);
        plcol0(1);
        plvsta();
        plwind(x_lo, x_hi, y_lo, y_hi);
        plbox("bcnst", 0.0, 0, "bcnstvl", 0.0, 0);
        pllab(x_label, y_label, t_title);
        for (size_t b = 0; b < n_bands; b++) {
            double fc = bands[b].centre;
            if (!(fc >= x_lo && fc <= x_hi))
                continue;
            PLFLT bx[4] = {bands[b].lo, bands[b].hi, bands[b].hi, bands[b].lo};
            PLFLT by[4] = {y_lo, y_lo, y_hi, y_hi};
            plcol0(BAND_FILL);
            plfill(4, bx, by);
            plcol0(BAND_LINE);
            pllsty(2);
            plwidth(1.0);
            PLFLT lx[2] = {fc, fc}, ly[2] = {y_lo, y_hi};
            plline(2, lx, ly);
            plcol0(1);
            plschr(0.0, 0.8);
            plot_escape(t_band, sizeof t_band, bands[b].name ? bands[b].name : "");
            /* Written upwards, centred on its reference point across the text: beside the
             * line on its left, or on its right where the left would leave the plot, and
             * never over either edge's ticks (a band at an end of the range). */
            PLFLT def_mm, ht_mm, vx0, vx1, vy0, vy1, sx0, sx1, sy0, sy1;
            plgchr(&def_mm, &ht_mm);
            plgvpd(&vx0, &vx1, &vy0, &vy1);
            plgspa(&sx0, &sx1, &sy0, &sy1);
            double half = 0.6 * ht_mm * (x_hi - x_lo) / ((vx1 - vx0) * (sx1 - sx0));
            double tx = fc - half - 0.002 * (x_hi - x_lo);
            if (tx - half < x_lo)
                tx = fc + half + 0.002 * (x_hi - x_lo);
            tx = fmin(fmax(tx, x_lo + 2.0 * half), x_hi - 2.0 * half); /* clear of the ticks */
            plptex(tx, y_lo + 0.15, 0.0, 1.0, 0.0, t_band);
            plschr(0.0, 1.1);
        }
        for (size_t c = 0; c < n_curves; c++) {
            for (size_t i = 0; i < n_x; i++)
                py[i] = plot_log(curves[c].y[i], y_lo);
            plcol0(colors[c]);
            pllsty(styles[c]);
            plwidth(widths[c]);
            plline((PLINT)n_x, x, py);
        }
        pllsty(1);
        plwidth(1.0);
        plcol0(1);
        PLFLT legend_w, legend_h;
        pllegend(&legend_w, &legend_h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.02, 0.02, 0.1, 0, 1, 1,
                 3, 2, (PLINT)n_curves, opts, 1.0, 0.75, 2.0, 1.0, colors, (PLCHAR_MATRIX)texts,
                 zeros, zeros, zeros_f, zeros_f, colors, styles, widths, zeros, zeros_f, zeros,
                 (PLCHAR_MATRIX)symbols);
        status = plot_end(path, err);
    }
cleanup:
    free(py);
    free(texts);
    free(symbols);
    free(opts);
    free(colors);
    free(styles);
    free(zeros);
    free(widths);
    free(zeros_f);
    return status;
}
