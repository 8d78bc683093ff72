/* The scene loader, the air and the warnings: the atmosphere's defaults (its
 * temperature from the enclosure around the sensors, the lines model's continuum), CSV
 * materials with overriding keys, and the warnings of a Kirchhoff mismatch, an
 * atmosphere's extent that leaves part of the scene out and a channel outside the models'
 * range. The loader's other cases: test_scene_load.c. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "atmosphere/atmosphere.h"
#include "scene/scene.h"
#include "scene_load_helpers.h"

/* The atmosphere's defaults (scene-format.md "atmosphere"): the background is the air's
 * temperature where the air's is given (0 K, a cold sky, passed every test), the air's
 * is 293.15 K without an enclosure around the sensors; the lines
 * model includes the continuum (continuum off by default passed too): the same
 * attenuation as "continuum": true, more than without it. */
static void test_atmosphere_defaults(void **state)
{
    (void)state;
    thz_scene *s = load_ok(HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS
                           ", \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": "
                           "0.01, \"temperature_k\": 280}}");
    assert_true(s->atmosphere.emitting && s->atmosphere.background_temperature_k == 280.0);
    thz_scene_destroy(s);
    /* no temperature and no enclosure around the sensor (a box seen from outside): the
     * air and its background at 293.15 K (295 K passed every test) */
    s = load_ok(HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS
                ", \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.01}}");
    assert_true(s->atmosphere.air.temperature_k == 293.15 &&
                s->atmosphere.background_temperature_k == 293.15);
    thz_scene_destroy(s);
    double alpha[3];
    static const char *const continuum[3] = {"", ", \"continuum\": true", ", \"continuum\": false"};
    for (int k = 0; k < 3; k++) {
        char json[2048];
        snprintf(json, sizeof json,
                 "%s%s%s%s%s, \"atmosphere\": {\"model\": \"lines\", \"temperature_k\": 296, "
                 "\"pressure_hpa\": 1013.25, \"relative_humidity\": 0.5%s}}",
                 HEAD, CHANNELS, MATERIALS, OBJECT(BOX), SENSORS, continuum[k]);
        s = load_ok(json);
        alpha[k] = atmosphere_alpha_direct_per_m(&s->atmosphere, 0.35e12);
        thz_scene_destroy(s);
    }
    if (!(alpha[0] == alpha[1] && alpha[2] < alpha[1]))
        fail_msg("alpha at 0.35 THz: %g per m by default, %g with the continuum, %g without",
                 alpha[0], alpha[1], alpha[2]);
}

static void test_csv_material_and_warnings(void **state)
{
    (void)state;
    thz_scene *s = NULL;
    thz_error err = {0};
    assert_int_equal(scene_load(SRC "/tests/inputs/scenes/warnings.json", &s, &err), THZ_OK);
    const thz_material *m = &s->materials[0];
    assert_string_equal(m->name, "lossy");
    assert_int_equal(m->reflectivity.n, 2);
    assert_true(m->reflectivity.value[1] == 0.2 && m->reflectivity.freq_hz[1] == 0.5e12);
    assert_int_equal(m->attenuation_per_m.n, 2);
    assert_int_equal(m->emissivity.n, 1); /* the key beside `file` overrides the column */
    assert_true(m->emissivity.value[0] == 0.3);
    assert_true(fabs(s->objects[0].mesh.total_area_m2 - (1.5 + sqrt(3) / 2)) < 1e-6);
    bool kirchhoff = false, table = false, winding = false;
    for (size_t i = 0; i < s->n_warnings; i++) {
        kirchhoff |= strstr(s->warnings[i], "\"plate\"") && strstr(s->warnings[i], "Kirchhoff");
        table |= strstr(s->warnings[i], "\"lossy\", reflectivity") &&
                 strstr(s->warnings[i], "0.300 THz");
        winding |= strstr(s->warnings[i], "\"part\"") && strstr(s->warnings[i], "winding");
    }
    assert_true(kirchhoff);
    assert_true(table);
    assert_true(winding);
    thz_scene_destroy(s);
}

/* Enclosures (closed boxes with inward normals): the air's temperature defaults to the
 * innermost one around the sensors (scene-format.md), here the room at 290 K inside the
 * hall at 310 K; an annex in the hall that holds no sensor is no reason to warn that the
 * sensor is outside "the enclosure". */
