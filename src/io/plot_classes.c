/* classify's class map as a PLplot figure (plot.h plot_classes): the classes in their
 * colours and a legend that names them. Only in a child process (plot_draw.h). */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <plplot/plplot.h>

#include "core/alloc.h"
#include "io/plot_draw.h"

/* The figure's layout in pixels: the map's left and right edges, a legend entry's
 * height and a legend column's width (for a name of PLOT_NAME_BYTES, cut beyond). */
#define PLOT_MAP_LEFT 77
#define PLOT_MAP_RIGHT 595
#define PLOT_LEGEND_ROW 28
#define PLOT_LEGEND_COLUMN 320
#define PLOT_NAME_BYTES 40

/* A legend entry's text: name escaped, cut to PLOT_NAME_BYTES (at a character's start)
 * with "..." after. */
static void plot_class_name(char *dst, size_t size, const char *name)
{
    char cut[PLOT_NAME_BYTES + 4];
    size_t n = strlen(name);
    if (n > PLOT_NAME_BYTES) {
        n = PLOT_NAME_BYTES;
        while (n > 0 && ((unsigned char)name[n] & 0xC0) == 0x80)
            n--;
        snprintf(cut, sizeof cut, "%.*s...", (int)n, name);
        name = cut;
    }
    plot_escape(dst, size, name);
}

/* cmap0: 0 the background, 1 the text, then nothing hit (black) and the classes. */
#define PLOT_CLASS_SLOT0 2

/* The cmap0 colour of class c (-1: nothing hit). */
static PLINT plot_class_colour(int32_t c)
{
    return PLOT_CLASS_SLOT0 + 1 + c;
}

/* The map, drawn as plot_image draws its image (an image, not a fill per cell, whose
 * antialiased edges let the white background through between cells: seams). Its colour
 * map holds one colour per class, slot c + 1 for class c and 0 for nothing hit; cell
 * value s + 1/2 maps to slot s exactly: plcol1 takes floor(fraction x colours). grid is
 * scratch for (bx + 1) x (by + 1) values and cols for bx + 1 pointers. */
static void plot_class_cells(const int32_t *classes, uint32_t columns, size_t n_classes,
                             const unsigned char (*rgb)[3], const plot_layout *l, PLFLT *grid,
                             PLFLT **cols, PLINT *r, PLINT *g, PLINT *b)
{
    size_t slots = n_classes + 1, nx = l->bx + 1, ny = l->by + 1;
    r[0] = g[0] = b[0] = 0;
    for (size_t k = 0; k < n_classes; k++) {
        r[k + 1] = rgb[k][0];
        g[k + 1] = rgb[k][1];
        b[k + 1] = rgb[k][2];
    }
    plscmap1n((PLINT)slots);
    plscmap1(r, g, b, (PLINT)slots);
    /* a cell is its block's first pixel; the last column and row repeated (plimagefr
     * colours a cell by its lower corner: bx x by cells from (bx + 1) x (by + 1) values) */
    for (size_t i = 0; i < nx; i++) {
        cols[i] = grid + i * ny;
        size_t c = (i < l->bx ? i : l->bx - 1) * l->f;
        for (size_t j = 0; j < ny; j++) {
            size_t row = (j < l->by ? j : l->by - 1) * l->f;
            int32_t k = classes[row * columns + c];
            cols[i][j] = (k >= 0 && (size_t)k < n_classes ? (double)k + 1.0 : 0.0) + 0.5;
        }
    }
    plimagefr((PLFLT_MATRIX)cols, (PLINT)nx, (PLINT)ny, 0.0, (double)(l->bx * l->f), 0.0,
              (double)(l->by * l->f), 0.0, (double)slots, 0.0, (double)slots, NULL, NULL);
}

