/* The fingerprint a photon map is matched against (scene/scene_hash.h): what `render`
 * checks a map file against and what lets a batch frame render from its base frame's
 * photons (scene-format.md, "Photons fired once for frames that differ only in their
 * sensors"). Every value of the scene that the photon phase reads must move its part of
 * the fingerprint, else a map fired for other optics or channels is used, and the user
 * gets another scene's images without a word; the sensors must move none, else no frame
 * of a moving camera reuses photons. Here the values no other test changes: a Ward lobe's
 * alpha_y, a spectral table's frequencies, an emitting air's background temperature and
 * extent, a measured response's weights, a line model's switch (its air state alike), a
 * complex index (its R, T and eps follow from it, and none of the material's spectra holds
 * it: a map fired for n = 2 was taken to render n = 3). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "scene/scene.h"
#include "scene/scene_hash.h"

/* The values a variant changes, in the scene's units. */
typedef struct variant {
    double alpha_y;      /* the Ward lobe's spread across the tangent */
    double table_hi_thz; /* the frequency of the reflectivity table's second row */
    double background_k; /* beyond the air's extent */
    double extent_x_m;   /* the extent's upper x */
    double weight;       /* the measured response's second weight */
    double sensor_x_m;   /* the sensor's position */
} variant;

static const variant base = {0.2, 1.2, 3.0, 3.0, 1.0, 0.0};

