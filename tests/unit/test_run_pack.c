/* A finished run as bytes and back (run/run_pack.h), as a batch frame computed on another
 * MPI rank reaches rank 0: a simulate run (two sensors, one with noise: the measured
 * planes) and a render run from its photons are packed, unpacked for a scene loaded
 * again from the same text, and packed again: the bytes must be equal, every plane of
 * every image and the summary text equal to the original run's; damaged, short and
 * other-scene bytes are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "api/api.h"
#include "run/run_pack.h"
#include "thzmap/thzmap.h"

/* A warm box in a room, two cameras (the second with receiver noise), two channels. */
static const char *pack_json_head =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"pack-unit\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.02}";
static const char *pack_json_tail =
    "],"
    " \"materials\": {\"wall\": {\"reflectivity\": 0.1}, \"grey\": {\"reflectivity\": 0.5}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
    "    \"temperature_k\": 295,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 6, 2], \"inward\": true}},"
    "   {\"name\": \"box\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 320,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.4, 0.4, 0.4]}}],"
    " \"sensors\": ["
    "   {\"name\": \"cam\", \"position_m\": [0, -2.5, 0], \"direction\": [0, 1, 0],"
    "    \"fov_deg\": 20, \"resolution\": [13, 9]},"
    "   {\"name\": \"noisy\", \"position_m\": [0.3, -2.5, 0], \"direction\": [0, 1, 0],"
    "    \"fov_deg\": 25, \"resolution\": [7, 5], \"noise\": {\"netd_k\": 0.5}}],"
    " \"photons\": {\"per_channel\": 5000, \"seed\": 11},"
    " \"render\": {\"integrator\": \"photon-map\"}}";

/* The scene's text with two channels, or one. */
static void pack_json(char *buf, size_t size, int two)
{
    snprintf(buf, size, "%s%s%s", pack_json_head,
             two ? ", {\"frequency_thz\": 0.9, \"relative_width\": 0.02}" : "", pack_json_tail);
}

typedef struct pack_fixture {
    thz_context *ctx;
    thz_scene *scene, *again; /* the same text loaded twice: sender's and receiver's */
    thz_run *simulated, *rendered;
} pack_fixture;

static int pack_setup(void **state)
{
    pack_fixture *f = calloc(1, sizeof *f);
    thz_error err;
    if (!f || !(f->ctx = thz_context_create()))
        return -1;
    thz_context_set_threads(f->ctx, 1);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.keep_photons = 1;
    char text[2048];
    pack_json(text, sizeof text, 1);
    if (thz_scene_load_string(text, NULL, NULL, &f->scene, &err) != THZ_OK ||
        thz_scene_load_string(text, NULL, NULL, &f->again, &err) != THZ_OK ||
        thz_simulate(f->ctx, f->scene, &settings, &f->simulated, &err) != THZ_OK ||
        thz_render_run(f->ctx, f->scene, thz_run_photons(f->simulated), -1, NULL, &f->rendered,
                       &err) != THZ_OK) {
        print_error("set-up: %s\n", err.message);
        return -1;
    }
    *state = f;
    return 0;
}

static int pack_teardown(void **state)
{
    pack_fixture *f = *state;
    thz_run_destroy(f->rendered);
    thz_run_destroy(f->simulated);
    thz_scene_destroy(f->again);
    thz_scene_destroy(f->scene);
    thz_context_destroy(f->ctx);
    free(f);
    return 0;
}

/* Every plane of every image of b equals a's, byte for byte. */
static void assert_same_images(const thz_run *a, const thz_run *b)
{
    assert_int_equal(thz_run_image_count(a), thz_run_image_count(b));
    for (size_t i = 0; i < thz_run_image_count(a); i++) {
        const thz_image *x = thz_run_image(a, i), *y = thz_run_image(b, i);
        assert_int_equal(thz_image_sensor(x), thz_image_sensor(y));
        size_t pixels = (size_t)thz_image_columns(x) * thz_image_rows(x);
        for (int p = 0; p < THZ_PLANE_COUNT; p++) {
            size_t nx, ny;
            const float *px = thz_image_plane(x, (thz_plane)p, &nx);
            const float *py = thz_image_plane(y, (thz_plane)p, &ny);
            assert_int_equal(nx, ny);
            assert_true((px == NULL) == (py == NULL));
            if (px && memcmp(px, py, nx * pixels * sizeof *px) != 0)
                fail_msg("image %zu: plane %s differs", i, thz_plane_name((thz_plane)p));
        }
    }
}

