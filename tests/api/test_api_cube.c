/* thz_cube_create and thz_cube_set_object_names: a cube of the caller's values is
 * classified exactly as the same values read from an ENVI file (thz_cube_read) for every
 * method (assignments, confusion, accuracies, class names), the values are copied, and
 * bad sizes, pointers and names are refused with THZ_ERR_INPUT naming the cube; values
 * that are not finite are taken and refused by thz_classify_cube, as a file's are.
 * argv: the thzmap binary (unused), the repository (unused). */
#include <math.h>
#include <stdint.h>

#include "api_test.h"

enum { COLS = 9, ROWS = 7, BANDS = 3, PIXELS = COLS * ROWS };

/* Three classes by column (0-2: A, 3-5: B, 6-8: C), each spectrum its class's plus a
 * deterministic wobble of +-0.5 K; row 0 of the first three columns sees nothing (-1).
 * Each class's spectra have their own shape, so the angle methods tell them apart too. */
static void make_scene(float *tb, float *truth)
{
    static const float mean[3][BANDS] = {{300, 280, 260}, {260, 300, 280}, {280, 260, 300}};
    uint32_t x = 12345;
    for (int r = 0; r < ROWS; r++)
        for (int c = 0; c < COLS; c++) {
            int p = r * COLS + c, k = c / 3;
            truth[p] = r == 0 && c < 3 ? -1.0f : (float)k;
            for (int b = 0; b < BANDS; b++) {
                x = x * 1664525u + 1013904223u;
                tb[b * PIXELS + p] = mean[k][b] + (float)(x >> 8) / 16777216.0f - 0.5f;
            }
        }
}

/* DIR/STEM.hdr and .img: little-endian float32, BSQ, as thzmap writes them. */
static void write_envi(const char *dir, const char *stem, const float *v, int bands,
                       const char *extra)
{
    char path[4200], text[512];
    snprintf(path, sizeof path, "%s/%s.hdr", dir, stem);
    snprintf(text, sizeof text,
             "ENVI\nsamples = %d\nlines = %d\nbands = %d\nheader offset = 0\n"
             "data type = 4\ninterleave = bsq\nbyte order = 0\n%s",
             COLS, ROWS, bands, extra);
    test_write_file(path, text);
    snprintf(path, sizeof path, "%s/%s.img", dir, stem);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        exit(1);
    }
    for (int i = 0; i < bands * PIXELS; i++) {
        uint32_t w;
        memcpy(&w, &v[i], 4);
        unsigned char b[4] = {(unsigned char)w, (unsigned char)(w >> 8), (unsigned char)(w >> 16),
                              (unsigned char)(w >> 24)};
        fwrite(b, 1, 4, f);
    }
    fclose(f);
}

