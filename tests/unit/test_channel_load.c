/* The loader's measured channel responses: inline tables and CSV files (centre given or
 * the response-weighted mean, weights as given), and the refusals with their
 * JSON paths or file:line (negative weight, all zero, not ascending, too few points, a
 * missing file, a wrong column, two responses, none), the limit of 4096 channels in a
 * list, and a range's last channel at to_thz exactly. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "scene/scene.h"
#include "scene_load_helpers.h"

/* A scene whose channels are those between the two. */
#define CHANNELS_OPEN HEAD "\"channels\": ["
#define CHANNELS_REST ", " MATERIALS OBJECT(BOX) SENSORS "}"
#define CHANNELS_CLOSE "]" CHANNELS_REST

static void test_tables(void **state)
{
    (void)state;
    thz_scene *s =
        load_ok(CHANNELS_OPEN "{\"name\": \"hat\", \"response\": [[0.34, 4], [0.36, 4]]},"
                              "{\"frequency_thz\": 0.605, \"response_file\": "
                              "\"responses/triangle.csv\"},"
                              "{\"response\": [[0.5, 0], [0.6, 1], [0.9, 0]]},"
                              "{\"frequency_thz\": 0.35, \"relative_width\": 0.01}" CHANNELS_CLOSE);
    assert_int_equal(s->n_channels, 4);
    const thz_channel *hat = &s->channels[0], *tri = &s->channels[1], *skew = &s->channels[2];
    assert_int_equal(hat->n_response, 2);
    assert_true(hat->response_weight[0] == 4.0 && hat->response_weight[1] == 4.0);
    assert_true(fabs(hat->center_hz - 0.35e12) < 1.0);
    assert_true(fabs(channel_bandwidth_hz(hat) - 0.08e12) < 1.0); /* weights as given */
    assert_int_equal(tri->n_response, 3);
    assert_true(tri->center_hz == 0.605e12); /* as given */
    assert_true(tri->response_weight[1] == 2.0);
    assert_true(fabs(channel_bandwidth_hz(tri) - 0.04e12) < 1.0);
    assert_true(fabs(skew->center_hz - 2.0e12 / 3.0) < 1.0); /* (0.5 + 0.6 + 0.9) / 3 THz */
    assert_string_equal(skew->name, "0.667 THz");            /* named by its centre */
    assert_int_equal(s->channels[3].n_response, 0);
    scene_destroy(s);
}

static void test_refusals(void **state)
{
    (void)state;
    load_bad(CHANNELS_OPEN "{\"response\": [[0.34, 1], [0.35, -0.5], [0.36, 1]]}" CHANNELS_CLOSE,
             "channels[0].response[1][1]: expected a number >= 0, got -0.5");
    load_bad(CHANNELS_OPEN "{\"response\": [[0.34, 0], [0.36, 0]]}" CHANNELS_CLOSE,
             "channels[0].response: every weight is 0 (expected at least one > 0)");
    load_bad(CHANNELS_OPEN "{\"response\": [[0.36, 1], [0.34, 1]]}" CHANNELS_CLOSE,
             "channels[0].response[1][0]: frequencies must increase strictly, got 0.34 THz after "
             "0.36 THz");
    load_bad(CHANNELS_OPEN "{\"response\": [[0.34, 1], [0.34, 1]]}" CHANNELS_CLOSE,
             "must increase strictly");
    load_bad(CHANNELS_OPEN "{\"response\": [[0.34, 1]]}" CHANNELS_CLOSE,
             "channels[0].response: expected at least 2 points [frequency_thz, weight], got 1");
    load_bad(CHANNELS_OPEN "{\"response\": 1}" CHANNELS_CLOSE,
             "channels[0].response: expected a table [[frequency_thz, weight], ...], got a number");
    load_bad(CHANNELS_OPEN "{\"response\": [[0.34, 1], [0.36]]}" CHANNELS_CLOSE,
             "channels[0].response[1]: expected a pair [frequency_thz, value]");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/none.csv\"}" CHANNELS_CLOSE,
             "channels[0].response_file: ");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/none.csv\"}" CHANNELS_CLOSE,
             "none.csv");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/negative.csv\"}" CHANNELS_CLOSE,
             "negative.csv:3: row 2, column 'weight': expected a number >= 0, got -0.5");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/descending.csv\"}" CHANNELS_CLOSE,
             "descending.csv:4: row 3: frequencies must increase strictly");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/zero.csv\"}" CHANNELS_CLOSE,
             "zero.csv: every weight is 0");
    load_bad(CHANNELS_OPEN "{\"response_file\": \"responses/wrong_column.csv\"}" CHANNELS_CLOSE,
             "wrong_column.csv: the header names no column 'weight'");
    load_bad(CHANNELS_OPEN
             "{\"frequency_thz\": 0.3, \"response\": [[0.34, 1], [0.36, 1]]}" CHANNELS_CLOSE,
             "channels[0].frequency_thz: expected a frequency where the response is > 0 (0.34 to "
             "0.36 THz), got 0.3");
    load_bad(CHANNELS_OPEN
             "{\"frequency_thz\": 0.35, \"relative_width\": 0.01, \"response\": [[0.34, 1], "
             "[0.36, 1]]}" CHANNELS_CLOSE,
             "channels[0]: conflicting responses (expected exactly one of relative_width, "
             "response, response_file)");
    load_bad(CHANNELS_OPEN "{\"frequency_thz\": 0.35}" CHANNELS_CLOSE,
             "channels[0]: missing spectral response (expected exactly one of relative_width");
    load_bad(CHANNELS_OPEN "{\"relative_width\": 0.01}" CHANNELS_CLOSE,
             "channels[0].frequency_thz: missing key");
}

/* scene-format.md: at most 4096 channels, in a list as in a range; a range's ends are
 * the given numbers exactly (0.3 + (0.9 - 0.3) is 0.9000000000000001). A list's limit
 * doubled, and the range's last channel left at from + (to - from) (mutants), passed
 * every test. */
static void test_channel_count_and_range_ends(void **state)
{
    (void)state;
    size_t size = 4097 * 80 + sizeof CHANNELS_OPEN CHANNELS_CLOSE;
    char *json = test_malloc(size);
    for (unsigned n = 4096; n <= 4097; n++) {
        size_t used = (size_t)snprintf(json, size, "%s", CHANNELS_OPEN);
        for (unsigned i = 0; i < n; i++) {
            used += (size_t)snprintf(json + used, size - used, i ? "," : "");
            used += (size_t)snprintf(json + used, size - used,
                                     "{\"frequency_thz\": 0.35, \"relative_width\": 0.01, "
                                     "\"name\": \"c%04u\"}",
                                     i);
        }
        snprintf(json + used, size - used, "%s", CHANNELS_CLOSE);
        if (n == 4096) {
            thz_scene *s = load_ok(json);
            assert_int_equal(s->n_channels, 4096);
            scene_destroy(s);
        } else {
            load_bad(json, "channels: expected at most 4096 channels, got 4097");
        }
    }
    /* a range instead of a list: CHANNELS_REST, without the list's closing bracket */
    snprintf(json, size, "%s",
             HEAD "\"channels\": {\"from_thz\": 0.3, \"to_thz\": 0.9, \"count\": 2, "
                  "\"relative_width\": 0.01}" CHANNELS_REST);
    thz_scene *s = load_ok(json);
    test_free(json);
    assert_true(s->channels[0].center_hz == 0.3e12 && s->channels[1].center_hz == 0.9e12);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tables),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_channel_count_and_range_ends),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