/* run -> bytes -> a run for the scene loaded again -> bytes: both byte strings equal. */
static void round_trip(pack_fixture *f, const thz_run *run, const char *what)
{
    thz_error err;
    uint8_t *bytes = NULL, *again = NULL;
    size_t size = 0, size_again = 0;
    thz_run *back = NULL;
    if (run_pack(&run->rs, &bytes, &size, &err) != THZ_OK ||
        api_run_unpack(f->again, bytes, size, &back, &err) != THZ_OK ||
        run_pack(&back->rs, &again, &size_again, &err) != THZ_OK)
        fail_msg("%s: %s", what, err.message);
    assert_int_equal(size, size_again);
    if (memcmp(bytes, again, size) != 0)
        fail_msg("%s: the bytes of the unpacked run differ", what);
    assert_same_images(run, back);
    assert_string_equal(thz_run_summary_json(run), thz_run_summary_json(back));
    thz_run_totals ta, tb;
    thz_run_get_totals(run, &ta);
    thz_run_get_totals(back, &tb);
    assert_int_equal(ta.n_channels, tb.n_channels);
    assert_int_equal(ta.n_sensors, tb.n_sensors);
    assert_int_equal(ta.photons_fired, tb.photons_fired);
    assert_int_equal(ta.photons_stored, tb.photons_stored);
    assert_int_equal(ta.back_face_samples, tb.back_face_samples);
    assert_int_equal(ta.n_warnings, tb.n_warnings);
    assert_int_equal(ta.max_passes, tb.max_passes);
    assert_int_equal(ta.worst_object, tb.worst_object);
    assert_true(ta.worst_p95_stderr_k == tb.worst_p95_stderr_k);
    assert_true(ta.worst_median_stderr_k == tb.worst_median_stderr_k);
    assert_true(ta.seconds == tb.seconds);
    assert_null(thz_run_photons(back)); /* the maps do not travel */
    thz_run_destroy(back);
    free(again);
    free(bytes);
}

static void test_simulate_round_trip(void **state)
{
    pack_fixture *f = *state;
    /* the noisy camera's measured planes are there to be carried */
    assert_non_null(thz_image_plane(thz_run_image(f->simulated, 1),
                                    THZ_PLANE_MEASURED_BRIGHTNESS_TEMPERATURE, NULL));
    round_trip(f, f->simulated, "simulate");
}

static void test_render_round_trip(void **state)
{
    pack_fixture *f = *state;
    assert_non_null(strstr(thz_run_summary_json(f->rendered), "\"render\""));
    round_trip(f, f->rendered, "render");
}

/* Short, damaged and other-scene bytes are refused, leaving no run. */
static void test_refusals(void **state)
{
    pack_fixture *f = *state;
    thz_error err;
    uint8_t *bytes = NULL;
    size_t size = 0;
    thz_run *back = NULL;
    assert_int_equal(run_pack(&f->simulated->rs, &bytes, &size, &err), THZ_OK);
    size_t cuts[] = {0, 7, 40, size / 2, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        assert_int_equal(api_run_unpack(f->again, bytes, cuts[i], &back, &err), THZ_ERR_INPUT);
        assert_null(back);
    }
    uint8_t *longer = malloc(size + 1);
    assert_non_null(longer);
    memcpy(longer, bytes, size);
    longer[size] = 0;
    assert_int_equal(api_run_unpack(f->again, longer, size + 1, &back, &err), THZ_ERR_INPUT);
    free(longer);
    bytes[0] ^= 1; /* the magic */
    assert_int_equal(api_run_unpack(f->again, bytes, size, &back, &err), THZ_ERR_INPUT);
    bytes[0] ^= 1;
    /* a scene with one channel less */
    char text[2048];
    pack_json(text, sizeof text, 0);
    thz_scene *other = NULL;
    if (thz_scene_load_string(text, NULL, NULL, &other, &err) != THZ_OK)
        fail_msg("the one-channel scene: %s", err.message);
    assert_int_equal(api_run_unpack(other, bytes, size, &back, &err), THZ_ERR_INPUT);
    assert_null(back);
    thz_scene_destroy(other);
    free(bytes);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_simulate_round_trip),
        cmocka_unit_test(test_render_round_trip),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, pack_setup, pack_teardown);
}
