/* PLplot figures (pngcairo), drawn: what every figure shares (the device check, a
 * figure's start and end, escaped text) and the channel preview image. plot_lines.c
 * draws the line plots, plot_attenuation.c the attenuation spectra. Only in child
 * processes (plot_child.c runs them; plot_draw.h says why).
 */
#include "io/plot_draw.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <plplot/plplot.h>

#include "core/alloc.h"
#include "core/order.h"

enum { PLOT_MAX_DEVICES = 256 };

static double plot_timeout_base = 60.0;

double plot_timeout_s(size_t cells)
{
    return plot_timeout_base + 2e-6 * (double)cells;
}

void plot_set_timeout_base_s(double base_s)
{
    plot_timeout_base = base_s;
}

/* Colour stops of the perceptual "viridis" map (van der Walt and Smith, 2015), taken
 * at 0, 1/8, ..., 1 and interpolated linearly in RGB: dark blue-violet to yellow, with
 * lightness rising monotonically so that brighter always means warmer, also in grey. */
static const unsigned char plot_viridis[9][3] = {
    {68, 1, 84},    {71, 45, 123}, {59, 82, 139},  {44, 114, 142}, {33, 145, 140},
    {40, 174, 128}, {94, 201, 98}, {173, 220, 48}, {253, 231, 37},
};

void plot_escape(char *dst, size_t size, const char *src)
{
    size_t j = 0;
    for (; *src && j + 2 < size; src++) {
        if (*src == '#')
            dst[j++] = '#';
        dst[j++] = *src;
    }
    dst[j] = '\0';
}

/* The most cells an image preview draws along its longer side: about twice the pixels
 * its figure gives the image (720 wide), so a larger image loses nothing to the eye. */
#define PLOT_IMAGE_CELLS 1024

plot_layout plot_image_layout(uint32_t columns, uint32_t rows)
{
    plot_layout l;
    uint32_t longest = columns > rows ? columns : rows;
    l.f = longest > PLOT_IMAGE_CELLS ? (longest + PLOT_IMAGE_CELLS - 1) / PLOT_IMAGE_CELLS : 1;
    l.bx = (columns + (size_t)l.f - 1) / l.f;
    l.by = (rows + (size_t)l.f - 1) / l.f;
    l.aspect = (double)rows / columns;
    l.height = (int)fmin(fmax(120.0 + 480.0 * l.aspect, 240.0), 1400.0);
    return l;
}

thz_status plot_check_device_here(void *arg, thz_error *err)
{
    (void)arg;
    /* PLplot exits the process when its driver directory holds no driver at all, so a
     * directory set by the user is checked for the cairo driver before PLplot looks. */
    const char *drv_dir = getenv("PLPLOT_DRV_DIR");
    if (drv_dir && *drv_dir) {
        char info[4096];
        int n = snprintf(info, sizeof info, "%s/cairo.driver_info", drv_dir);
        if (n < 0 || (size_t)n >= sizeof info || access(info, R_OK) != 0)
            return thz_error_set(err, THZ_ERR_IO,
                                 "PLplot has no pngcairo device in PLPLOT_DRV_DIR=%s: install "
                                 "the package plplot-driver-cairo or unset PLPLOT_DRV_DIR",
                                 drv_dir);
    }
    const char *menu[PLOT_MAX_DEVICES];
    const char *names[PLOT_MAX_DEVICES];
    const char **pm = menu, **pn = names;
    int n = PLOT_MAX_DEVICES;
    plgDevs(&pm, &pn, &n);
    for (int i = 0; i < n; i++)
        if (pn[i] && strcmp(pn[i], "pngcairo") == 0)
            return THZ_OK;
    return thz_error_set(err, THZ_ERR_IO,
                         "PLplot has no pngcairo device: install the package plplot-driver-cairo");
}

thz_status plot_begin(const char *path, int width, int height, thz_error *err)
{
    thz_status status = plot_check_device_here(NULL, err);
    if (status != THZ_OK)
        return status;
    FILE *f = fopen(path, "wb");
    if (!f)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
    fclose(f);
    plsdev("pngcairo");
    plsfnam(path);
    plspage(0.0, 0.0, width, height, 0, 0);
    plscolbg(255, 255, 255);
    plscol0(1, 0, 0, 0);
    plinit();
    pladv(0);
    plschr(0.0, 1.0);
    return THZ_OK;
}

