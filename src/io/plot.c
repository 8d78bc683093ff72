/* PLplot figures (pngcairo), drawn: channel previews, per-object spectra and attenuation
 * spectra. Only in child processes (plot_child.c runs them; plot_draw.h says why).
 */
#include "io/plot_draw.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <plplot/plplot.h>

#include "core/alloc.h"
#include "core/order.h"

/* A filled circle (U+25CF) marks each data point; cairo renders UTF-8 text. */
#define PLOT_MARK "\xe2\x97\x8f"

enum { PLOT_MAX_DEVICES = 256, PLOT_TEXT = 512, PLOT_GRID_COLOR = 15 };

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

/* Distinguishable line colours (a common qualitative palette), cmap0 indices 2..11. */
static const unsigned char plot_lines_palette[10][3] = {
    {31, 119, 180}, {255, 127, 14},  {44, 160, 44},   {214, 39, 40},  {148, 103, 189},
    {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207},
};

/* PLplot treats '#' as its escape character: double it in user text. */
static void plot_escape(char *dst, size_t size, const char *src)
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

/* Starts a figure of width x height pixels into path: checks the device and that the
 * file can be created (PLplot prompts on stdin and exits when it cannot open it),
 * sets a white background with black text. In the child. */
static thz_status plot_begin(const char *path, int width, int height, thz_error *err)
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

/* Finishes the figure and checks the file was written. In the child. */
static thz_status plot_end(const char *path, thz_error *err)
{
    plend();
    FILE *f = fopen(path, "rb");
    long size = -1;
    if (f) {
        if (fseek(f, 0, SEEK_END) == 0)
            size = ftell(f);
        fclose(f);
    }
    if (size <= 0)
        return thz_error_set(err, THZ_ERR_IO, "%s: PLplot wrote no figure", path);
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

thz_status plot_image_draw(const char *path, const float *values, uint32_t columns, uint32_t rows,
                           const char *title, const char *value_label, thz_error *err)
{
    if (columns == 0 || rows == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: empty image", path);
    /* An image larger than the figure shows is drawn from blocks of f x f pixels, each
     * the mean of its finite pixels: plimage draws a rectangle per cell, and a 4096 x 4096
     * preview took 10 s for the figure's ~500 pixels across (scale audit). The colour bar
     * still comes from every pixel. */
    uint32_t longest = columns > rows ? columns : rows;
    uint32_t f =
        longest > PLOT_IMAGE_CELLS ? (longest + PLOT_IMAGE_CELLS - 1) / PLOT_IMAGE_CELLS : 1;
    size_t bx = (columns + (size_t)f - 1) / f, by = (rows + (size_t)f - 1) / f;
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
    /* The colour bar spans the 1st to 99th percentile of the finite values, so that a
     * few noisy pixels do not flatten the picture; values beyond are drawn in the end
     * colours, and the bar then shows a triangular cap at that end. */
    double vmin = 0.0, vmax = 1.0, lowest = INFINITY, highest = -INFINITY;
    bool clipped_low = false, clipped_high = false;
    size_t n_finite = 0;
    for (size_t i = 0; i < (size_t)columns * rows; i++)
        if (isfinite(values[i])) {
            finite[n_finite++] = values[i];
            lowest = fmin(lowest, values[i]);
            highest = fmax(highest, values[i]);
        }
    if (n_finite > 0) {
        vmin = order_select(finite, n_finite, (size_t)floor(0.01 * (double)(n_finite - 1)));
        vmax = order_select(finite, n_finite, (size_t)ceil(0.99 * (double)(n_finite - 1)));
        clipped_low = lowest < vmin;
        clipped_high = highest > vmax;
    }
    double scale = fmax(fabs(vmin), fabs(vmax));
    if (vmax - vmin <= 1e-9 * scale) { /* a flat image still needs a scale */
        double pad = scale > 0.0 ? 1e-3 * scale : 0.5;
        vmin -= pad;
        vmax += pad;
    }
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
    double aspect = (double)rows / columns;
    int width = 720;
    int height = (int)fmin(fmax(120.0 + 480.0 * aspect, 240.0), 1400.0);
    status = plot_begin(path, width, height, err);
    if (status == THZ_OK) {
        plvpas(0.10, 0.78, 0.12, 0.90, aspect);
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
