/* Figures drawn with PLplot's pngcairo device: the per-channel preview S.band-NN.png
 * (an image with a perceptual colour map and a labelled colour bar), classify's
 * S.class.png (classes in their colours, with a legend), S.spectra.png
 * (one line per object against frequency, as the paper's Fig. 6), and the
 * attenuation spectrum of `thzmap atmosphere --plot` (log axis, shaded channels).
 *
 * Every figure (and the device check) is drawn in a child process (core/child.h;
 * plot_draw.h says why), one at a time or a batch by a few at once. PLplot's global
 * state therefore lives in the children only, and figures may be drawn from several
 * threads at once; code outside io/plot*.c must not call PLplot itself. A child that
 * fails, dies or takes too long (then killed) gives an error "... while plotting PATH
 * ..." (THZ_ERR_IO).
 */
#ifndef THZ_IO_PLOT_H
#define THZ_IO_PLOT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/cancel.h"
#include "core/error.h"

/* THZ_OK if PLplot has the pngcairo device; otherwise THZ_ERR_IO with a message
 * naming the missing package. (PLplot asked for a missing device exits the process,
 * so every figure checks this first, in its child.) Checked in a child process once per
 * process and PLPLOT_DRV_DIR: a success is remembered (a failure is not), so a batch's
 * frames and a library caller's runs do not start a child each for it. */
thz_status plot_check_device(thz_error *err);

/* Text: titles and curve names are shown as given ('#', PLplot's escape character,
 * is doubled); axis and colour-bar labels are PLplot text, so the caller may use its
 * escapes such as "T#db#u" for a subscript b. */

/* An image of values (row 0 at the top, column 0 at the left; NaN drawn as the
 * lowest colour) with a colour bar spanning the finite values, labelled
 * `value_label` (which carries the unit), axes in pixels, and `title` on top. */
thz_status plot_image(const char *path, const float *values, uint32_t columns, uint32_t rows,
                      const char *title, const char *value_label, thz_error *err);

/* A map of classes: classes[row * columns + column] is pixel (column, row)'s class, 0 to
 * n_classes - 1, or -1 where nothing is hit (row 0 at the top). Class k is drawn in
 * colour rgb[k] (sRGB), nothing hit in black, beside a legend naming every class (and
 * "nothing hit" when a pixel is -1) with its colour; axes in pixels, `title` on top.
 * 960 pixels wide, high as plot_image's figure of the same image; an image larger than
 * the figure shows is drawn from the first (top-left) pixel of each block. */
thz_status plot_classes(const char *path, const int32_t *classes, uint32_t columns, uint32_t rows,
                        size_t n_classes, const char *const *names, const unsigned char (*rgb)[3],
                        const char *title, thz_error *err);

/* Line plot: n_lines curves over n_x abscissae x (in `x_label` units), curve i at
 * y[i * n_x + j]; non-finite points are left out. A legend names each curve. A title
 * too wide for the figure is wrapped at spaces onto more lines (the plot shrinks from
 * the top to make room). */
thz_status plot_lines(const char *path, size_t n_x, const double *x, size_t n_lines,
                      const char *const *names, const double *y, const char *title,
                      const char *x_label, const char *y_label, thz_error *err);
/* The same for x of whole numbers (a count): ticks at whole numbers only. */
thz_status plot_lines_whole_x(const char *path, size_t n_x, const double *x, size_t n_lines,
                              const char *const *names, const double *y, const char *title,
                              const char *x_label, const char *y_label, thz_error *err);

/* A curve of plot_attenuation: n_x values y over the figure's abscissae, drawn in
 * colour rgb with line width `width` (1 = thin), dashed or solid. `name` is PLplot
 * text, like the axis labels (e.g. "H#d2#uO" for a subscript 2). */
typedef struct plot_curve {
    const char *name;
    const double *y;
    unsigned char rgb[3];
    double width;
    bool dashed;
} plot_curve;

/* A frequency band of plot_attenuation, in x units: shaded from lo to hi, a dashed
 * line at centre, and `name` (shown as given) written upwards beside it, inside the
 * plot (on the line's right for a band at the left end). */
typedef struct plot_band {
    const char *name;
    double lo, centre, hi;
} plot_band;

enum { PLOT_MAX_CURVES = 12 };

/* Curves (at most PLOT_MAX_CURVES) of attenuation against x on a logarithmic y axis of nine decades
 * whose top clears the largest value by two decades for the legend (top left, naming every curve);
 * values <= 0 or below the axis are drawn at its bottom. Bands whose centre lies outside the x
 * range are left out. 1200 x 750 pixels. */
thz_status plot_attenuation(const char *path, size_t n_x, const double *x, size_t n_curves,
                            const plot_curve *curves, size_t n_bands, const plot_band *bands,
                            const char *title, const char *x_label, const char *y_label,
                            thz_error *err);

/* A batch of figures drawn by a few child processes at once: plot_image's and
 * plot_lines' figures, added in order (the batch copies every text and a line plot's
 * arrays; an image's values must stay valid until plot_batch_run), then drawn by up to
 * `processes` children (0: one per online processor), and by no more than one per
 * PLOT_FIGURES_PER_CHILD figures, each drawing a contiguous share in order: one process
 * start and one PLplot, cairo and fontconfig set-up per child rather than per figure,
 * and the shares side by side. Returns THZ_OK or the failure of the first figure that
 * failed, in the order they were added (a child stops at its first); the figures before
 * it are written. */
/* A child's set-up (fork, PLplot's cairo driver and its libraries loaded, fontconfig)
 * costs about two figures' drawing (a 4 x 3 sensor's three figures: 0.17 s of CPU in one
 * child, 0.23 s in two, the same wall time; the paper's scene's seven: 0.27 s of wall
 * time in one child, 0.18-0.20 s in two). */
#define PLOT_FIGURES_PER_CHILD 3u
typedef struct plot_batch plot_batch;

plot_batch *plot_batch_create(void); /* NULL: out of memory */
void plot_batch_destroy(plot_batch *b);
thz_status plot_batch_image(plot_batch *b, const char *path, const float *values, uint32_t columns,
                            uint32_t rows, const char *title, const char *value_label,
                            thz_error *err);
thz_status plot_batch_lines(plot_batch *b, const char *path, size_t n_x, const double *x,
                            size_t n_lines, const char *const *names, const double *y,
                            const char *title, const char *x_label, const char *y_label,
                            thz_error *err);
/* `cancel` (may be NULL) stops the drawing: THZ_ERR_CANCELLED, the children killed. */
thz_status plot_batch_run(plot_batch *b, int processes, const cancel_check *cancel, thz_error *err);

#endif
