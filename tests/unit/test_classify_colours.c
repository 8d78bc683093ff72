/* classify's colours (analysis/classify_output.c): with more classes than any fixed
 * palette holds, every class in classification.json has its own `color` (the palette
 * once repeated after 10 classes: the legend showed two classes in one colour), none is
 * the black of "nothing hit" or the page's white, and S.class.png draws each class in
 * the colour the JSON lists. Read back from the files, as a user would. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "analysis/classify.h"
#include "analysis/classify_output.h"
#include "plot_helpers.h"

enum { CLASSES = 45, STRIPE = 3, COLS = CLASSES * STRIPE, ROWS = 10, PIXELS = COLS * ROWS };

/* Pixels of exactly colour c. */
static size_t count_colour(const unsigned char *px, size_t n, const int *c)
{
    size_t count = 0;
    for (size_t i = 0; i < n; i++)
        count += px[3 * i] == c[0] && px[3 * i + 1] == c[1] && px[3 * i + 2] == c[2];
    return count;
}

static void test_files_agree_and_differ(void **state)
{
    (void)state;
    /* class k: a vertical stripe of STRIPE columns, its own two-band spectrum (K) */
    float *cube = malloc(2 * PIXELS * sizeof *cube);
    int32_t *truth = malloc(PIXELS * sizeof *truth);
    assert_non_null(cube);
    assert_non_null(truth);
    for (size_t p = 0; p < PIXELS; p++) {
        int k = (int)(p % COLS) / STRIPE;
        truth[p] = k;
        cube[p] = 300.0f + (float)k;
        cube[PIXELS + p] = 300.0f + (float)(k % 7) * 3.0f;
    }
    classify_result r;
    thz_error err = {0};
    assert_int_equal(classify_run(cube, 2, PIXELS, truth, CLASSIFY_LDA, 0.5, 1, &r, &err), THZ_OK);
    assert_int_equal(r.n_classes, CLASSES);
    char names[CLASSES][16];
    const char *class_names[CLASSES];
    for (int k = 0; k < CLASSES; k++) {
        snprintf(names[k], sizeof names[k], "obj%d", k);
        class_names[k] = names[k];
    }
    classify_report rep = {.result = &r,
                           .sensor = "cam",
                           .source = "cam",
                           .method = CLASSIFY_LDA,
                           .seed = 1,
                           .train_fraction = 0.5,
                           .columns = COLS,
                           .rows = ROWS,
                           .class_names = class_names};
    char *text = classify_json(&rep, &err);
    assert_non_null(text);
    char *dir = make_tmp_dir(), path[1024];
    assert_int_equal(classify_write_files(dir, &rep, text, &err), THZ_OK);

    snprintf(path, sizeof path, "%s/classification.json", dir);
    json_error_t jerr;
    json_t *root = json_load_file(path, 0, &jerr);
    assert_non_null(root);
    json_t *classes = json_object_get(root, "classes");
    assert_int_equal(json_array_size(classes), CLASSES);
    int colour[CLASSES][3];
    for (size_t k = 0; k < CLASSES; k++) {
        json_t *c = json_object_get(json_array_get(classes, k), "color");
        assert_int_equal(json_array_size(c), 3);
        for (size_t i = 0; i < 3; i++)
            colour[k][i] = (int)json_integer_value(json_array_get(c, i));
        int sum = colour[k][0] + colour[k][1] + colour[k][2];
        if (sum == 0 || sum == 3 * 255)
            fail_msg("class %zu in black or white", k);
        for (size_t j = 0; j < k; j++)
            if (!memcmp(colour[j], colour[k], sizeof colour[k]))
                fail_msg("classes %zu and %zu both in (%d, %d, %d)", j, k, colour[k][0],
                         colour[k][1], colour[k][2]);
    }

    /* S.class.png: each class's colour drawn, in its legend box (14 x 14 pixels at
     * least) and its stripe of the map (the map at least 3 pixels a column) */
    unsigned char *px;
    uint32_t w, h;
    snprintf(path, sizeof path, "%s/cam.class.png", dir);
    read_png(path, &px, &w, &h);
    for (size_t k = 0; k < CLASSES; k++) {
        size_t n = count_colour(px, (size_t)w * h, colour[k]);
        if (n < 200)
            fail_msg("class %zu's colour (%d, %d, %d): %zu pixels of the figure", k, colour[k][0],
                     colour[k][1], colour[k][2], n);
    }
    free(px);
    const char *files[] = {"classification.json", "cam.class.hdr", "cam.class.img",
                           "cam.class.png"};
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        remove(path);
    }
    assert_int_equal(rmdir(dir), 0);
    json_decref(root);
    free(text);
    classify_result_fini(&r);
    free(cube);
    free(truth);
    free(dir);
}

/* Far more classes than the palette: still all distinct, and the same every time. */
static void test_many_distinct(void **state)
{
    (void)state;
    enum { N = 3000 };
    unsigned char(*a)[3] = malloc(N * sizeof *a), (*b)[3] = malloc(N * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    classify_class_colours(N, a);
    classify_class_colours(N, b);
    assert_memory_equal(a, b, N * sizeof *a);
    /* a sort would do, but N^2 / 2 comparisons take a few ms */
    for (size_t k = 0; k < N; k++)
        for (size_t j = 0; j < k; j++)
            if (!memcmp(a[j], a[k], sizeof a[k]))
                fail_msg("classes %zu and %zu both in (%d, %d, %d)", j, k, a[k][0], a[k][1],
                         a[k][2]);
    /* a class's colour does not depend on how many there are */
    classify_class_colours(100, b);
    assert_memory_equal(a, b, 100 * sizeof *a);
    free(a);
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_files_agree_and_differ),
        cmocka_unit_test(test_many_distinct),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