thz_status plot_classes_draw(const char *path, const int32_t *classes, uint32_t columns,
                             uint32_t rows, size_t n_classes, const char *const *names,
                             const unsigned char (*rgb)[3], const char *title, thz_error *err)
{
    if (columns == 0 || rows == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: empty image", path);
    bool nothing = false;
    for (size_t p = 0; p < (size_t)columns * rows && !nothing; p++)
        nothing = classes[p] < 0;
    /* the legend: the classes, then nothing hit if any pixel is */
    size_t n = n_classes + (nothing ? 1 : 0);
    PLINT *opts = thz_calloc(n + 1, sizeof *opts),
          *text_colours = thz_calloc(n + 1, sizeof *text_colours);
    PLINT *box_colours = thz_calloc(n + 1, sizeof *box_colours),
          *patterns = thz_calloc(n + 1, sizeof *patterns);
    PLFLT *scales = thz_calloc(n + 1, sizeof *scales), *widths = thz_calloc(n + 1, sizeof *widths);
    char *text = thz_calloc(n + 1, PLOT_TEXT);
    const char **texts = thz_calloc(n + 1, sizeof *texts);
    plot_layout lay = plot_image_layout(columns, rows);
    PLFLT *grid = thz_malloc_array((lay.bx + 1) * (lay.by + 1), sizeof *grid);
    PLFLT **cols = thz_malloc_array(lay.bx + 1, sizeof *cols);
    PLINT *cmap = thz_malloc_array(3 * (n_classes + 1), sizeof *cmap);
    thz_status status = THZ_OK;
    if (!opts || !text_colours || !box_colours || !patterns || !scales || !widths || !text ||
        !texts || !grid || !cols || !cmap) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
        goto cleanup;
    }
    for (size_t k = 0; k < n; k++) {
        opts[k] = PL_LEGEND_COLOR_BOX;
        text_colours[k] = 1;
        box_colours[k] = plot_class_colour(k < n_classes ? (int32_t)k : -1);
        scales[k] = 0.7; /* a gap between the boxes */
        widths[k] = 1.0;
        texts[k] = text + k * PLOT_TEXT;
        plot_class_name(text + k * PLOT_TEXT, PLOT_TEXT, k < n_classes ? names[k] : "nothing hit");
    }
    char t_title[PLOT_TEXT];
    plot_escape(t_title, sizeof t_title, title);

    /* The legend beside the map, PLOT_LEGEND_ROW pixels an entry, in columns of
     * PLOT_LEGEND_COLUMN pixels: the figure grows taller (to 1400 pixels) and then wider
     * for more entries; the map keeps its place, PLOT_MAP_LEFT to PLOT_MAP_RIGHT. */
    int height = lay.height;
    if (height < PLOT_LEGEND_ROW * (int)fmin((double)n, 60.0) + 100)
        height = PLOT_LEGEND_ROW * (int)fmin((double)n, 60.0) + 100;
    height = height < 1400 ? height : 1400;
    size_t most = (size_t)(height - 100) / PLOT_LEGEND_ROW;
    size_t ncolumn = n ? (n + most - 1) / most : 1, nrow = n ? (n + ncolumn - 1) / ncolumn : 1;
    int width = PLOT_MAP_RIGHT + 45 + PLOT_LEGEND_COLUMN * (int)ncolumn;
    status = plot_begin(path, width, height, err);
    if (status != THZ_OK)
        goto cleanup;
    /* PLplot's characters grow with the page, as (width + height) / 2: at 700 pixels
     * (960 x 440, a 4:3 image's) the legend's entries (text scale 0.8, spacing 2) are
     * PLOT_LEGEND_ROW apart; the same text on every page */
    PLFLT chr_def, chr_ht;
    plgchr(&chr_def, &chr_ht);
    plschr(chr_def * 1400.0 / (width + height), 1.0);
    plscmap0n((PLINT)(PLOT_CLASS_SLOT0 + 1 + n_classes));
    plscol0(0, 255, 255, 255);
    plscol0(1, 0, 0, 0);
    plscol0(PLOT_CLASS_SLOT0, 0, 0, 0);
    for (size_t k = 0; k < n_classes; k++)
        plscol0(plot_class_colour((int32_t)k), rgb[k][0], rgb[k][1], rgb[k][2]);
    /* square pixels, but a strip (classify_spectra's one row) at least 1/16 as high */
    plvpas((double)PLOT_MAP_LEFT / width, (double)PLOT_MAP_RIGHT / width, 0.12, 0.90,
           fmax(lay.aspect, 1.0 / 16.0));
    /* Row 0 at the top: the y axis runs from `rows` at the bottom to 0 on top. */
    plwind(0.0, columns, rows, 0.0);
    plot_class_cells(classes, columns, n_classes, rgb, &lay, grid, cols, cmap, cmap + n_classes + 1,
                     cmap + 2 * (n_classes + 1));
    plcol0(1);
    /* a strip has no room for the rows' numbers */
    double map_px = (PLOT_MAP_RIGHT - PLOT_MAP_LEFT) * fmax(lay.aspect, 1.0 / 16.0);
    plbox("bcnst", 0.0, 0, map_px < 80.0 ? "bcst" : "bcnstv", 0.0, 0);
    pllab("column (pixel)", "row (pixel)", t_title);
    PLFLT legend_w, legend_h;
    if (n > 0)
        pllegend(&legend_w, &legend_h, PL_LEGEND_BACKGROUND,
                 PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.03, 0.0, 0.06, 0,
                 1, 1, (PLINT)nrow, (PLINT)ncolumn, (PLINT)n, opts, 1.0, 0.8, 2.0, 0.0,
                 text_colours, texts, box_colours, patterns, scales, widths, NULL, NULL, NULL, NULL,
                 NULL, NULL, NULL);
    status = plot_end(path, err);
cleanup:
    free(opts);
    free(text_colours);
    free(box_colours);
    free(patterns);
    free(scales);
    free(widths);
    free(text);
    free(texts);
    free(grid);
    free(cols);
    free(cmap);
    return status;
}
