/* ENVI and sensor output: a synthetic 5 x 3, two-channel sensor_images is written with
 * output_write_sensor, and the files are read back byte for byte and header field by
 * header field (scene-format.md "Outputs"). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/path.h"
#include "io/envi.h"
#include "io/output.h"
#include "scene/scene.h"
#include "sensor/images.h"

enum { COLS = 5, ROWS = 3, NCH = 2 };

/* A scratch directory, removed with its files by remove_dir. */
static char *make_tmp_dir(void)
{
    const char *base = getenv("TMPDIR");
    char templ[512];
    snprintf(templ, sizeof templ, "%s/thz-test-envi-XXXXXX", base && *base ? base : "/tmp");
    char *d = mkdtemp(templ);
    assert_non_null(d);
    return thz_strdup(d);
}

static void remove_dir(char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.' && (!e->d_name[1] || (e->d_name[1] == '.' && !e->d_name[2])))
                continue;
            char path[1024];
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
        closedir(d);
    }
    rmdir(dir);
    free(dir);
}

/* Whole file into a NUL-terminated buffer; *size its length. */
static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    buf[n] = '\0';
    fclose(f);
    if (size)
        *size = (size_t)n;
    return buf;
}

/* The value of `key = value` in an ENVI header (copied into out), or NULL. */
static const char *header_value(const char *hdr, const char *key, char *out, size_t size)
{
    size_t klen = strlen(key);
    for (const char *line = hdr; line && *line;) {
        const char *next = strchr(line, '\n');
        size_t len = next ? (size_t)(next - line) : strlen(line);
        if (len > klen + 3 && strncmp(line, key, klen) == 0 &&
            strncmp(line + klen, " = ", 3) == 0) {
            size_t vlen = len - klen - 3;
            if (vlen >= size)
                vlen = size - 1;
            memcpy(out, line + klen + 3, vlen);
            out[vlen] = '\0';
            return out;
        }
        line = next ? next + 1 : NULL;
    }
    return NULL;
}

static void assert_header(const char *hdr, const char *key, const char *expected)
{
    char v[1024];
    const char *got = header_value(hdr, key, v, sizeof v);
    if (!got)
        fail_msg("header has no '%s'", key);
    assert_string_equal(got, expected);
}

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Reads DIR/STEM.img and compares it word for word with the expected floats. */
static void assert_img_floats(const char *dir, const char *stem, const float *expected, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.img", dir, stem);
    size_t size = 0;
    char *data = slurp(path, &size);
    if (!data)
        fail_msg("missing %s", path);
    assert_int_equal(size, n * 4);
    for (size_t i = 0; i < n; i++) {
        uint32_t w = le32((const unsigned char *)data + 4 * i), e;
        memcpy(&e, &expected[i], 4);
        if (w != e)
            fail_msg("%s word %zu: 0x%08x, expected 0x%08x", stem, i, w, e);
    }
    free(data);
}

/* The mean column of the pixels within 12 of (r, g, b) left of 0.78 of the width (the
 * preview, not its colour bar: test_plot.c); -1 if none. */
static double mean_x_of(const unsigned char *px, uint32_t w, uint32_t h, int r, int g, int b)
{
    double sx = 0.0;
    size_t n = 0;
    for (uint32_t j = 0; j < h; j++)
        for (uint32_t i = 0; i < (uint32_t)(0.78 * w); i++) {
            const unsigned char *p = px + 3 * ((size_t)j * w + i);
            if (abs(p[0] - r) <= 12 && abs(p[1] - g) <= 12 && abs(p[2] - b) <= 12) {
                sx += i;
                n++;
            }
        }
    return n ? sx / (double)n : -1.0;
}

/* DIR/cam.PREFIX-NN.png shows channel NN (scene-format.md), whose values fill_images
 * makes warmest at the right in channel 1 and at the left in channel 2: the colour map's
 * warm end (viridis 253 231 37) right of its cold end (68 1 84) in the first, left of it
 * in the second. Every preview drawn from channel 1 (a mutant, of S.band-NN.png or of
 * S.measured-band-NN.png) passed every test. */
