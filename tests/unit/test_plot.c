/* PLplot figures: the pngcairo device is found, previews show the colour map's ends
 * at the image's extremes on a white page, row 0 on top and column 0 on the left, their
 * colour bar from the 1st to the 99th percentile, odd inputs (flat, NaN, one pixel, no
 * curves, '#' in names) still give a figure, line plots wrap long titles and label close
 * ticks apart, and the attenuation figure shows its curves and bands. test_plot_batch.c
 * has figures drawn side by side (threads, batches of processes). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "io/plot.h"
#include "io/plot_draw.h"
#include "io/png_image.h"
#include "plot_helpers.h"

/* Whether some pixel lies within tol of (r, g, b) in every component. */
static int has_colour(const unsigned char *px, size_t n, int r, int g, int b, int tol)
{
    for (size_t i = 0; i < n; i++) {
        const unsigned char *p = px + 3 * i;
        if (abs(p[0] - r) <= tol && abs(p[1] - g) <= tol && abs(p[2] - b) <= tol)
            return 1;
    }
    return 0;
}

static void test_device(void **state)
{
    (void)state;
    thz_error err = {0};
    thz_status st = plot_check_device(&err);
    if (st != THZ_OK)
        fail_msg("%s", err.message);
}

/* A PLPLOT_DRV_DIR without the cairo driver is our error, not PLplot's exit; also
 * after a check without it succeeded (the success is remembered for that setting only). */
static void test_device_dir_without_cairo(void **state)
{
    (void)state;
    const char *old = getenv("PLPLOT_DRV_DIR");
    char *saved = old ? thz_strdup(old) : NULL;
    thz_error err = {0};
    assert_int_equal(plot_check_device(&err), THZ_OK);
    setenv("PLPLOT_DRV_DIR", "/nonexistent-thz-plplot-drivers", 1);
    assert_int_equal(plot_check_device(&err), THZ_ERR_IO);
    assert_non_null(strstr(err.message, "plplot-driver-cairo"));
    if (saved)
        setenv("PLPLOT_DRV_DIR", saved, 1);
    else
        unsetenv("PLPLOT_DRV_DIR");
    free(saved);
}

