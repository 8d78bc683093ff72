/* Figures drawn with PLplot's pngcairo device: the per-channel preview S.band-NN.png
 * (an image with a perceptual colour map and a labelled colour bar) and S.spectra.png
 * (one line per object against frequency, as the paper's Fig. 6).
 *
 * Thread safety: PLplot keeps global state and can draw one figure at a time, so
 * every function here holds one process-wide mutex (the module's only static) while
 * it talks to PLplot. Figures drawn from several threads are therefore serialised;
 * code outside this file must not call PLplot itself.
 */
#ifndef THZ_IO_PLOT_H
#define THZ_IO_PLOT_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* THZ_OK if PLplot has the pngcairo device; otherwise THZ_ERR_IO with a message
 * naming the missing package. (PLplot asked for a missing device exits the process,
 * so every figure checks this first.) */
thz_status plot_check_device(thz_error *err);

/* Text: titles and curve names are shown as given ('#', PLplot's escape character,
 * is doubled); axis and colour-bar labels are PLplot text, so the caller may use its
 * escapes such as "T#db#u" for a subscript b. */

/* An image of values (row 0 at the top, column 0 at the left; NaN drawn as the
 * lowest colour) with a colour bar spanning the finite values, labelled
 * `value_label` (which carries the unit), axes in pixels, and `title` on top. */
thz_status plot_image(const char *path, const float *values, uint32_t columns, uint32_t rows,
                      const char *title, const char *value_label, thz_error *err);

/* Line plot: n_lines curves over n_x abscissae x (in `x_label` units), curve i at
 * y[i * n_x + j]; non-finite points are left out. A legend names each curve. */
thz_status plot_lines(const char *path, size_t n_x, const double *x, size_t n_lines,
                      const char *const *names, const double *y, const char *title,
                      const char *x_label, const char *y_label, thz_error *err);

#endif