static void check_previews(const char *dir, const char *prefix)
{
    for (int c = 0; c < NCH; c++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/cam.%s-%02d.png", dir, prefix, c + 1);
        png_image im;
        memset(&im, 0, sizeof im);
        im.version = PNG_IMAGE_VERSION;
        assert_true(png_image_begin_read_from_file(&im, path));
        im.format = PNG_FORMAT_RGB;
        unsigned char *px = malloc(PNG_IMAGE_SIZE(im));
        assert_non_null(px);
        assert_true(png_image_finish_read(&im, NULL, px, 0, NULL));
        double warm = mean_x_of(px, im.width, im.height, 253, 231, 37);
        double cold = mean_x_of(px, im.width, im.height, 68, 1, 84);
        if (warm < 0.0 || cold < 0.0 || (c == 0 ? !(warm > cold) : !(warm < cold)))
            fail_msg("%s: warmest at x = %.0f, coldest at %.0f", path, warm, cold);
        free(px);
    }
}

static char *read_header(const char *dir, const char *stem)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.hdr", dir, stem);
    char *hdr = slurp(path, NULL);
    if (!hdr)
        fail_msg("missing %s", path);
    assert_memory_equal(hdr, "ENVI\n", 5);
    return hdr;
}

/* A scene with just what the writer reads: 2 channels, 3 objects, one sensor. */
static thz_scene *make_scene(void)
{
    thz_scene *s = scene_create();
    assert_non_null(s);
    s->name = thz_strdup("synthetic");
    s->path = thz_strdup("/nowhere/synthetic.json");
    s->n_channels = NCH;
    s->channels = thz_calloc(NCH, sizeof *s->channels);
    snprintf(s->channels[0].name, sizeof s->channels[0].name, "0.200 THz");
    s->channels[0].center_hz = 0.2e12;
    s->channels[0].relative_width = 0.01;
    /* ENVI list characters and a line break (a JSON "\n") in a name: written as spaces
     * and ';', the header keeping one key a line */
    snprintf(s->channels[1].name, sizeof s->channels[1].name, "band {b},\n2");
    /* 8 significant digits: the header keeps them (scene-format.md: the channel centres) */
    s->channels[1].center_hz = 1.2345678e12;
    s->channels[1].relative_width = 0.02;
    s->n_objects = 3;
    s->objects = thz_calloc(3, sizeof *s->objects);
    s->objects[0].name = thz_strdup("room");
    s->objects[1].name = thz_strdup("target");
    s->objects[2].name = thz_strdup("hidden#1");
    s->n_sensors = 1;
    s->sensors = thz_calloc(1, sizeof *s->sensors);
    s->sensors[0].name = thz_strdup("cam");
    s->sensors[0].columns = COLS;
    s->sensors[0].rows = ROWS;
    s->sensors[0].normalize_to_k = 295.0;
    return s;
}

/* Gradients that make every position distinguishable. */
static void fill_images(sensor_images *img, int with_stderr)
{
    assert_int_equal(sensor_images_init(img, COLS, ROWS, NCH, with_stderr, NULL), THZ_OK);
    for (size_t c = 0; c < NCH; c++)
        for (size_t r = 0; r < ROWS; r++)
            for (size_t x = 0; x < COLS; x++) {
                size_t i = (c * ROWS + r) * COLS + x;
                img->radiance[i] = (float)(1e-15 * (1.0 + (double)i));
                img->power[i] = (float)(1e-12 * (double)(i + 1));
                /* channel 1 warmer to the right, channel 2 to the left: their previews
                 * are told apart (check_previews) */
                double x_warm = c == 0 ? (double)x : (double)(COLS - 1 - x);
                img->brightness_temperature[i] =
                    (float)(280.0 + 10.0 * (double)c + x_warm + 0.25 * (double)r);
                img->normalized[i] = (float)(0.9 + 0.01 * (double)i);
                if (with_stderr)
                    img->radiance_stderr[i] = (float)(1e-17 * (double)i);
            }
    for (size_t p = 0; p < COLS * ROWS; p++) {
        img->temperature_k[p] = (float)(290.0 + (double)p);
        img->distance_m[p] = (float)(0.5 + 0.1 * (double)p);
        img->object_id[p] = (int32_t)(p % 4) - 1; /* -1, 0, 1, 2 */
        for (int k = 0; k < 3; k++)
            img->visual_rgb[3 * p + (size_t)k] = (float)p / (COLS * ROWS) * (float)(k + 1) / 3.0f;
    }
}