static void test_image_colours(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/img.png", dir);
    enum { C = 16, R = 8 };
    float v[C * R];
    for (int i = 0; i < C * R; i++)
        v[i] = 290.0f + (float)(i % C); /* 290 K on the left to 305 K on the right */
    thz_error err = {0};
    if (plot_image(path, v, C, R, "test: channel 1", "brightness temperature (K)", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    assert_int_equal(w, 720);
    assert_true(h >= 240);
    size_t n = (size_t)w * h;
    /* White page, and both ends of the colour map present (min and max pixels). */
    assert_memory_equal(px, "\xff\xff\xff", 3);
    assert_true(has_colour(px, n, 68, 1, 84, 6));
    assert_true(has_colour(px, n, 253, 231, 37, 6));
    free(px);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* The mean (x, y) of the pixels within tol of (r, g, b) left of x_end (the image, not
 * its colour bar); whether there is any. */
static int colour_centre(const unsigned char *px, uint32_t w, uint32_t h, uint32_t x_end, int r,
                         int g, int b, int tol, double *x, double *y)
{
    double sx = 0.0, sy = 0.0;
    size_t n = 0;
    for (uint32_t j = 0; j < h; j++)
        for (uint32_t i = 0; i < x_end && i < w; i++) {
            const unsigned char *p = px + 3 * ((size_t)j * w + i);
            if (abs(p[0] - r) <= tol && abs(p[1] - g) <= tol && abs(p[2] - b) <= tol) {
                sx += i;
                sy += j;
                n++;
            }
        }
    if (n == 0)
        return 0;
    *x = sx / (double)n;
    *y = sy / (double)n;
    return 1;
}

/* A preview shows row 0 at the top and column 0 at the left, as the ENVI cube and
 * S.visual.png do: the coldest quarter (top left) in the colour map's low end lies above
 * and left of the hottest (bottom right) in its high end. Drawn upside down (the y axis
 * from 0 at the bottom, a helper's mutant) it passed every test. */
static void test_image_orientation(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/orient.png", dir);
    enum { C = 16, R = 12 };
    float v[C * R];
    for (int r = 0; r < R; r++)
        for (int c = 0; c < C; c++)
            v[r * C + c] = r < R / 2 && c < C / 2     ? 280.0f
                           : r >= R / 2 && c >= C / 2 ? 320.0f
                                                      : 300.0f;
    thz_error err = {0};
    if (plot_image(path, v, C, R, "orientation", "T (K)", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    /* the image's viewport ends at 0.78 of the width; the colour bar is beyond */
    uint32_t x_end = (uint32_t)(0.78 * w);
    double cold_x = 0, cold_y = 0, hot_x = 0, hot_y = 0, mid_x = 0, mid_y = 0;
    assert_true(colour_centre(px, w, h, x_end, 68, 1, 84, 6, &cold_x, &cold_y));
    assert_true(colour_centre(px, w, h, x_end, 253, 231, 37, 6, &hot_x, &hot_y));
    assert_true(colour_centre(px, w, h, x_end, 33, 145, 140, 12, &mid_x, &mid_y));
    /* each quarter is 8 x 6 pixels of about 34 figure pixels each */
    assert_true(hot_y - cold_y > 100.0);
    assert_true(hot_x - cold_x > 100.0);
    free(px);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* The colour bar's range is the 1st to the 99th percentile of the finite values (as
 * docs/gui.md says of the page's, whose range the CLI's previews share), with a cap at each
 * end beyond which values lie, and a flat image widened to a range. */
static void test_colour_range(void **state)
{
    (void)state;
    enum { N = 203 };
    float v[N];
    double scratch[N];
    /* 0, 1, ..., 200 K shuffled by a stride coprime to 201, and two NaN */
    for (int i = 0; i < 201; i++)
        v[i] = (float)((i * 73) % 201);
    v[201] = NAN;
    v[202] = INFINITY;
    plot_range r = plot_colour_range(v, N, scratch);
    /* of 201 finite values: index floor(0.01 x 200) = 2 and ceil(0.99 x 200) = 198 */
    assert_true(r.lo == 2.0);
    assert_true(r.hi == 198.0);
    assert_true(r.clipped_low && r.clipped_high);

    float inside[5] = {3.0f, 1.0f, 2.0f, NAN, 4.0f}; /* 4 values: indices 0 and 3 */
    r = plot_colour_range(inside, 5, scratch);
    assert_true(r.lo == 1.0 && r.hi == 4.0);
    assert_false(r.clipped_low || r.clipped_high);

    float flat[3] = {300.0f, 300.0f, 300.0f};
    r = plot_colour_range(flat, 3, scratch);
    assert_true(fabs(r.lo - 299.7) < 1e-9 && fabs(r.hi - 300.3) < 1e-9);
    float zero[2] = {0.0f, 0.0f};
    r = plot_colour_range(zero, 2, scratch);
    assert_true(r.lo == -0.5 && r.hi == 0.5);
    float none[2] = {NAN, NAN};
    r = plot_colour_range(none, 2, scratch);
    assert_true(r.lo == 0.0 && r.hi == 1.0);
}

/* S.visual.png's writer: row 0 at the top, column 0 at the left, sRGB values as given
 * (a negative row stride, which libpng takes as bottom-up, passed every test before). */
static void test_visual_png_orientation(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/visual.png", dir);
    /* 3 x 2: the top row red, green, blue; the bottom row white, black, grey */
    const float rgb[18] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0.5f, 0.5f, 0.5f};
    thz_error err = {0};
    if (png_image_write_srgb8(path, rgb, 3, 2, &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    assert_int_equal(w, 3);
    assert_int_equal(h, 2);
    const unsigned char want[18] = {255, 0,   0,   0, 255, 0, 0,   0,   255,
                                    255, 255, 255, 0, 0,   0, 128, 128, 128};
    assert_memory_equal(px, want, sizeof want);
    free(px);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* An image wider than the figure shows (drawn from 3 x 3 blocks): the narrow strips of
 * its lowest values on the left edge and its highest on the right edge still show, in
 * the colour map's end colours (the blocks cover the whole image, to its last column). */
static void test_large_image(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/large.png", dir);
    enum { C = 2100, R = 700 };
    float *v = thz_malloc_array((size_t)C * R, sizeof *v);
    assert_non_null(v);
    for (size_t r = 0; r < R; r++)
        for (size_t c = 0; c < C; c++)
            v[r * C + c] = c < 9 ? 250.0f : c >= C - 9 ? 350.0f : (r % 2 ? NAN : 300.0f);
    thz_error err = {0};
    if (plot_image(path, v, C, R, "large", "T (K)", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    assert_int_equal(w, 720);
    size_t n = (size_t)w * h;
    assert_true(has_colour(px, n, 68, 1, 84, 6));    /* the left strip */
    assert_true(has_colour(px, n, 253, 231, 37, 6)); /* the right strip, the last columns */
    free(px);
    free(v);
    unlink(path);
    rmdir(dir);
    free(dir);
}

static void test_odd_images(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/odd.png", dir);
    thz_error err = {0};
    float flat[6] = {295, 295, 295, 295, 295, 295};
    assert_int_equal(plot_image(path, flat, 3, 2, "flat #1", "T (K)", &err), THZ_OK);
    float nan[4] = {NAN, NAN, NAN, NAN};
    assert_int_equal(plot_image(path, nan, 2, 2, "nan", "T (K)", &err), THZ_OK);
    float one = 1e-14f;
    assert_int_equal(plot_image(path, &one, 1, 1, "one", "L (W m-2 sr-1 Hz-1)", &err), THZ_OK);
    float tall[2 * 50];
    for (int i = 0; i < 100; i++)
        tall[i] = (float)i;
    assert_int_equal(plot_image(path, tall, 2, 50, "tall", "x (1)", &err), THZ_OK);
    /* An unwritable path fails with our error instead of PLplot's prompt and exit. */
    assert_int_equal(plot_image("/nonexistent-thz-dir/x.png", flat, 3, 2, "t", "T (K)", &err),
                     THZ_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent-thz-dir/x.png"));
    unlink(path);
    rmdir(dir);
    free(dir);
}

static void test_lines(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/lines.png", dir);
    enum { NX = 6, NL = 13 };
    double x[NX], y[NL * NX];
    const char *names[NL];
    char name_buf[NL][32];
    for (int j = 0; j < NX; j++)
        x[j] = 0.2 + 0.2 * j;
    for (int i = 0; i < NL; i++) {
        snprintf(name_buf[i], sizeof name_buf[i], "object #%d", i);
        names[i] = name_buf[i];
        for (int j = 0; j < NX; j++)
            y[i * NX + j] = 0.8 + 0.01 * i + 0.02 * sin(j + i);
    }
    y[3] = NAN; /* a missing point is left out */
    thz_error err = {0};
    if (plot_lines(path, NX, x, NL, names, y, "spectra", "frequency (THz)", "N (1)", &err) !=
        THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    assert_int_equal(w, 960);
    assert_int_equal(h, 600);
    assert_memory_equal(px, "\xff\xff\xff", 3);
    assert_true(has_colour(px, (size_t)w * h, 31, 119, 180, 10)); /* first curve's colour */
    free(px);
    /* No curve at all (no object in view) is still a figure. */
    assert_int_equal(plot_lines(path, NX, x, 0, NULL, NULL, "empty", "f (THz)", "N (1)", &err),
                     THZ_OK);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* A title wider than the figure (bands-spectra.png's list of chosen channels) is wrapped
 * onto more lines, none cut at the figure's edges: no dark pixel in the outermost columns,
 * and dark pixels (the title) in the rows above the plot. */
static void test_long_title(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/title.png", dir);
    double x[3] = {0.2, 0.3, 0.4}, y[3] = {250.0, 260.0, 255.0};
    const char *names[] = {"body"};
    const char *title = "outdoor-concealed: mean Tb per class; chosen: 0.28 THz (relative width "
                        "0.01); 0.12, 0.3 THz (relative width 0.03); 0.44, 0.52, 0.61 THz "
                        "(relative width 0.05)";
    thz_error err = {0};
    if (plot_lines(path, 3, x, 1, names, y, title, "frequency (THz)", "T (K)", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    size_t dark_top = 0;
    for (uint32_t r = 0; r < h; r++)
        for (uint32_t c = 0; c < w; c++) {
            const unsigned char *p = px + 3 * ((size_t)r * w + c);
            bool dark = p[0] < 128 && p[1] < 128 && p[2] < 128;
            if (dark && (c < 3 || c + 3 >= w))
                fail_msg("a dark pixel at column %u, row %u: the title is cut", c, r);
            dark_top += dark && r < h / 8;
        }
    assert_true(dark_top > 500);
    free(px);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* '#' starts a PLplot escape ("#d" lowers the text, "#u" raises it): a '#' in a name
 * that goes into a figure (an object "hidden#1" in S.spectra.png's legend, a sensor in a
 * title) is doubled, which PLplot draws as one '#'. The doubling dropped (a mutant)
 * passed every test. */
static void test_escape(void **state)
{
    (void)state;
    char out[64];
    plot_escape(out, sizeof out, "hidden#1 #d#u");
    assert_string_equal(out, "hidden##1 ##d##u");
    plot_escape(out, sizeof out, "T (K)");
    assert_string_equal(out, "T (K)");
}

/* A count's axis (bands-score.png's K) has its ticks at whole numbers. */
static void test_whole_ticks(void **state)
{
    (void)state;
    const double spans[] = {0.2, 2.2, 3.1, 9.0, 17.0, 33.0, 60.0, 250.0, 700.0};
    const double want[] = {1.0, 1.0, 1.0, 2.0, 5.0, 5.0, 10.0, 50.0, 100.0};
    for (size_t i = 0; i < sizeof spans / sizeof spans[0]; i++) {
        assert_true(plot_whole_tick(spans[i]) == want[i]);
        /* at most 10 ticks (60 in steps of 5 would be 12) */
        assert_true(spans[i] / want[i] <= 10.0);
    }
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/k.png", dir);
    double k[3] = {1, 2, 3}, jm[3] = {0.7, 1.3, 1.5};
    const char *names[] = {"worst pair"};
    thz_error err = {0};
    if (plot_lines_whole_x(path, 3, k, 1, names, jm, "K", "channels K", "JM", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* Ticks of an axis whose values differ only in the 5th digit get labels that differ
 * (they were all "300.0"); ordinary ranges keep PLplot's 4 digits. */
static void test_label_digits(void **state)
{
    (void)state;
    const double lo[] = {300.010, 0.30010, -1e6 - 3.0, 200.0, 0.0, 5.0};
    const double hi[] = {300.022, 0.30022, -1e6 + 3.0, 300.0, 1e-3, 5.0};
    const int want[] = {7, 6, 8, 4, 4, 4};
    for (size_t i = 0; i < sizeof lo / sizeof lo[0]; i++) {
        int d = plot_label_digits(lo[i], hi[i]);
        assert_int_equal(d, want[i]);
        if (!(hi[i] > lo[i]))
            continue;
        char a[64], b[64]; /* neighbouring ticks at the spacing named, apart */
        double step = (hi[i] - lo[i]) / 8.0, mid = 0.5 * (lo[i] + hi[i]);
        snprintf(a, sizeof a, "%.*g", d, mid);
        snprintf(b, sizeof b, "%.*g", d, mid + step);
        assert_string_not_equal(a, b);
    }
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/close.png", dir);
    double x[3] = {0.2, 0.6, 1.0}, tb[3] = {300.012, 300.021, 300.016};
    const char *names[] = {"target"};
    thz_error err = {0};
    if (plot_lines(path, 3, x, 1, names, tb, "close values", "frequency (THz)", "Tb (K)", &err) !=
        THZ_OK)
        fail_msg("%s", err.message);
    unlink(path);
    rmdir(dir);
    free(dir);
}

/* The attenuation figure: its size, the curves' and the shaded band's colours, a
 * '#' in a band name, zero values (drawn at the axis bottom), and an unwritable path
 * as our error (PLplot would prompt on stdin and exit). */
static void test_attenuation(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    char path[1024];
    snprintf(path, sizeof path, "%s/att.png", dir);
    enum { NX = 200 };
    double x[NX], total[NX], part[NX];
    for (int j = 0; j < NX; j++) {
        x[j] = 0.1 + 0.9 * j / (NX - 1);
        total[j] = 10.0 + 1e4 / (1.0 + pow((x[j] - 0.557) / 0.005, 2.0));
        part[j] = j % 7 == 0 ? 0.0 : 0.5 * total[j];
    }
    plot_curve curves[] = {{"H#d2#uO lines", part, {214, 39, 40}, 1.0, false},
                           {"total", total, {44, 160, 44}, 2.0, true}};
    plot_band bands[] = {{"#1 (0.35 THz)", 0.34, 0.35, 0.36}, {"out", 1.5, 1.6, 1.7}};
    thz_error err = {0};
    if (plot_attenuation(path, NX, x, 2, curves, 2, bands, "air #1", "frequency (THz)",
                         "attenuation (dB/km)", &err) != THZ_OK)
        fail_msg("%s", err.message);
    unsigned char *px = NULL;
    uint32_t w = 0, h = 0;
    read_png(path, &px, &w, &h);
    assert_int_equal(w, 1200);
    assert_int_equal(h, 750);
    assert_true(has_colour(px, (size_t)w * h, 214, 39, 40, 10));
    assert_true(has_colour(px, (size_t)w * h, 44, 160, 44, 10));
    assert_true(has_colour(px, (size_t)w * h, 234, 234, 234, 6)); /* band shading on white */
    free(px);
    unlink(path);

    snprintf(path, sizeof path, "%s/no-such-dir/att.png", dir);
    assert_int_equal(plot_attenuation(path, NX, x, 2, curves, 0, NULL, "t", "f", "a", &err),
                     THZ_ERR_IO);
    assert_non_null(strstr(err.message, "cannot create"));
    rmdir(dir);
    free(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_device),
        cmocka_unit_test(test_device_dir_without_cairo),
        cmocka_unit_test(test_image_colours),
        cmocka_unit_test(test_odd_images),
        cmocka_unit_test(test_visual_png_orientation),
        cmocka_unit_test(test_escape),
        cmocka_unit_test(test_image_orientation),
        cmocka_unit_test(test_colour_range),
        cmocka_unit_test(test_lines),
        cmocka_unit_test(test_attenuation),
        cmocka_unit_test(test_long_title),
        cmocka_unit_test(test_whole_ticks),
        cmocka_unit_test(test_label_digits),
        cmocka_unit_test(test_large_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