static void test_nested_enclosures(void **state)
{
    (void)state;
#define ENCLOSURE(n, t, size, x)                                                                   \
    "{\"name\": \"" n "\", \"type\": \"solid\", \"material\": \"m\", \"temperature_k\": " t ", "   \
    "\"shape\": {\"type\": \"box\", \"size_m\": [" size ", " size ", " size                        \
    "], \"inward\": true}, "                                                                       \
    "\"transform\": {\"translate_m\": [" x ", 0, 0]}}"
#define HALL ENCLOSURE("hall", "310", "10", "0")
#define ROOM ENCLOSURE("room", "290", "2", "0")
#define ANNEX ENCLOSURE("annex", "300", "2", "4")
    static const char json[] = HEAD CHANNELS MATERIALS
        "\"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.01}, "
        "\"objects\": [" HALL ", " ROOM ", " ANNEX "], "
        "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -0.5, 0], "
        "\"look_at_m\": [0, 0.5, 0], \"fov_deg\": 40, \"resolution\": [16, 8]}]}";
#undef HALL
#undef ROOM
#undef ANNEX
#undef ENCLOSURE
    thz_scene *s = load_ok(json);
    assert_true(s->atmosphere.air.temperature_k == 290.0);
    assert_true(s->atmosphere.background_temperature_k == 290.0);
    for (size_t i = 0; i < s->n_warnings; i++)
        fail_msg("warning: %s", s->warnings[i]);
    thz_scene_destroy(s);
}

/* An explicit emissivity more than 0.01 from Kirchhoff's absorptivity is warned of
 * (scene-format.md), one closer is not: R = 0.1 on a solid, A = 0.9. */
static size_t kirchhoff_warnings(const char *emissivity)
{
    char json[1024];
    snprintf(json, sizeof json,
             HEAD CHANNELS
             "\"materials\": {\"m\": {\"reflectivity\": 0.1, \"emissivity\": %s}}, " OBJECT(BOX)
                 SENSORS "}",
             emissivity);
    thz_scene *s = load_ok(json);
    size_t n = 0;
    for (size_t i = 0; i < s->n_warnings; i++)
        n += strstr(s->warnings[i], "Kirchhoff") != NULL;
    thz_scene_destroy(s);
    return n;
}

static void test_kirchhoff_warning_threshold(void **state)
{
    (void)state;
    assert_int_equal(kirchhoff_warnings("0.9"), 0);
    assert_int_equal(kirchhoff_warnings("0.895"), 0);
    assert_int_equal(kirchhoff_warnings("0.88"), 1);
}

/* How many of the scene's warnings name `what` and the atmosphere's extent. */
static size_t extent_warnings(const char *extent, const char *what)
{
    char json[1024];
    snprintf(json, sizeof json,
             HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS
             ", \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.1, "
             "\"temperature_k\": 290, %s}}",
             extent);
    thz_scene *s = load_ok(json);
    size_t n = 0;
    for (size_t i = 0; i < s->n_warnings; i++)
        n += strstr(s->warnings[i], what) && strstr(s->warnings[i], "atmosphere's extent");
    thz_scene_destroy(s);
    return n;
}

/* An extent that leaves out part of the scene is warned about (free paths there still
 * attenuate and emit); surfaces on its faces are inside. */
static void test_atmosphere_extent_warnings(void **state)
{
    (void)state;
    const char *faces = "\"extent_min_m\": [-0.5, -0.5, -0.5], \"extent_max_m\": [0.5, 0.5, 0.5]";
    const char *inner = "\"extent_min_m\": [-0.4, -0.4, -0.4], \"extent_max_m\": [0.4, 0.4, 0.4]";
    const char *all = "\"extent_min_m\": [-9, -9, -9], \"extent_max_m\": [9, 9, 9]";
    assert_int_equal(extent_warnings(faces, "object \"o\""), 0);
    assert_int_equal(extent_warnings(faces, "sensor \"c\""), 1); /* the camera at y = -5 */
    assert_int_equal(extent_warnings(inner, "object \"o\""), 1);
    assert_int_equal(extent_warnings(all, "object"), 0);
    assert_int_equal(extent_warnings(all, "sensor"), 0);
}

/* How many of the scene's warnings say that a channel lies outside the frequencies the
 * models are meant for, with one channel at `thz`. */
static size_t frequency_warnings(const char *thz)
{
    char json[1024];
    snprintf(json, sizeof json,
             HEAD
             "\"channels\": [{\"frequency_thz\": %s, \"relative_width\": 0.01}], " MATERIALS OBJECT(
                 BOX) SENSORS "}",
             thz);
    thz_scene *s = load_ok(json);
    size_t n = 0;
    for (size_t i = 0; i < s->n_warnings; i++)
        n += strstr(s->warnings[i], "the range thzmap's models are meant for") != NULL;
    thz_scene_destroy(s);
    return n;
}