static void test_sensor_files(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    thz_scene *scene = make_scene();
    sensor_images img;
    fill_images(&img, 1);
    thz_error err = {0};
    thz_status st = output_write_sensor(dir, scene, 0, &img, 0, NULL, &err);
    if (st != THZ_OK)
        fail_msg("output_write_sensor: %s", err.message);

    const size_t cube = (size_t)COLS * ROWS * NCH, plane = (size_t)COLS * ROWS;
    struct {
        const char *stem, *units;
        const float *data;
        size_t n;
    } cubes[] = {
        {"cam.radiance", "W m-2 sr-1 Hz-1", img.radiance, cube},
        {"cam.radiance_stderr", "W m-2 sr-1 Hz-1", img.radiance_stderr, cube},
        {"cam.power", "W", img.power, cube},
        {"cam.brightness_temperature", "K", img.brightness_temperature, cube},
        {"cam.normalized", "1", img.normalized, cube},
        {"cam.temperature", "K", img.temperature_k, plane},
        {"cam.distance", "m", img.distance_m, plane},
    };
    for (size_t k = 0; k < sizeof cubes / sizeof cubes[0]; k++) {
        assert_img_floats(dir, cubes[k].stem, cubes[k].data, cubes[k].n);
        char *hdr = read_header(dir, cubes[k].stem);
        assert_header(hdr, "samples", "5");
        assert_header(hdr, "lines", "3");
        assert_header(hdr, "bands", cubes[k].n == cube ? "2" : "1");
        assert_header(hdr, "data type", "4");
        assert_header(hdr, "byte order", "0");
        assert_header(hdr, "header offset", "0");
        assert_header(hdr, "interleave", "bsq");
        assert_header(hdr, "data units", cubes[k].units);
        char v[1024];
        assert_non_null(header_value(hdr, "description", v, sizeof v));
        assert_non_null(strstr(v, cubes[k].units));
        /* {thzmap VERSION: QUANTITY [UNIT]; sensor S; scene NAME} (the two names swapped
         * passed every test) */
        char want[256];
        snprintf(want, sizeof want, "[%s]; sensor cam; scene synthetic}", cubes[k].units);
        if (strncmp(v, "{thzmap " THZ_VERSION_STRING ": ", 10 + strlen(THZ_VERSION_STRING)) != 0 ||
            strlen(v) < strlen(want) || strcmp(v + strlen(v) - strlen(want), want) != 0)
            fail_msg("%s: description '%s', expected '{thzmap %s: ... %s'", cubes[k].stem, v,
                     THZ_VERSION_STRING, want);
        if (cubes[k].n == cube) {
            /* List characters in a channel name must not break the list. */
            assert_header(hdr, "band names", "{0.200 THz, band  b ; 2}");
            assert_header(hdr, "wavelength units", "GHz");
            assert_header(hdr, "wavelength", "{200, 1234.5678}");
            assert_header(hdr, "fwhm", "{2, 24.691356}");
            assert_null(header_value(hdr, "data ignore value", v, sizeof v));
        } else {
            assert_null(header_value(hdr, "wavelength", v, sizeof v));
            /* truth maps: -1 where nothing is hit, distinct from any temperature or
             * distance */
            assert_header(hdr, "data ignore value", "-1");
        }
        free(hdr);
    }

    /* object_id: float32 like every ENVI image, the index as an exact float, -1 where
     * nothing is hit, the object names for the indices. */
    float ids[COLS * ROWS];
    for (size_t p = 0; p < plane; p++)
        ids[p] = (float)img.object_id[p];
    assert_img_floats(dir, "cam.object_id", ids, plane);
    char *hdr = read_header(dir, "cam.object_id");
    assert_header(hdr, "data type", "4");
    assert_header(hdr, "bands", "1");
    assert_header(hdr, "band names", "{object_id}");
    assert_header(hdr, "data units", "1");
    assert_header(hdr, "data ignore value", "-1");
    assert_header(hdr, "object names", "{room, target, hidden#1}");
    free(hdr);

    /* The PNGs: visual, one preview per channel (numbered from 01), the spectra. */
    char path[1024];
    size_t size = 0;
    const char *pngs[] = {"cam.visual.png", "cam.band-01.png", "cam.band-02.png",
                          "cam.spectra.png"};
    for (size_t k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, pngs[k]);
        char *png = slurp(path, &size);
        if (!png)
            fail_msg("missing %s", pngs[k]);
        assert_true(size > 8);
        assert_memory_equal(png, "\x89PNG\r\n\x1a\n", 8);
        free(png);
    }
    snprintf(path, sizeof path, "%s/cam.band-03.png", dir);
    assert_int_not_equal(access(path, F_OK), 0);
    check_previews(dir, "band");

    sensor_images_fini(&img);
    scene_destroy(scene);
    remove_dir(dir);
}