/* Why a figure's file stopped short, as far as can be told after the fact: PLplot's
 * cairo driver ignores a failed write, so its errno is gone. */
static const char *plot_short_reason(const char *path, long size)
{
    struct rlimit lim;
    if (getrlimit(RLIMIT_FSIZE, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY && size >= 0 &&
        (rlim_t)size >= lim.rlim_cur)
        return strerror(EFBIG);
    struct statvfs fs;
    if (statvfs(path, &fs) == 0 && fs.f_bavail == 0)
        return strerror(ENOSPC);
    return "a write failed";
}

thz_status plot_end(const char *path, thz_error *err)
{
    plend();
    /* A PNG ends with its IEND chunk. A write that fails part-way (a full disk, a
     * file-size limit) leaves a file cut short, which PLplot does not report: without
     * this check a truncated figure was kept as a result (exit status 0). */
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    unsigned char tail[sizeof iend];
    FILE *f = fopen(path, "rb");
    long size = -1;
    int whole = 0;
    if (f) {
        if (fseek(f, 0, SEEK_END) == 0)
            size = ftell(f);
        whole = size >= (long)sizeof iend && fseek(f, -(long)sizeof iend, SEEK_END) == 0 &&
                fread(tail, 1, sizeof tail, f) == sizeof tail &&
                memcmp(tail, iend, sizeof iend) == 0;
        fclose(f);
    }
    if (size <= 0)
        return thz_error_set(err, THZ_ERR_IO, "%s: PLplot wrote no figure: %s", path,
                             plot_short_reason(path, size));
    if (!whole)
        return thz_error_set(err, THZ_ERR_IO, "%s: PLplot wrote an incomplete figure: %s", path,
                             plot_short_reason(path, size));
    return THZ_OK;
}

static void plot_set_viridis(void)
{
    enum { N = sizeof plot_viridis / sizeof plot_viridis[0] };
    PLFLT pos[N], r[N], g[N], b[N];
    for (int i = 0; i < N; i++) {
        pos[i] = (PLFLT)i / (N - 1);
        r[i] = plot_viridis[i][0] / 255.0;
        g[i] = plot_viridis[i][1] / 255.0;
        b[i] = plot_viridis[i][2] / 255.0;
    }
    plscmap1n(256);
    plscmap1l(1, N, pos, r, g, b, NULL);
}

/* The colour bar spans the 1st to 99th percentile of the finite values, so that a few
 * noisy pixels do not flatten the picture; values beyond are drawn in the end colours, and
 * the bar then shows a triangular cap at that end. */
plot_range plot_colour_range(const float *values, size_t n, double *finite)
{
    plot_range r = {.lo = 0.0, .hi = 1.0};
    double lowest = INFINITY, highest = -INFINITY;
    size_t n_finite = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(values[i])) {
            finite[n_finite++] = values[i];
            lowest = fmin(lowest, values[i]);
            highest = fmax(highest, values[i]);
        }
    if (n_finite > 0) {
        r.lo = order_select(finite, n_finite, (size_t)floor(0.01 * (double)(n_finite - 1)));
        r.hi = order_select(finite, n_finite, (size_t)ceil(0.99 * (double)(n_finite - 1)));
        r.clipped_low = lowest < r.lo;
        r.clipped_high = highest > r.hi;
    }
    double scale = fmax(fabs(r.lo), fabs(r.hi));
    if (r.hi - r.lo <= 1e-9 * scale) { /* a flat image still needs a scale */
        double pad = scale > 0.0 ? 1e-3 * scale : 0.5;
        r.lo -= pad;
        r.hi += pad;
    }
    return r;
}

