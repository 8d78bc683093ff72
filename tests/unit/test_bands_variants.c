/* The scene texts of band selection's renders (analysis/bands_variants.c), against
 * docs/analysis.md "Class spread": each variant changes its one nuisance and nothing
 * else: a target's temperature + range (that target alone), the other objects' and the
 * air's + the ambient range, the humidity x (1 - range), every shell's thickness
 * x (1 + range), the sensor turned by the angle range about its up axis (around
 * look_at_m, or its direction turned); every variant holds the air at the nominal
 * temperature, the coarse renders take one sample per pixel and a quarter of the paths.
 * The CLI tests see these only through spreads (> 0.05 K, > 10 x an uncovered plate's),
 * which the humidity raised, the shells thinned, the angle halved, the rotation's axial
 * term dropped, the coarse paths halved or the air moved in a target's render all
 * passed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/bands_values_internal.h"

/* room (290 K, not a target), A (300 K, a target), a shell "cover" (280 K, 1 mm, a
 * target); air at 295 K and 50 % relative humidity; a camera 2 m in front of and 1 m
 * above the point it looks at, oversampling 2. */
static const char scene_text[] =
    "{\"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.01}],"
    " \"atmosphere\": {\"temperature_k\": 295, \"relative_humidity\": 50},"
    " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"temperature_k\": 290},"
    "  {\"name\": \"A\", \"type\": \"solid\", \"temperature_k\": 300},"
    "  {\"name\": \"cover\", \"type\": \"shell\", \"temperature_k\": 280, \"thickness_m\": 0.001}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -2, 1], \"look_at_m\": [0, 0, 0],"
    "  \"up\": [0, 0, 1], \"oversampling\": 2, \"noise\": {\"netd_k\": [0.2, 0.3]}}]}";

static const double thz[2] = {0.4, 0.6}, widths[2] = {0.01, 0.02};
static const bool is_class[3] = {false, true, true};

static bands_setup setup(void)
{
    return (bands_setup){.candidates_thz = thz,
                         .widths = widths,
                         .n_candidates = 2,
                         .target_range_k = 3.0,
                         .ambient_range_k = 2.0,
                         .humidity_range = 0.2,
                         .thickness_range = 0.5,
                         .angle_range_deg = 10.0,
                         .paths_per_sample = 16};
}

/* The variant's document (parsed back) and how many values it changed. */
static json_t *variant(const char *scene, const bands_setup *s, int what, size_t target,
                       bool coarse, int *changed)
{
    json_error_t jerr;
    json_t *root = json_loads(scene, 0, &jerr);
    assert_non_null(root);
    char *text = bands_variant_text(root, s, is_class, what, target, 295.0, coarse, changed);
    assert_non_null(text);
    json_t *doc = json_loads(text, 0, &jerr);
    assert_non_null(doc);
    free(text);
    json_decref(root);
    return doc;
}

/* Object i's temperature. */
static double object_t(const json_t *doc, size_t i)
{
    return json_number_value(
        json_object_get(json_array_get(json_object_get(doc, "objects"), i), "temperature_k"));
}

static void assert_close(double got, double want)
{
    if (!(fabs(got - want) <= 1e-12 * fabs(want)))
        fail_msg("%.15g, expected %.15g", got, want);
}

/* What a variant holds of the others: temperatures (room, A, cover, air), humidity,
 * thickness. */
static void assert_state(const json_t *doc, double room, double a, double cover, double air,
                         double rh, double thickness)
{
    assert_close(object_t(doc, 0), room);
    assert_close(object_t(doc, 1), a);
    assert_close(object_t(doc, 2), cover);
    const json_t *atm = json_object_get(doc, "atmosphere");
    assert_close(json_number_value(json_object_get(atm, "temperature_k")), air);
    assert_close(json_number_value(json_object_get(atm, "relative_humidity")), rh);
    assert_close(json_number_value(json_object_get(
                     json_array_get(json_object_get(doc, "objects"), 2), "thickness_m")),
                 thickness);
}

static void test_each_variant_changes_its_nuisance(void **state)
{
    (void)state;
    bands_setup s = setup();
    int changed;
    json_t *doc = variant(scene_text, &s, VAR_NOMINAL, 0, true, &changed);
    assert_int_equal(changed, 0);
    assert_state(doc, 290, 300, 280, 295, 50, 0.001); /* the air held at the nominal's */
    json_decref(doc);

    doc = variant(scene_text, &s, VAR_TARGETS, 1, true, &changed); /* A alone */
    assert_int_equal(changed, 1);
    assert_state(doc, 290, 303, 280, 295, 50, 0.001);
    json_decref(doc);
    doc = variant(scene_text, &s, VAR_TARGETS, 2, true, &changed); /* the cover alone */
    assert_int_equal(changed, 1);
    assert_state(doc, 290, 300, 283, 295, 50, 0.001);
    json_decref(doc);

    doc = variant(scene_text, &s, VAR_AMBIENT, 0, true, &changed); /* the room and the air */
    assert_int_equal(changed, 2);
    assert_state(doc, 292, 300, 280, 297, 50, 0.001);
    json_decref(doc);

    doc = variant(scene_text, &s, VAR_HUMIDITY, 0, true, &changed); /* downwards */
    assert_int_equal(changed, 1);
    assert_state(doc, 290, 300, 280, 295, 50 * 0.8, 0.001);
    json_decref(doc);

    doc = variant(scene_text, &s, VAR_THICKNESS, 0, true, &changed); /* thicker */
    assert_int_equal(changed, 1);
    assert_state(doc, 290, 300, 280, 295, 50, 0.001 * 1.5);
    json_decref(doc);
}