/* Without radiance_stderr there is no stderr cube. */
static void test_no_stderr(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    thz_scene *scene = make_scene();
    sensor_images img;
    fill_images(&img, 0);
    thz_error err = {0};
    assert_int_equal(output_write_sensor(dir, scene, 0, &img, 0, NULL, &err), THZ_OK);
    char path[1024];
    snprintf(path, sizeof path, "%s/cam.radiance_stderr.hdr", dir);
    assert_int_not_equal(access(path, F_OK), 0);
    snprintf(path, sizeof path, "%s/cam.radiance.hdr", dir);
    assert_int_equal(access(path, F_OK), 0);
    sensor_images_fini(&img);
    scene_destroy(scene);
    remove_dir(dir);
}

/* A sensor with a PSF writes the measured cubes (scene-format.md "Outputs"): their
 * values, and the header keys of a per-channel cube with their own units, W m-2 sr-1 Hz-1
 * and K. (`data units = 1` for the measured brightness temperature passed every test.) */
static void test_measured_files(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    thz_scene *scene = make_scene();
    scene->sensors[0].psf = PSF_GAUSSIAN;
    scene->sensors[0].psf_fwhm_deg = 0.5;
    sensor_images img;
    fill_images(&img, 0);
    const size_t cube = (size_t)COLS * ROWS * NCH;
    img.measured_radiance = thz_malloc_array(cube, sizeof *img.measured_radiance);
    img.measured_brightness_temperature =
        thz_malloc_array(cube, sizeof *img.measured_brightness_temperature);
    assert_true(img.measured_radiance && img.measured_brightness_temperature);
    for (size_t i = 0; i < cube; i++) {
        img.measured_radiance[i] = (float)(2e-15 * (1.0 + (double)i));
        img.measured_brightness_temperature[i] = img.brightness_temperature[i] - 30.0f;
    }
    thz_error err = {0};
    if (output_write_sensor(dir, scene, 0, &img, 0, NULL, &err) != THZ_OK)
        fail_msg("output_write_sensor: %s", err.message);
    struct {
        const char *stem, *units;
        const float *data;
    } cubes[] = {
        {"cam.measured_radiance", "W m-2 sr-1 Hz-1", img.measured_radiance},
        {"cam.measured_brightness_temperature", "K", img.measured_brightness_temperature},
    };
    for (size_t k = 0; k < 2; k++) {
        assert_img_floats(dir, cubes[k].stem, cubes[k].data, cube);
        char *hdr = read_header(dir, cubes[k].stem);
        assert_header(hdr, "bands", "2");
        assert_header(hdr, "data units", cubes[k].units);
        assert_header(hdr, "band names", "{0.200 THz, band  b ; 2}");
        assert_header(hdr, "wavelength units", "GHz");
        assert_header(hdr, "wavelength", "{200, 1234.5678}");
        char v[1024];
        assert_non_null(header_value(hdr, "description", v, sizeof v));
        if (!strstr(v, cubes[k].units) || !strstr(v, "Gaussian FWHM 0.5 deg"))
            fail_msg("%s: description '%s' lacks its unit or the model", cubes[k].stem, v);
        free(hdr);
    }
    for (size_t c = 1; c <= NCH; c++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/cam.measured-band-%02zu.png", dir, c);
        assert_int_equal(access(path, F_OK), 0);
    }
    check_previews(dir, "measured-band");
    sensor_images_fini(&img);
    scene_destroy(scene);
    remove_dir(dir);
}

