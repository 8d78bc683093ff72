/* The figures of io/plot.h as drawn, in the process that calls these (plot.c: the
 * device check, a figure's start and end, the image preview; plot_lines.c: the line plots
 * and their wrapped titles; plot_attenuation.c: the attenuation spectrum). Only a
 * child process may call them (plot_child.c starts it): PLplot, and the cairo,
 * fontconfig and GLib it draws with, end the process (exit() or abort()) or deadlock
 * when an allocation fails, and PLplot also exits on some errors, so PLplot never runs
 * in the caller's process, which may hold a run's staging files. Each figure is one
 * plinit ... plend session of PLplot's global state, in whichever child draws it.
 */
#ifndef THZ_IO_PLOT_DRAW_H
#define THZ_IO_PLOT_DRAW_H

#include <stddef.h>
#include <stdint.h>

#include "io/plot.h"

/* How long a figure may take before its child is killed (a deadlocked GLib): far
 * beyond a normal figure (well under 1 s; base_s, 60 s), plus time for the cells of a
 * large image. */
double plot_timeout_s(size_t cells);
/* Sets that limit's base (60 s) for the figures drawn from now on; for tests only (a
 * sanitizer build's known hang, test_plot_batch.c), before any thread draws. */
void plot_set_timeout_base_s(double base_s);

/* plot_check_device's check, here (a child_fn: arg unused). */
thz_status plot_check_device_here(void *arg, thz_error *err);

/* An image's colour bar: lo to hi, the 1st to the 99th percentile of its finite values
 * (widened when flat), and whether values lie beyond either end (the bar's caps). */
typedef struct plot_range {
    double lo, hi;
    bool clipped_low, clipped_high;
} plot_range;
/* Of n values; finite is scratch for n doubles. */
plot_range plot_colour_range(const float *values, size_t n, double *finite);

/* How an image of columns x rows pixels is drawn (plot_image, plot_classes): cells of
 * f x f pixels, bx x by of them (at most 1024 along the longer side: a larger image is
 * drawn from blocks), in a plot area of the image's aspect (rows / columns: square
 * pixels) on a figure `height` pixels high. */
typedef struct plot_layout {
    uint32_t f;
    size_t bx, by;
    double aspect;
    int height;
} plot_layout;
plot_layout plot_image_layout(uint32_t columns, uint32_t rows);

/* plot_image's, plot_classes', plot_lines' and plot_attenuation's figures, drawn here. */
thz_status plot_image_draw(const char *path, const float *values, uint32_t columns, uint32_t rows,
                           const char *title, const char *value_label, thz_error *err);
thz_status plot_classes_draw(const char *path, const int32_t *classes, uint32_t columns,
                             uint32_t rows, size_t n_classes, const char *const *names,
                             const unsigned char (*rgb)[3], const char *title, thz_error *err);
thz_status plot_lines_draw(const char *path, size_t n_x, const double *x, size_t n_lines,
                           const char *const *names, const double *y, const char *title,
                           const char *x_label, const char *y_label, bool whole_x, thz_error *err);

/* The interval of labelled ticks on an axis of whole numbers spanning `span`: 1, 2, 5,
 * 10, 20, ... (never below 1), for about 4 to 10 ticks. */
double plot_whole_tick(double span);
/* PLplot labels an axis with at most 4 significant digits unless told more (plsyax), so
 * values that differ only in the 5th (300.012 to 300.021 K) got one label at every tick:
 * the digits (4 to 12) that tell apart ticks about (hi - lo) / 8 apart, as
 * plot_whole_tick's are. */
int plot_label_digits(double lo, double hi);
thz_status plot_attenuation_draw(const char *path, size_t n_x, const double *x, size_t n_curves,
                                 const plot_curve *curves, size_t n_bands, const plot_band *bands,
                                 const char *title, const char *x_label, const char *y_label,
                                 thz_error *err);

/* ---- what the figures share (plot.c) ---- */

/* The bytes of a PLplot text: a title, a label, a curve's name. */
enum { PLOT_TEXT = 512 };
/* PLplot treats '#' as its escape character: double it in user text. */
void plot_escape(char *dst, size_t size, const char *src);
/* Starts a figure of width x height pixels into path: checks the device and that the
 * file can be created (PLplot prompts on stdin and exits when it cannot open it),
 * sets a white background with black text. In the child. */
thz_status plot_begin(const char *path, int width, int height, thz_error *err);
/* Finishes the figure and checks the file was written. In the child. */
thz_status plot_end(const char *path, thz_error *err);

#endif