static scene_hash hash_of(variant v)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"format\": \"thzmap-scene/1\","
             " \"channels\": [{\"name\": \"m\", \"frequency_thz\": 0.35, \"response\": [[0.34, 1], "
             "[0.35, %.17g],"
             "   [0.36, 1]]}],"
             " \"materials\": {\"paint\": {\"reflectivity\": [[0.2, 0.05], [%.17g, 0.12]],"
             "   \"reflection\": {\"model\": \"ward\", \"alpha_x\": 0.1, \"alpha_y\": %.17g}}},"
             " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.1,"
             "   \"emitting\": true, \"temperature_k\": 290, \"background_temperature_k\": %.17g,"
             "   \"extent_min_m\": [-3, -3, -3], \"extent_max_m\": [%.17g, 3, 3]},"
             " \"objects\": [{\"name\": \"box\", \"type\": \"solid\", \"material\": \"paint\","
             "   \"temperature_k\": 300, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1]}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [%.17g, -2, 0],"
             "   \"look_at_m\": [0, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}]}",
             v.weight, v.table_hi_thz, v.alpha_y, v.background_k, v.extent_x_m, v.sensor_x_m);
    thz_scene *s = NULL;
    thz_error err = {0};
    if (scene_load_string(text, THZ_SOURCE_DIR, "t.json", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    scene_hash h;
    scene_hash_compute(s, &h);
    scene_destroy(s);
    return h;
}

/* Changed in one value, the optics (or the channels) differ and the rest are equal. */
static void expect_moves(variant v, const char *what, int channels)
{
    scene_hash a = hash_of(base), b = hash_of(v);
    if (a.geometry != b.geometry)
        fail_msg("%s: the geometry's fingerprint moved", what);
    if ((a.optics != b.optics) != !channels)
        fail_msg("%s: the optics' fingerprint %s", what, channels ? "moved" : "stayed");
    if ((a.channels != b.channels) != channels)
        fail_msg("%s: the channels' fingerprint %s", what, channels ? "stayed" : "moved");
}

static void test_photon_inputs_move_it(void **state)
{
    (void)state;
    variant v = base;
    v.alpha_y = 0.3;
    expect_moves(v, "alpha_y 0.2 -> 0.3", 0);
    v = base;
    v.table_hi_thz = 1.0; /* the same reflectivities at other frequencies */
    expect_moves(v, "the table's second frequency 1.2 -> 1.0 THz", 0);
    v = base;
    v.background_k = 300.0;
    expect_moves(v, "background_temperature_k 3 -> 300", 0);
    v = base;
    v.extent_x_m = 4.0;
    expect_moves(v, "extent_max_m's x 3 -> 4 m", 0);
    v = base;
    v.weight = 0.5; /* the centre given: the weights alone differ */
    expect_moves(v, "the response's middle weight 1 -> 0.5", 1);
}

/* The lines model without its continuum: the same air state (temperature, pressure,
 * humidity), another alpha, which only the prepared tables carry. */
static void test_line_switch_moves_it(void **state)
{
    (void)state;
    scene_hash h[2];
    for (int i = 0; i < 2; i++) {
        char text[2048];
        snprintf(text, sizeof text,
                 "{\"format\": \"thzmap-scene/1\","
                 " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.02}],"
                 " \"materials\": {\"wall\": {\"reflectivity\": 0.0}},"
                 " \"atmosphere\": {\"model\": \"lines\", \"temperature_k\": 290,"
                 "   \"pressure_hpa\": 1000, \"relative_humidity\": 0.4, \"continuum\": %s},"
                 " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
                 "   \"temperature_k\": 295, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1],"
                 "   \"inward\": true}}],"
                 " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, 0, 0],"
                 "   \"look_at_m\": [1, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}]}",
                 i ? "false" : "true");
        thz_scene *s = NULL;
        thz_error err = {0};
        if (scene_load_string(text, THZ_SOURCE_DIR, "t.json", &s, &err) != THZ_OK)
            fail_msg("%s", err.message);
        scene_hash_compute(s, &h[i]);
        scene_destroy(s);
    }
    assert_true(h[0].optics != h[1].optics);
    assert_true(h[0].geometry == h[1].geometry && h[0].channels == h[1].channels);
}

/* A camera moved (the air's temperature given, so not the enclosure's around it): the
 * photons are the same, and so is every part of the fingerprint. */
static void test_sensors_move_none(void **state)
{
    (void)state;
    variant v = base;
    v.sensor_x_m = 1.0;
    scene_hash a = hash_of(base), b = hash_of(v);
    assert_true(a.geometry == b.geometry);
    assert_true(a.optics == b.optics);
    assert_true(a.channels == b.channels);
}

/* The optics' fingerprint of a box of material `material` (a JSON object). */
static uint64_t optics_of(const char *material)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"format\": \"thzmap-scene/1\","
             " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.02}],"
             " \"materials\": {\"m\": %s},"
             " \"objects\": [{\"name\": \"box\", \"type\": \"solid\", \"material\": \"m\","
             "   \"temperature_k\": 300, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1]}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -2, 0],"
             "   \"look_at_m\": [0, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}]}",
             material);
    thz_scene *s = NULL;
    thz_error err = {0};
    if (scene_load_string(text, THZ_SOURCE_DIR, "t.json", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    scene_hash h;
    scene_hash_compute(s, &h);
    scene_destroy(s);
    return h.optics;
}

/* A complex index, constant, tabled or a permittivity model, changed in one value. */
static void test_complex_index_moves_it(void **state)
{
    (void)state;
    static const char *const pairs[][2] = {
        {"{\"refractive_index\": [2, 0.01]}", "{\"refractive_index\": [3, 0.01]}"},
        {"{\"refractive_index\": [2, 0.01]}", "{\"refractive_index\": [2, 0.02]}"},
        {"{\"refractive_index\": [[0.3, 2, 0.01], [0.4, 2.1, 0.01]]}",
         "{\"refractive_index\": [[0.3, 2, 0.01], [0.4, 2.2, 0.01]]}"},
        {"{\"permittivity_model\": {\"model\": \"debye\", \"eps_inf\": 2, \"eps_s\": 4,"
         " \"tau_ps\": 1}}",
         "{\"permittivity_model\": {\"model\": \"debye\", \"eps_inf\": 2, \"eps_s\": 4,"
         " \"tau_ps\": 1.1}}"},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++)
        if (optics_of(pairs[i][0]) == optics_of(pairs[i][1]))
            fail_msg("%s -> %s: the optics' fingerprint stayed", pairs[i][0], pairs[i][1]);
    /* and the same index gives the same fingerprint */
    assert_true(optics_of(pairs[0][0]) == optics_of(pairs[1][0]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_photon_inputs_move_it),
        cmocka_unit_test(test_line_switch_moves_it),
        cmocka_unit_test(test_sensors_move_none),
        cmocka_unit_test(test_complex_index_moves_it),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
