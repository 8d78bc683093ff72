/* What the API tests share: a failure counter with messages, a check that a call was
 * refused as bad input, a temporary directory, the two-sensor, two-channel scene of
 * tests/cli/test_simulate.sh as JSON text, file reading, and an image's planes compared
 * with the ENVI files of a run. Header-only so that each test
 * stays one program on the public API alone. */
#ifndef THZ_TESTS_API_TEST_H
#define THZ_TESTS_API_TEST_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "thzmap/thzmap.h"

static int test_failures = 0;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                        \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

/* Stops the test: nothing after a failed call can be checked. */
#define REQUIRE_OK(call, err)                                                                      \
    do {                                                                                           \
        thz_status st_ = (call);                                                                   \
        if (st_ != THZ_OK) {                                                                       \
            fprintf(stderr, "FAIL %s:%d: %s: %s: %s\n", __FILE__, __LINE__, #call,                 \
                    thz_status_name(st_), (err)->message);                                         \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

/* A call refused as bad input (THZ_ERR_INPUT) whose message holds needle; what names the
 * case in the failure. */
static inline void expect_input_error(thz_status st, const thz_error *err, const char *needle,
                                      const char *what)
{
    CHECK(st == THZ_ERR_INPUT, "%s: %s (%s)", what, thz_status_name(st), err->message);
    CHECK(strstr(err->message, needle) != NULL, "%s: '%s' not in '%s'", what, needle, err->message);
}

/* The scene (20000 photons per channel, photon-map: the integrator that fires photons and
 * has no passes; settings may change both). Both sensors have optics and noise (an Airy
 * PSF by FFT, a Gaussian one applied directly), so the measured planes are compared
 * too. */
static const char test_scene_json[] =
    "{\n"
    "  \"format\": \"thzmap-scene/1\",\n"
    "  \"name\": \"api-test\",\n"
    "  \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.05},\n"
    "               {\"frequency_thz\": 0.9, \"relative_width\": 0.02}],\n"
    "  \"materials\": {\n"
    "    \"wall\": {\"reflectivity\": 0.2},\n"
    "    \"paint\": {\"reflectivity\": [[0.2, 0.05], [1.2, 0.3]], \"color\": [0.8, 0.2, 0.2]},\n"
    "    \"cloth\": {\"reflectivity\": 0.05, \"attenuation_per_m\": 200, \"transmission\": "
    "\"straight\"}\n"
    "  },\n"
    "  \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.05},\n"
    "  \"objects\": [\n"
    "    {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": "
    "295,\n"
    "     \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},\n"
    "    {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"paint\", \"temperature_k\": "
    "310,\n"
    "     \"shape\": {\"type\": \"box\", \"size_m\": [0.6, 0.05, 0.5]},\n"
    "     \"transform\": {\"translate_m\": [0, 0.5, 0]}},\n"
    "    {\"name\": \"veil\", \"type\": \"shell\", \"thickness_m\": 0.001, \"material\": "
    "\"cloth\",\n"
    "     \"temperature_k\": 300, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.4, 0.4]},\n"
    "     \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [0.2, 0.1, 0]}}\n"
    "  ],\n"
    "  \"sensors\": [\n"
    "    {\"name\": \"cam\", \"position_m\": [0, -0.9, 0], \"look_at_m\": [0, 0.5, 0],\n"
    "     \"fov_deg\": 70, \"resolution\": [20, 16], \"oversampling\": 2, \"normalize_to_k\": "
    "295,\n"
    "     \"aperture_m2\": 0.01, \"aperture_diameter_m\": 0.01,\n"
    "     \"noise\": {\"receiver_temperature_k\": 600, \"integration_time_s\": 0.001, "
    "\"radiometer\": \"dicke\"}},\n"
    "    {\"name\": \"side\", \"position_m\": [0.8, -0.8, 0.3], \"look_at_m\": [0, 0.4, -0.2],\n"
    "     \"fov_deg\": 50, \"resolution\": [12, 12], \"psf\": \"gaussian\", \"psf_fwhm_deg\": 8,\n"
    "     \"noise\": {\"netd_k\": [0.3, 0.5]}, \"noise_seed\": 3}\n"
    "  ],\n"
    "  \"photons\": {\"per_channel\": 20000, \"seed\": 4},\n"
    "  \"render\": {\"integrator\": \"photon-map\"}\n"
    "}\n";

/* test_scene_json with `from` replaced by `to` (malloc'd); exits when `from` is not in it. */
static inline char *test_scene_with(const char *from, const char *to)
{
    const char *at = strstr(test_scene_json, from);
    if (!at)
        exit(1);
    size_t n = strlen(test_scene_json) - strlen(from) + strlen(to) + 1;
    char *s = malloc(n);
    if (!s)
        exit(1);
    snprintf(s, n, "%.*s%s%s", (int)(at - test_scene_json), test_scene_json, to, at + strlen(from));
    return s;
}

/* A fresh directory under $TMPDIR (or /tmp); exits on failure. */
static inline void test_temp_dir(char *out, size_t n)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(out, n, "%s/thzmap-api-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    if (!mkdtemp(out)) {
        perror("mkdtemp");
        exit(1);
    }
}

/* The whole file (malloc'd) and its size; NULL if it cannot be read. */
static inline unsigned char *test_read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *data = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? 2 * cap : 65536;
            unsigned char *d = realloc(data, cap);
            if (!d) {
                free(data);
                fclose(f);
                return NULL;
            }
            data = d;
        }
        size_t got = fread(data + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    fclose(f);
    *size = n;
    return data;
}

static inline void test_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        perror(path);
        exit(1);
    }
}

/* Compares every ENVI plane of `image` with the files of dir/<sensor>.<quantity>.img, bit
 * for bit (the visual plane is a PNG of 8 bits: not compared). */
static inline void test_compare_image_files(const thz_image *image, const char *dir)
{
    size_t pixels = (size_t)thz_image_columns(image) * thz_image_rows(image);
    for (int p = 0; p < THZ_PLANE_COUNT; p++) {
        if (p == THZ_PLANE_VISUAL_RGB)
            continue; /* a PNG, 8 bits: not the float plane */
        size_t bands = 0;
        const float *plane = thz_image_plane(image, (thz_plane)p, &bands);
        char path[8400];
        snprintf(path, sizeof path, "%s/%s.%s.img", dir, thz_image_sensor_name(image),
                 thz_plane_name((thz_plane)p));
        size_t size = 0;
        unsigned char *file = test_read_file(path, &size);
        if (!plane) {
            CHECK(!file, "%s exists but the image has no %s plane", path,
                  thz_plane_name((thz_plane)p));
            free(file);
            continue;
        }
        CHECK(file != NULL, "%s missing", path);
        if (file) {
            CHECK(size == bands * pixels * sizeof(float), "%s: %zu bytes, plane %zu", path, size,
                  bands * pixels * sizeof(float));
            CHECK(size == bands * pixels * sizeof(float) && memcmp(file, plane, size) == 0,
                  "%s differs from the in-memory plane", path);
        }
        free(file);
    }
}

/* rm -rf dir (a test's own temporary directory). */
static inline void test_remove_dir(const char *dir)
{
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "warning: could not remove %s\n", dir);
}

/* The end of a test: its directory removed when it passed (kept, and said so, when it
 * failed), its failure count printed; the exit status. */
static inline int test_finish(const char *program, const char *dir)
{
    if (test_failures == 0)
        test_remove_dir(dir);
    else
        fprintf(stderr, "kept %s\n", dir);
    printf("%s: %d failures\n", program, test_failures);
    return test_failures ? 1 : 0;
}

#endif