static void check_refusals(const float *tb)
{
    thz_error err = {0};
    thz_cube *cube = (thz_cube *)&err; /* must be set to NULL on a refusal */
    expect_input_error(thz_cube_create("spectra", 0, ROWS, BANDS, tb, &cube, &err), &err,
                       "spectra: 0 columns, 7 rows, 3 bands: expected at least 1", "0 columns");
    CHECK(cube == NULL, "a refused cube was not set to NULL");
    expect_input_error(thz_cube_create("spectra", COLS, 0, BANDS, tb, &cube, &err), &err,
                       "expected at least 1 of each", "0 rows");
    expect_input_error(thz_cube_create("spectra", COLS, ROWS, 0, tb, &cube, &err), &err,
                       "expected at least 1 of each", "0 bands");
    expect_input_error(thz_cube_create("spectra", COLS, ROWS, BANDS, NULL, &cube, &err), &err,
                       "spectra: no values", "NULL data");
    expect_input_error(thz_cube_create("spectra", 1, 1, (1u << 20) + 1, tb, &cube, &err), &err,
                       "1048577 bands: expected at most 1048576", "too many bands");
    /* 2^64 - 2^33 + 1 pixels of 2^20 bands: their bytes overflow a size_t (the check comes
     * before anything is read from tb) */
    expect_input_error(thz_cube_create("big", UINT32_MAX, UINT32_MAX, 1u << 20, tb, &cube, &err),
                       &err, "big: 4294967295 x 4294967295 pixels of 1048576 bands", "overflow");
    expect_input_error(thz_cube_create("", COLS, ROWS, BANDS, tb, &cube, &err), &err,
                       "an empty name", "empty name");
    expect_input_error(thz_cube_create("x", COLS, ROWS, BANDS, tb, NULL, &err), &err,
                       "no place for the cube", "NULL out");
    CHECK(cube == NULL, "a refused cube was not set to NULL");
    /* no name: "cube" in messages */
    REQUIRE_OK(thz_cube_create(NULL, COLS, ROWS, BANDS, tb, &cube, &err), &err);
    const char *two[2] = {"A", "B"}, *empty[2] = {"A", ""}, *null[2] = {"A", NULL};
    REQUIRE_OK(thz_cube_set_object_names(cube, two, 2, &err), &err);
    expect_input_error(thz_cube_set_object_names(cube, empty, 2, &err), &err,
                       "cube: object name 1 is empty", "empty object name");
    expect_input_error(thz_cube_set_object_names(cube, null, 2, &err), &err,
                       "cube: object name 1 is NULL", "NULL object name");
    expect_input_error(thz_cube_set_object_names(cube, NULL, 2, &err), &err, "names is NULL",
                       "NULL names");
    expect_input_error(thz_cube_set_object_names(NULL, two, 2, &err), &err, "no cube", "NULL cube");
    /* a refusal keeps the names the cube had */
    CHECK(thz_cube_object_name_count(cube) == 2 && strcmp(thz_cube_object_name(cube, 1), "B") == 0,
          "names after a refusal: %zu", thz_cube_object_name_count(cube));
    REQUIRE_OK(thz_cube_set_object_names(cube, NULL, 0, &err), &err);
    CHECK(thz_cube_object_name_count(cube) == 0 && !thz_cube_object_name(cube, 0),
          "names after clearing: %zu", thz_cube_object_name_count(cube));
    thz_cube_destroy(cube);
}

/* The classification's assignments, confusion and accuracies equal `ref`'s. */
static void check_same(const thz_classification *a, const thz_classification *ref,
                       const char *method)
{
    thz_classification_info ia, ir;
    thz_classification_get_info(a, &ia);
    thz_classification_get_info(ref, &ir);
    CHECK(ia.n_classes == 3 && ir.n_classes == 3, "%s: %zu and %zu classes", method, ia.n_classes,
          ir.n_classes);
    CHECK(ia.pixels == ir.pixels && ia.pixels == PIXELS - 3, "%s: %llu and %llu pixels", method,
          (unsigned long long)ia.pixels, (unsigned long long)ir.pixels);
    CHECK(ia.accuracy == ir.accuracy && ia.training_pixels == ir.training_pixels, "%s: %g vs %g",
          method, ia.accuracy, ir.accuracy);
    CHECK(memcmp(thz_classification_map(a), thz_classification_map(ref),
                 PIXELS * sizeof(int32_t)) == 0,
          "%s: the class maps differ", method);
    CHECK(memcmp(thz_classification_confusion(a), thz_classification_confusion(ref),
                 9 * sizeof(uint64_t)) == 0,
          "%s: the confusion matrices differ", method);
    for (size_t k = 0; k < 3; k++)
        CHECK(strcmp(thz_classification_class_name(a, k), thz_classification_class_name(ref, k)) ==
                  0,
              "%s: class %zu is '%s' against '%s'", method, k, thz_classification_class_name(a, k),
              thz_classification_class_name(ref, k));
}