thz_status plot_image_draw(const char *path, const float *values, uint32_t columns, uint32_t rows,
                           const char *title, const char *value_label, thz_error *err)
{
    if (columns == 0 || rows == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: empty image", path);
    /* An image larger than the figure shows is drawn from blocks of f x f pixels, each
     * the mean of its finite pixels: plimage draws a rectangle per cell, and a 4096 x 4096
     * preview took 10 s for the figure's ~500 pixels across (scale audit). The colour bar
     * still comes from every pixel. */
    plot_layout lay = plot_image_layout(columns, rows);
    uint32_t f = lay.f;
    size_t bx = lay.bx, by = lay.by;
    /* plimage draws (nx-1) x (ny-1) cells coloured by their lower corner: pass one more
     * column and row (copies of the last) so that every block is one whole cell. */
    size_t nx = bx + 1, ny = by + 1;
    PLFLT *grid = thz_malloc_array(nx * ny, sizeof *grid);
    PLFLT **cols = thz_malloc_array(nx, sizeof *cols);
    double *finite = thz_malloc_array((size_t)columns * rows, sizeof *finite);
    thz_status status = THZ_OK;
    if (!grid || !cols || !finite) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
        goto cleanup;
    }
    plot_range bar = plot_colour_range(values, (size_t)columns * rows, finite);
    double vmin = bar.lo, vmax = bar.hi;
    bool clipped_low = bar.clipped_low, clipped_high = bar.clipped_high;
    for (size_t i = 0; i < nx; i++) {
        cols[i] = grid + i * ny;
        size_t c0 = (i < bx ? i : bx - 1) * f, c1 = c0 + f < columns ? c0 + f : columns;
        for (size_t j = 0; j < ny; j++) {
            size_t r0 = (j < by ? j : by - 1) * f, r1 = r0 + f < rows ? r0 + f : rows;
            double sum = 0.0;
            size_t n = 0;
            for (size_t r = r0; r < r1; r++)
                for (size_t c = c0; c < c1; c++)
                    if (isfinite(values[r * columns + c])) {
                        sum += values[r * columns + c];
                        n++;
                    }
            cols[i][j] = n ? fmin(fmax(sum / (double)n, vmin), vmax) : vmin;
        }
    }
    char t_title[PLOT_TEXT], t_label[PLOT_TEXT];
    plot_escape(t_title, sizeof t_title, title);
    snprintf(t_label, sizeof t_label, "%s", value_label);

    /* Square pixels: the plot area follows the image's aspect ratio. */
    status = plot_begin(path, 720, lay.height, err);
    if (status == THZ_OK) {
        plvpas(0.10, 0.78, 0.12, 0.90, lay.aspect);
        /* Row 0 at the top: the y axis runs from `rows` at the bottom to 0 on top. */
        plwind(0.0, columns, rows, 0.0);
        plot_set_viridis();
        plimage((PLFLT_MATRIX)cols, (PLINT)nx, (PLINT)ny, 0.0, (double)(bx * f), 0.0,
                (double)(by * f), vmin, vmax, 0.0, columns, 0.0, rows);
        plcol0(1);
        plbox("bcnst", 0.0, 0, "bcnstv", 0.0, 0);
        pllab("column (pixel)", "row (pixel)", t_title);

        PLFLT bar_w, bar_h;
        PLINT label_opts[] = {PL_COLORBAR_LABEL_RIGHT};
        const char *labels[] = {t_label};
        const char *axis_opts[] = {"bcvtm"};
        PLFLT ticks[] = {0.0};
        PLINT sub_ticks[] = {0};
        PLINT n_values[] = {2};
        PLFLT range[] = {vmin, vmax};
        const PLFLT *value_rows[] = {range};
        PLINT bar_opt = PL_COLORBAR_IMAGE | (clipped_low ? PL_COLORBAR_CAP_LOW : 0) |
                        (clipped_high ? PL_COLORBAR_CAP_HIGH : 0);
        plcolorbar(&bar_w, &bar_h, bar_opt,
                   PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.03, 0.0, 0.04,
                   0.9, 0, 1, 1, 0.0, 1.0, 0, 0.0, 1, label_opts, labels, 1, axis_opts, ticks,
                   sub_ticks, n_values, (PLFLT_MATRIX)value_rows);
        status = plot_end(path, err);
    }
cleanup:
    free(finite);
    free(cols);
    free(grid);
    return status;
}