/* The candidates as the channels; the coarse renders one sample per pixel and a quarter
 * of the paths (16: 4), the full nominal render as the scene asks; a per-channel netd_k
 * list, which cannot follow the candidates, dropped. */
static void test_channels_and_render_settings(void **state)
{
    (void)state;
    bands_setup s = setup();
    int changed;
    for (int coarse = 0; coarse < 2; coarse++) {
        json_t *doc = variant(scene_text, &s, VAR_NOMINAL, 0, coarse, &changed);
        const json_t *ch = json_object_get(doc, "channels");
        assert_int_equal(json_array_size(ch), 2);
        for (size_t c = 0; c < 2; c++) {
            const json_t *e = json_array_get(ch, c);
            assert_close(json_number_value(json_object_get(e, "frequency_thz")), thz[c]);
            assert_close(json_number_value(json_object_get(e, "relative_width")), widths[c]);
        }
        const json_t *render = json_object_get(doc, "render");
        assert_string_equal(json_string_value(json_object_get(render, "integrator")), "path");
        assert_int_equal(json_integer_value(json_object_get(render, "paths_per_sample")),
                         coarse ? 4 : 16);
        const json_t *cam = json_array_get(json_object_get(doc, "sensors"), 0);
        assert_int_equal(json_integer_value(json_object_get(cam, "oversampling")), coarse ? 1 : 2);
        assert_null(json_object_get(cam, "noise"));
        json_decref(doc);
    }
    assert_int_equal(bands_coarse_paths(16), 4);
    assert_int_equal(bands_coarse_paths(7), 1);
    assert_int_equal(bands_coarse_paths(3), 1);
}

static void vec3(const json_t *doc, const char *key, double v[3])
{
    const json_t *a = json_object_get(json_array_get(json_object_get(doc, "sensors"), 0), key);
    assert_int_equal(json_array_size(a), 3);
    for (size_t i = 0; i < 3; i++)
        v[i] = json_number_value(json_array_get(a, i));
}

/* The angle between the horizontal parts (about up = z) of u and v, degrees. */
static double turn_deg(const double u[3], const double v[3])
{
    double dot = u[0] * v[0] + u[1] * v[1], cross = u[0] * v[1] - u[1] * v[0];
    return fabs(atan2(cross, dot)) * 180.0 / M_PI;
}

/* The sensor turned by 10 degrees about its up axis: around look_at_m, at the same
 * distance and height (the offset's part along the axis kept), the look_at_m point
 * kept; given a direction instead, the direction turned the same way, its part along
 * the axis kept. */
static void test_sensor_turned_about_up(void **state)
{
    (void)state;
    bands_setup s = setup();
    int changed;
    json_t *doc = variant(scene_text, &s, VAR_ANGLE, 0, true, &changed);
    assert_int_equal(changed, 1);
    double pos[3], at[3];
    vec3(doc, "position_m", pos);
    vec3(doc, "look_at_m", at);
    assert_true(at[0] == 0.0 && at[1] == 0.0 && at[2] == 0.0);
    const double before[3] = {0.0, -2.0, 1.0};
    assert_true(fabs(pos[2] - 1.0) < 1e-12);
    assert_true(fabs(hypot(pos[0], pos[1]) - 2.0) < 1e-12);
    if (!(fabs(turn_deg(before, pos) - 10.0) < 1e-9))
        fail_msg("turned by %.6f degrees, expected 10", turn_deg(before, pos));
    assert_state(doc, 290, 300, 280, 295, 50, 0.001); /* nothing else changed */
    json_decref(doc);

    /* the same camera by a direction: turned about its own position */
    json_error_t jerr;
    json_t *root = json_loads(scene_text, 0, &jerr);
    json_t *cam = json_array_get(json_object_get(root, "sensors"), 0);
    json_object_del(cam, "look_at_m");
    json_t *dir = json_array();
    const double d0[3] = {0.0, 0.8, -0.6};
    for (size_t i = 0; i < 3; i++)
        json_array_append_new(dir, json_real(d0[i]));
    json_object_set_new(cam, "direction", dir);
    char *text = json_dumps(root, JSON_COMPACT);
    json_decref(root);
    doc = variant(text, &s, VAR_ANGLE, 0, true, &changed);
    free(text);
    assert_int_equal(changed, 1);
    double d[3];
    vec3(doc, "direction", d);
    vec3(doc, "position_m", pos);
    assert_true(pos[0] == 0.0 && pos[1] == -2.0 && pos[2] == 1.0);
    assert_true(fabs(d[2] + 0.6) < 1e-12 && fabs(hypot(d[0], d[1]) - 0.8) < 1e-12);
    assert_true(fabs(turn_deg(d0, d) - 10.0) < 1e-9);
    json_decref(doc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_each_variant_changes_its_nuisance),
        cmocka_unit_test(test_channels_and_render_settings),
        cmocka_unit_test(test_sensor_turned_about_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