int main(int argc, char **argv)
{
    (void)argc;
    char dir[4096];
    test_temp_dir(dir, sizeof dir);
    static float tb[BANDS * PIXELS], truth[PIXELS];
    make_scene(tb, truth);
    check_refusals(tb);

    thz_error err = {0};
    thz_cube *mem = NULL, *mem_truth = NULL, *file = NULL, *file_truth = NULL;
    REQUIRE_OK(thz_cube_create("spectra", COLS, ROWS, BANDS, tb, &mem, &err), &err);
    REQUIRE_OK(thz_cube_create("truth", COLS, ROWS, 1, truth, &mem_truth, &err), &err);
    const char *names[3] = {"A", "B", "C"};
    REQUIRE_OK(thz_cube_set_object_names(mem_truth, names, 3, &err), &err);
    write_envi(dir, "cam.brightness_temperature", tb, BANDS, "");
    write_envi(dir, "cam.object_id", truth, 1, "object names = {A, B, C}\n");
    REQUIRE_OK(thz_cube_read(dir, "cam.brightness_temperature", &file, &err), &err);
    REQUIRE_OK(thz_cube_read(dir, "cam.object_id", &file_truth, &err), &err);

    /* the values are copied: the caller's array may change */
    float first = tb[0];
    tb[0] = -1000.0f;
    CHECK(thz_cube_data(mem)[0] == first && thz_cube_data(mem) != tb, "the data are not copied");
    tb[0] = first;
    CHECK(thz_cube_columns(mem) == COLS && thz_cube_rows(mem) == ROWS && thz_cube_bands(mem) == 3,
          "sizes %u x %u x %zu", thz_cube_columns(mem), thz_cube_rows(mem), thz_cube_bands(mem));
    CHECK(memcmp(thz_cube_data(mem), thz_cube_data(file), sizeof tb) == 0,
          "the file's values differ from the made cube's");
    CHECK(thz_cube_wavelength_ghz(mem) == NULL, "a made cube has a wavelength");

    /* every method: a made cube classifies as the file does */
    for (size_t i = 0; thz_classify_method(i); i++) {
        thz_classify_options opt;
        thz_classify_options_init(&opt);
        opt.method = thz_classify_method(i);
        thz_classification *a = NULL, *ref = NULL;
        REQUIRE_OK(thz_classify_cube(mem, mem_truth, &opt, &a, &err), &err);
        REQUIRE_OK(thz_classify_cube(file, file_truth, &opt, &ref, &err), &err);
        check_same(a, ref, opt.method);
        thz_classification_info info;
        thz_classification_get_info(a, &info);
        CHECK(strcmp(info.source, "spectra") == 0 && info.sensor == NULL, "%s: source '%s'",
              opt.method, info.source);
        /* well-separated classes: every method right on every pixel */
        CHECK(info.accuracy == 1.0, "%s: accuracy %g on separable classes", opt.method,
              info.accuracy);
        CHECK(strcmp(thz_classification_class_name(a, 2), "C") == 0, "%s: class 2 '%s'", opt.method,
              thz_classification_class_name(a, 2));
        thz_classification_destroy(a);
        thz_classification_destroy(ref);
    }

    /* what the classifier refuses of a made cube, named by the name it was made with */
    thz_classification *c = NULL;
    tb[2 * PIXELS + 3 * COLS + 4] = NAN;
    thz_cube *bad = NULL;
    REQUIRE_OK(thz_cube_create("spectra", COLS, ROWS, BANDS, tb, &bad, &err), &err);
    expect_input_error(thz_classify_cube(bad, mem_truth, NULL, &c, &err), &err,
                       "spectra: band 3, row 4, column 5 holds a value that is not finite", "NaN");
    CHECK(c == NULL, "a refused classification was given");
    thz_cube_destroy(bad);
    truth[5] = 0.5f;
    REQUIRE_OK(thz_cube_create("truth", COLS, ROWS, 1, truth, &bad, &err), &err);
    expect_input_error(thz_classify_cube(mem, bad, NULL, &c, &err), &err,
                       "truth: pixel 5 holds 0.5, not an object index or -1", "0.5 in the truth");
    thz_cube_destroy(bad);
    REQUIRE_OK(thz_cube_create("truth", COLS, ROWS - 1, 1, truth, &bad, &err), &err);
    expect_input_error(thz_classify_cube(mem, bad, NULL, &c, &err), &err,
                       "truth: the truth is 9 x 6 with 1 bands; expected one band of 9 x 7 like "
                       "spectra",
                       "a truth of another size");
    thz_cube_destroy(bad);

    thz_cube_destroy(mem);
    thz_cube_destroy(mem_truth);
    thz_cube_destroy(file);
    thz_cube_destroy(file_truth);
    return test_finish(argv[0], dir);
}
