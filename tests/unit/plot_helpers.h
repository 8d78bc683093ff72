/* What the PLplot figures' unit tests share (test_plot.c, test_plot_batch.c): a fresh
 * temporary directory and a PNG read back as 8-bit RGB. Header-only (static inline), as
 * scene_load_helpers.h. */
#ifndef THZ_TESTS_PLOT_HELPERS_H
#define THZ_TESTS_PLOT_HELPERS_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

/* $TMPDIR/thz-test-plot-XXXXXX (or under /tmp), made; caller frees the name. */
static inline char *make_tmp_dir(void)
{
    const char *base = getenv("TMPDIR");
    char templ[512];
    snprintf(templ, sizeof templ, "%s/thz-test-plot-XXXXXX", base && *base ? base : "/tmp");
    char *d = mkdtemp(templ);
    assert_non_null(d);
    return thz_strdup(d);
}

/* Decodes path as 8-bit RGB; caller frees *pixels. */
static inline void read_png(const char *path, unsigned char **pixels, uint32_t *w, uint32_t *h)
{
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path))
        fail_msg("%s: %s", path, image.message);
    image.format = PNG_FORMAT_RGB;
    *pixels = malloc(PNG_IMAGE_SIZE(image));
    assert_non_null(*pixels);
    if (!png_image_finish_read(&image, NULL, *pixels, 0, NULL))
        fail_msg("%s: %s", path, image.message);
    *w = image.width;
    *h = image.height;
}

#endif