/* The range's ends, 0.05 and 10 THz, are inside it (0.05 THz was warned about as outside
 * 0.05 to 10 THz: its centre in Hz times 1e-12 rounds to 0.049999...). */
static void test_frequency_range_ends(void **state)
{
    (void)state;
    assert_int_equal(frequency_warnings("0.05"), 0);
    assert_int_equal(frequency_warnings("10"), 0);
    assert_int_equal(frequency_warnings("0.0499"), 1);
    assert_int_equal(frequency_warnings("10.01"), 1);
}

/* The humidity keys mean what scene-format.md says: h2o_vmr 0.01 at 296 K and 1013.25 hPa
 * is 0.01 x 101325 Pa x 18.015 g/mol / (8.3145 J/(mol K) x 296 K) = 7.417 g/m^3 of water
 * vapour (the ideal gas), and water_vapour_g_m3 7.5 is 7.5 g/m^3. The loader's kinds of
 * the keys water_vapour_g_m3 and h2o_vmr swapped (a mutant) passed every test, none of
 * whose scenes gave those keys: 0.01 of vapour was read as 0.01 g/m^3, dry air. */
static void test_humidity_keys(void **state)
{
    (void)state;
    static const char *const keys[2] = {"\"h2o_vmr\": 0.01", "\"water_vapour_g_m3\": 7.5"};
    double rho[2];
    for (int k = 0; k < 2; k++) {
        char json[2048];
        snprintf(json, sizeof json,
                 "%s%s%s%s%s, \"atmosphere\": {\"model\": \"itu-p676\", \"temperature_k\": 296, "
                 "\"pressure_hpa\": 1013.25, %s}}",
                 HEAD, CHANNELS, MATERIALS, OBJECT(BOX), SENSORS, keys[k]);
        thz_scene *s = load_ok(json);
        rho[k] = atm_air_h2o_density_g_m3(&s->atmosphere.air);
        if (k == 0)
            assert_true(fabs(atm_air_h2o_vmr(&s->atmosphere.air) - 0.01) < 1e-12);
        thz_scene_destroy(s);
    }
    double ideal = 0.01 * 101325.0 * 18.015 / (8.3145 * 296.0);
    if (!(fabs(rho[0] - ideal) < 0.005 * ideal && fabs(rho[1] - 7.5) < 1e-9))
        fail_msg("water vapour %g g/m^3 from h2o_vmr 0.01 (ideal gas %g), %g from 7.5 g/m^3",
                 rho[0], ideal, rho[1]);
}

/* A sensor inside a closed solid is warned about, one outside it not, even where it lies
 * within the solid's bounding box and the check's ray from it (oblique, towards +x +y +z)
 * crosses the solid twice: here a sphere of radius 1 and a sensor at its bounding box's
 * corner, 1.56 m from its centre. Counting any crossing as inside (a mutant of
 * check_inside's parity) passed every test, and warned that such a sensor sees the
 * sphere from inside. */
#define SPHERE_SCENE(pos)                                                                          \
    HEAD CHANNELS MATERIALS OBJECT(                                                                \
        "{\"type\": \"sphere\", \"radius_m\": 1}") "\"sensors\": [{\"name\": \"c\", "              \
                                                   "\"position_m\": " pos                          \
                                                   ", \"direction\": [1, 1, 1], "                  \
                                                   "\"fov_deg\": 40, \"resolution\": [16, 8]}]}"

static void test_sensor_inside_by_parity(void **state)
{
    (void)state;
    assert_int_equal(
        load_count_warnings(SPHERE_SCENE("[-0.9, -0.9, -0.9]"), "is inside object", NULL), 0);
    assert_int_equal(load_count_warnings(SPHERE_SCENE("[0, 0, 0.1]"), "is inside object", NULL), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_atmosphere_defaults),
        cmocka_unit_test(test_csv_material_and_warnings),
        cmocka_unit_test(test_nested_enclosures),
        cmocka_unit_test(test_kirchhoff_warning_threshold),
        cmocka_unit_test(test_atmosphere_extent_warnings),
        cmocka_unit_test(test_frequency_range_ends),
        cmocka_unit_test(test_sensor_inside_by_parity),
        cmocka_unit_test(test_humidity_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