/* Cubes that thzmap does not write but reads (thz_cube_read, classify): big-endian
 * (byte order = 1) and with bytes before the data (header offset). Both read as the same
 * values; the reader once could ignore either and pass every test (a helper's mutants). */
static void test_read_byte_order_and_offset(void **state)
{
    (void)state;
    char *dir = make_tmp_dir();
    const float want[6] = {1.5f, -2.25f, 300.125f, 4e-20f, 5e20f, 6.0f};
    for (int big = 0; big < 2; big++)
        for (int offset = 0; offset <= 7; offset += 7) {
            char path[1024];
            snprintf(path, sizeof path, "%s/o.hdr", dir);
            FILE *f = fopen(path, "w");
            assert_non_null(f);
            fprintf(f,
                    "ENVI\ndescription = {other}\nsamples = 3\nlines = 2\nbands = 1\n"
                    "header offset = %d\nfile type = ENVI Standard\ndata type = 4\n"
                    "interleave = bsq\nbyte order = %d\n",
                    offset, big);
            fclose(f);
            snprintf(path, sizeof path, "%s/o.img", dir);
            f = fopen(path, "wb");
            assert_non_null(f);
            for (int i = 0; i < offset; i++)
                fputc(0xA5, f); /* not a float of the cube */
            for (int i = 0; i < 6; i++) {
                uint32_t w;
                memcpy(&w, &want[i], 4);
                for (int k = 0; k < 4; k++)
                    fputc((int)(w >> (8 * (big ? 3 - k : k))) & 0xff, f);
            }
            fclose(f);
            envi_cube c;
            thz_error err = {0};
            assert_int_equal(envi_read_float32(dir, "o", &c, &err), THZ_OK);
            assert_int_equal(c.samples, 3);
            assert_int_equal(c.lines, 2);
            assert_memory_equal(c.data, want, sizeof want);
            envi_cube_fini(&c);
        }
    remove_dir(dir);
}

/* A directory that does not exist is an I/O error naming the file, not a crash. */
static void test_unwritable(void **state)
{
    (void)state;
    float v[6] = {1, 2, 3, 4, 5, 6};
    envi_info info = {.description = "x", .samples = 3, .lines = 2, .bands = 1};
    thz_error err = {0};
    assert_int_equal(envi_write_float32("/nonexistent-thz-dir", "a", &info, v, &err), THZ_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent-thz-dir/a.img"));
}

/* An OUTDIR so long that the file names do not fit: an error naming the limit (the old
 * snprintf into a fixed buffer cut the name silently). */
static void test_path_too_long(void **state)
{
    (void)state;
    thz_scene *scene = make_scene();
    sensor_images img;
    fill_images(&img, 0);
    /* 4080 bytes: "/cam.radiance.img" (17) does not fit in 4095, "/summary.json" (13) does */
    char *outdir = malloc(THZ_PATH_MAX);
    assert_non_null(outdir);
    memset(outdir, 'd', 4080);
    outdir[0] = '/';
    outdir[4080] = '\0';
    thz_error err = {0};
    assert_int_equal(output_write_sensor(outdir, scene, 0, &img, 0, NULL, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "path of 4097 bytes, longer than the limit of 4095"));
    memset(outdir, 'd', 4090);
    outdir[0] = '/';
    outdir[4090] = '\0';
    run_summary rs = {.command = "simulate"};
    assert_int_equal(summary_write(outdir, scene, &rs, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "path of 4103 bytes, longer than the limit of 4095"));
    free(outdir);
    sensor_images_fini(&img);
    scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sensor_files),   cmocka_unit_test(test_no_stderr),
        cmocka_unit_test(test_measured_files), cmocka_unit_test(test_read_byte_order_and_offset),
        cmocka_unit_test(test_unwritable),     cmocka_unit_test(test_path_too_long),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
