/* The scene loader: the spec's example scene (geometry, materials, defaults), the
 * channel range shorthand and default names (unique; given names checked among
 * themselves), shapes, transforms, sensors, and a few refusals with their JSON paths (the
 * full table of bad scenes is tests/cli/test_bad_scenes.sh). The atmosphere's defaults,
 * CSV materials and the loader's warnings: test_scene_load_air.c. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "physics/brdf.h"
#include "scene/scene.h"
#include "scene_load_helpers.h"

static void test_example(void **state)
{
    (void)state;
    thz_scene *s = NULL;
    thz_error err = {0};
    assert_int_equal(thz_scene_load(SRC "/examples/plate-in-box/scene.json", &s, &err), THZ_OK);
    assert_string_equal(s->name, "plate-in-box");
    assert_int_equal(s->n_channels, 1);
    assert_string_equal(s->channels[0].name, "0.35 THz");
    assert_true(fabs(s->channels[0].center_hz - 0.35e12) < 1);
    assert_int_equal(s->n_materials, 4);
    assert_string_equal(s->materials[0].name, "wall");
    assert_string_equal(s->materials[3].name, "table");
    assert_int_equal(s->materials[1].reflectivity.n, 2);
    assert_true(s->materials[1].color[0] == 0.8);
    assert_true(s->materials[0].color[1] == 0.6);
    assert_int_equal(s->materials[2].transmission, TRANSMISSION_STRAIGHT);
    assert_int_equal(s->materials[3].reflectivity.n, 5);
    assert_int_equal(s->materials[3].emissivity.n, 0); /* Kirchhoff */
    assert_int_equal(s->atmosphere.model, ATM_CONSTANT);
    assert_int_equal(s->n_objects, 3);
    const thz_object *room = &s->objects[0];
    assert_true(fabs(room->mesh.total_area_m2 - 10.0) < 1e-9);
    assert_true(room->mesh.bbox_min_m[2] == 0.0 && room->mesh.bbox_max_m[2] == 2.0);
    assert_int_equal(s->objects[1].mesh.n_triangles, 4 * 64);
    assert_int_equal(s->objects[2].type, OBJECT_SHELL);
    assert_true(scene_object_two_sided(&s->objects[2]));
    assert_true(s->objects[2].thickness_m == 0.0005);
    assert_int_equal(s->objects[2].mesh.n_triangles, 2 * 64);
    assert_true(fabs(s->objects[2].mesh.bbox_min_m[2] - 0.3) < 1e-6);
    const thz_sensor *c = &s->sensors[0];
    assert_true(fabs(c->direction[1] - 1.0) < 1e-15 && c->direction[0] == 0.0);
    assert_true(c->columns == 64 && c->rows == 64 && c->oversampling == 2);
    assert_int_equal(s->photons.gather_min_photons, 16);
    assert_int_equal(s->n_warnings, 0);
    thz_scene_destroy(s);
}

/* How many of m's triangles face away from the point c (normal . (centroid - c) > 0). */
static size_t faces_away_from(const thz_mesh *m, const double c[3])
{
    size_t n = 0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        double d = 0.0;
        for (int a = 0; a < 3; a++) {
            double centroid = 0.0;
            for (int v = 0; v < 3; v++)
                centroid += m->positions[3 * m->indices[3 * t + v] + a] / 3.0;
            d += m->normals[3 * t + a] * (centroid - c[a]);
        }
        n += d > 0.0;
    }
    return n;
}

static void test_defaults_and_range(void **state)
{
    (void)state;
    thz_scene *s = load_ok(HEAD "\"channels\": {\"from_thz\": 0.2, \"to_thz\": 1.2, \"count\": 6, "
                                "\"relative_width\": 0.02}, " MATERIALS OBJECT(BOX) SENSORS "}");
    assert_string_equal(s->name, "test");
    assert_int_equal(s->n_channels, 6);
    assert_string_equal(s->channels[0].name, "0.200 THz");
    assert_string_equal(s->channels[5].name, "1.200 THz");
    assert_true(fabs(s->channels[2].center_hz - 0.6e12) < 1e-3);
    assert_true(s->channels[5].center_hz == 1.2e12);
    assert_int_equal(s->atmosphere.model, ATM_NONE);
    /* a box's inward defaults to false: all 12 triangles face out (scene-format.md) */
    const double origin[3] = {0.0, 0.0, 0.0};
    assert_int_equal(s->objects[0].mesh.n_triangles, 12);
    assert_int_equal(faces_away_from(&s->objects[0].mesh, origin), 12);
    const thz_sensor *c = &s->sensors[0];
    assert_true(c->aperture_m2 == 1e-2 && c->oversampling == 1 && c->normalize_to_k == 295);
    assert_true(c->up[2] == 1.0);
    assert_true(s->photons.per_channel == 1000000 && s->photons.seed == 1);
    assert_true(s->photons.min_relative_power == 0.01);
    assert_int_equal(s->photons.gather_min_photons, 16);     /* the spec's k (8 passed unseen) */
    assert_int_equal(s->render.integrator, INTEGRATOR_PATH); /* changed: docs/integrators.md */
    assert_false(s->photons.per_channel_given);
    assert_false(s->render.paths_per_sample_given);
    assert_true(s->render.target_noise_k == 0.0 && s->render.max_seconds == 0.0);
    assert_int_equal(s->render.gather_rays, 32);
    assert_int_equal(s->render.paths_per_sample, 16);
    assert_false(s->objects[0].two_sided);
    assert_true(s->materials[0].attenuation_per_m.n == 1);
    /* a material's defaults: no attenuation inside, diffuse transmission (1 per m and
     * "straight" passed every loader test) */
    assert_true(spectrum_eval(&s->materials[0].attenuation_per_m, 0.35e12) == 0.0);
    assert_int_equal(s->materials[0].transmission, TRANSMISSION_DIFFUSE);
    thz_scene_destroy(s);
}

/* The shapes' defaults of scene-format.md "shapes", counted in triangles: a cylinder
 * has caps (2 n side + 2 n cap triangles) and a disk 64 segments; a sphere 4
 * subdivisions, 20 * 4^4 triangles. (Caps off by default left every cylinder open,
 * subdivisions 3 gave 1280 triangles; neither was caught.) */
static void test_shape_defaults(void **state)
{
    (void)state;
    thz_scene *s = load_ok(
        HEAD CHANNELS MATERIALS
        "\"objects\": [{\"name\": \"can\", \"type\": \"solid\", \"material\": \"m\", "
        "\"temperature_k\": 300, \"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.5, "
        "\"height_m\": 1}}, {\"name\": \"ball\", \"type\": \"solid\", \"material\": \"m\", "
        "\"temperature_k\": 300, \"shape\": {\"type\": \"sphere\", \"radius_m\": 0.5}}, "
        "{\"name\": \"disk\", \"type\": \"solid\", \"material\": \"m\", \"temperature_k\": 300, "
        "\"shape\": {\"type\": \"disk\", \"radius_m\": 0.5}}], " SENSORS "}");
    assert_int_equal(s->objects[0].mesh.n_triangles, 2 * 64 + 2 * 64);
    /* the caps close it at z = 0 and z = height_m: a base at the origin */
    assert_true(s->objects[0].mesh.bbox_min_m[2] == 0.0 && s->objects[0].mesh.bbox_max_m[2] == 1.0);
    assert_int_equal(s->objects[1].mesh.n_triangles, 20 * 4 * 4 * 4 * 4);
    assert_int_equal(s->objects[2].mesh.n_triangles, 64);
    thz_scene_destroy(s);
}

/* scene-format.md: objects lie within 1e9 m of the origin; one just inside that limit
 * (its top at 999 999 000.5 m, in float 999 999 040 m) loads. (A limit of 5e8 m passed
 * every test: only objects beyond it, at 2e9 m, were tried.) */
static void test_far_object_within_limit(void **state)
{
    (void)state;
    thz_scene *s = load_ok(
        HEAD CHANNELS MATERIALS
        "\"objects\": [{\"name\": \"far\", \"type\": \"solid\", \"material\": \"m\", "
        "\"temperature_k\": 300, \"shape\": " BOX ", \"transform\": {\"translate_m\": [0, 0, "
        "999999000]}}], " SENSORS "}");
    assert_true(s->objects[0].mesh.bbox_max_m[2] > 9.9e8 &&
                s->objects[0].mesh.bbox_max_m[2] <= 1e9);
    thz_scene_destroy(s);
}

static void test_blocks(void **state)
{
    (void)state;
    thz_scene *s = load_ok(
        HEAD CHANNELS MATERIALS
        "\"objects\": [{\"name\": \"ball\", \"type\": \"solid\", \"material\": \"m\", "
        "\"temperature_k\": 0, \"two_sided\": true, "
        "\"shape\": {\"type\": \"sphere\", \"radius_m\": 0.5, \"subdivisions\": 2}, "
        "\"transform\": {\"scale\": 2, \"rotate_deg\": [0, 0, 45], \"translate_m\": [1, 2, 3]}}, "
        "{\"name\": \"disk\", \"type\": \"shell\", \"thickness_m\": 0.001, \"material\": \"m\", "
        "\"temperature_k\": 290, \"shape\": {\"type\": \"disk\", \"radius_m\": 1, \"segments\": "
        "8}, "
        "\"transform\": {\"scale\": [1, -1, 1]}}], "
        "\"sensors\": [{\"name\": \"a\", \"position_m\": [0, 0, 0], \"direction\": [3, 0, 4], "
        "\"up\": [0, 1, 0], \"fov_deg\": 10, \"resolution\": [1, 1], \"aperture_m2\": 0.5, "
        "\"oversampling\": 16, \"normalize_to_k\": 77}], "
        "\"photons\": {\"per_channel\": 1e3, \"seed\": 42, \"min_relative_power\": 0.5, "
        "\"gather_min_photons\": 2}, "
        "\"render\": {\"integrator\": \"path\", \"gather_rays\": 3, \"paths_per_sample\": 4}}");
    const thz_object *ball = &s->objects[0];
    assert_true(ball->two_sided);
    assert_int_equal(ball->mesh.n_triangles, 320);
    assert_true(fabs(ball->mesh.bbox_max_m[2] - 4.0) < 1e-5);
    assert_true(fabs(ball->mesh.bbox_min_m[2] - 2.0) < 1e-5);
    /* the mirrored disk keeps its normal +z (winding flipped with the mirror) */
    const thz_object *disk = &s->objects[1];
    for (size_t t = 0; t < disk->mesh.n_triangles; t++)
        assert_true(disk->mesh.normals[3 * t + 2] > 0.999f);
    assert_true(fabs(s->sensors[0].direction[0] - 0.6) < 1e-15);
    assert_true(fabs(s->sensors[0].direction[2] - 0.8) < 1e-15);
    assert_true(s->photons.per_channel == 1000 && s->photons.seed == 42);
    assert_int_equal(s->photons.gather_min_photons, 2);
    assert_int_equal(s->render.integrator, INTEGRATOR_PATH);
    assert_int_equal(s->render.gather_rays, 3);
    assert_int_equal(s->render.paths_per_sample, 4);
    thz_scene_destroy(s);
}

/* scene_object_optics_constant: constants only, no index; such an object's optics are
 * the same at every frequency (what the photon phase and the renderer cache), a table's
 * are not. */
static void test_optics_constant(void **state)
{
    (void)state;
    thz_scene *s = load_ok(
        HEAD CHANNELS
        "\"materials\": {\"c\": {\"reflectivity\": 0.1, \"attenuation_per_m\": 5, "
        "\"emissivity\": 0.8}, \"t\": {\"reflectivity\": [[0.2, 0.05], [1.2, 0.12]]}, "
        "\"a\": {\"reflectivity\": 0.1, \"attenuation_per_m\": [[0.2, 60], [1.2, 900]]}, "
        "\"i\": {\"refractive_index\": [2, 0.01]}}, "
        "\"objects\": [{\"name\": \"c\", \"type\": \"solid\", \"material\": \"c\", "
        "\"temperature_k\": 300, \"shape\": " BOX "}, "
        "{\"name\": \"t\", \"type\": \"solid\", \"material\": \"t\", "
        "\"temperature_k\": 300, \"shape\": " BOX "}, "
        "{\"name\": \"a\", \"type\": \"shell\", \"thickness_m\": 0.001, \"material\": \"a\", "
        "\"temperature_k\": 300, \"shape\": " BOX "}, "
        "{\"name\": \"i\", \"type\": \"solid\", \"material\": \"i\", "
        "\"temperature_k\": 300, \"shape\": " BOX "}], " SENSORS "}");
    const bool expect[4] = {true, false, false, false};
    for (size_t o = 0; o < 4; o++)
        assert_int_equal(scene_object_optics_constant(s, &s->objects[o]), expect[o]);
    /* the constant one: the same point at two frequencies */
    optics_point c_lo = scene_object_optics(s, &s->objects[0], 0.3e12);
    optics_point c_hi = scene_object_optics(s, &s->objects[0], 1.1e12);
    assert_true(c_lo.reflectivity == c_hi.reflectivity &&
                c_lo.attenuation_per_m == c_hi.attenuation_per_m &&
                c_lo.emissivity == c_hi.emissivity);
    optics_point lo = scene_object_optics(s, &s->objects[1], 0.3e12);
    optics_point hi = scene_object_optics(s, &s->objects[1], 1.1e12);
    assert_true(lo.reflectivity != hi.reflectivity);
    thz_scene_destroy(s);
}

static void test_default_channel_names(void **state)
{
    (void)state;
    /* format 1.1 only adds keys: a 1/1.1 file loads either way */
    thz_scene *s11 = load_ok("{\"format\": \"thzmap-scene/1.1\", "
                             "\"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": "
                             "0.01}], " MATERIALS OBJECT(BOX) SENSORS "}");
    assert_int_equal(s11->n_channels, 1);
    thz_scene_destroy(s11);
    /* 0.35 and 0.3501 THz would both be "0.350 THz": they get a decimal more, the
     * others keep three; a given name that looks like a default one stays */
    thz_scene *s =
        load_ok(HEAD "\"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.01}, "
                     "{\"frequency_thz\": 0.3501, \"relative_width\": 0.01}, "
                     "{\"frequency_thz\": 0.6, \"relative_width\": 0.01}, "
                     "{\"name\": \"0.700 THz\", \"frequency_thz\": 0.9, "
                     "\"relative_width\": 0.01}, "
                     "{\"frequency_thz\": 0.7, \"relative_width\": 0.01}, "
                     "{\"frequency_thz\": 1.1, \"relative_width\": 0.01}, "
                     "{\"frequency_thz\": 1.1, \"relative_width\": 0.02}], " MATERIALS OBJECT(BOX)
                         SENSORS "}");
    static const char *const names[] = {"0.3500 THz", "0.3501 THz",   "0.600 THz",   "0.700 THz",
                                        "0.7000 THz", "1.100 THz #5", "1.100 THz #6"};
    assert_int_equal(s->n_channels, 7);
    for (size_t i = 0; i < 7; i++)
        assert_string_equal(s->channels[i].name, names[i]);
    thz_scene_destroy(s);
    /* the range form: names stay unique where the step is below the 3rd decimal */
    s = load_ok(HEAD "\"channels\": {\"from_thz\": 0.2, \"to_thz\": 0.2005, \"count\": 6, "
                     "\"relative_width\": 0.02}, " MATERIALS OBJECT(BOX) SENSORS "}");
    assert_string_equal(s->channels[1].name, "0.2001 THz");
    for (size_t i = 0; i < s->n_channels; i++)
        for (size_t j = 0; j < i; j++)
            assert_true(strcmp(s->channels[i].name, s->channels[j].name) != 0);
    thz_scene_destroy(s);
    /* only names the user gave are checked against each other, under their own key */
    load_bad(HEAD "\"channels\": [{\"name\": \"a\", \"frequency_thz\": 0.3, \"relative_width\": "
                  "0.01}, {\"frequency_thz\": 0.3, \"relative_width\": 0.01}, {\"name\": \"a\", "
                  "\"frequency_thz\": 0.4, \"relative_width\": 0.01}], " MATERIALS OBJECT(BOX)
                      SENSORS "}",
             "channels[2].name: channel name \"a\" is already used by channels[0]");
    /* a given name that takes the last resort of a default one */
    load_bad(HEAD "\"channels\": [{\"name\": \"0.300 THz #2\", \"frequency_thz\": 0.4, "
                  "\"relative_width\": 0.01}, {\"frequency_thz\": 0.3, \"relative_width\": 0.01}, "
                  "{\"frequency_thz\": 0.3, \"relative_width\": 0.01}], " MATERIALS OBJECT(BOX)
                      SENSORS "}",
             "channels[2]: the default name \"0.300 THz #2\" of channels[2] is already used by "
             "channels[0]");
}

/* Unique names per list, through the loader's hash of the names seen: a repeat names the
 * first holder however far back, each list on its own (an object and a sensor may share a
 * name), and loading one scene after a refused one starts afresh. */
static void test_unique_names(void **state)
{
    (void)state;
#define NAMED(n)                                                                                   \
    "{\"name\": \"" n "\", \"type\": \"solid\", \"material\": \"m\", \"temperature_k\": 300, "     \
    "\"shape\": " BOX "}"
#define CAMERA(n)                                                                                  \
    "{\"name\": \"" n                                                                              \
    "\", \"position_m\": [0, -5, 0], \"look_at_m\": [0, 0, 0], \"fov_deg\": 40, "                  \
    "\"resolution\": [16, 8]}"
    load_bad(HEAD CHANNELS MATERIALS "\"objects\": [" NAMED("a") ", " NAMED("b") ", " NAMED(
                 "c") ", " NAMED("d") ", " NAMED("b") "], \"sensors\": [" CAMERA("c") "]}",
             "objects[4].name: object name \"b\" is already used by objects[1]");
    thz_scene *s = load_ok(HEAD CHANNELS MATERIALS "\"objects\": [" NAMED("a") ", " NAMED(
        "b") "], \"sensors\": [" CAMERA("b") ", " CAMERA("a") "]}");
    assert_int_equal(s->n_objects, 2);
    thz_scene_destroy(s);
    load_bad(HEAD CHANNELS MATERIALS "\"objects\": [" NAMED("a") "], \"sensors\": [" CAMERA(
                 "x") ", " CAMERA("y") ", " CAMERA("x") "]}",
             "sensors[2].name: sensor name \"x\" is already used by sensors[0]");
#undef NAMED
#undef CAMERA
}

/* One mesh file named by three objects (imported once, each object a copy): each takes
 * its own transform, and the copies do not share arrays. */
static void test_mesh_file_named_thrice(void **state)
{
    (void)state;
#define TETRA(n, x)                                                                                \
    "{\"name\": \"" n "\", \"type\": \"solid\", \"material\": \"m\", \"temperature_k\": 300, "     \
    "\"shape\": {\"type\": \"mesh\", \"file\": \"../meshes/tetra.obj\"}, "                         \
    "\"transform\": {\"translate_m\": [" x ", 0, 0]}}"
    thz_scene *s = load_ok(HEAD CHANNELS MATERIALS "\"objects\": [" TETRA("a", "0") ", " TETRA(
        "b", "5") ", " TETRA("c", "-3") "], " SENSORS "}");
    assert_int_equal(s->n_objects, 3);
    const double x0[3] = {0.0, 5.0, -3.0};
    for (size_t i = 0; i < 3; i++) {
        const thz_mesh *m = &s->objects[i].mesh;
        assert_int_equal(m->n_triangles, 4);
        assert_true(fabs(m->bbox_min_m[0] - x0[i]) < 1e-6);
        assert_true(fabs(m->bbox_max_m[0] - (x0[i] + 1.0)) < 1e-6);
        for (size_t j = 0; j < i; j++)
            assert_true(m->positions != s->objects[j].mesh.positions &&
                        m->indices != s->objects[j].mesh.indices);
    }
    thz_scene_destroy(s);
#undef TETRA
}

/* Sensor optics and noise: defaults, A_S from D, NETD for every channel. */
static void test_sensor_model(void **state)
{
    (void)state;
#define CAM                                                                                        \
    "\"position_m\": [0, -5, 0], \"look_at_m\": [0, 0, 0], "                                       \
    "\"fov_deg\": 40, \"resolution\": [16, 8]"
#define TWO_CHANNELS                                                                               \
    "\"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.01}, "                         \
    "{\"frequency_thz\": 0.7, \"relative_width\": 0.01}], "
    thz_scene *s = load_ok(HEAD TWO_CHANNELS MATERIALS OBJECT(BOX) "\"sensors\": ["
                                                                   "{\"name\": \"c\", " CAM "}, "
                                                                   "{\"name\": \"d\", " CAM ", "
                                                                   "\"aperture_diameter_m\": 0.5, "
                                                                   "\"noise\": {\"netd_k\": 0.3}}, "
                                                                   "{\"name\": \"e\", " CAM ", "
                                                                   "\"aperture_diameter_m\": 0.5, "
                                                                   "\"aperture_m2\": 0.02, "
                                                                   "\"psf\": \"none\", "
                                                                   "\"noise\": {\"receiver_"
                                                                   "temperature_k\": 400, "
                                                                   "\"integration_time_s\": 0.1, "
                                                                   "\"radiometer\": \"dicke\"}, "
                                                                   "\"noise_seed\": 9}]}");
    const thz_sensor *c = &s->sensors[0], *d = &s->sensors[1], *e = &s->sensors[2];
    assert_int_equal(c->psf, PSF_NONE);
    assert_int_equal(c->noise.kind, NOISE_NONE);
    assert_true(c->aperture_m2 == 1e-2);
    assert_false(c->noise_seed_given);
    assert_int_equal(d->psf, PSF_AIRY);
    assert_true(fabs(d->aperture_m2 - M_PI * 0.25 / 4.0) < 1e-15);
    assert_int_equal(d->noise.kind, NOISE_NETD);
    assert_true(d->noise.netd_k[0] == 0.3 && d->noise.netd_k[1] == 0.3);
    assert_int_equal(e->psf, PSF_NONE);
    assert_true(e->aperture_m2 == 0.02);
    assert_int_equal(e->noise.kind, NOISE_RADIOMETER);
    assert_int_equal(e->noise.radiometer, RADIOMETER_DICKE);
    assert_true(e->noise.receiver_temperature_k == 400 && e->noise.integration_time_s == 0.1);
    assert_true(e->noise_seed_given && e->noise_seed == 9);
    thz_scene_destroy(s);
#undef CAM
#undef TWO_CHANNELS
}

static void test_refusals(void **state)
{
    (void)state;
    load_bad("{\"format\": \"thzmap-scene/1\",\n  \"channels\": [}", "test.json:2:");
    load_bad(HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS ", \"extra\": 1}", "extra: unknown key");
    load_bad(HEAD CHANNELS MATERIALS
             "\"objects\": [{\"name\": \"o\", \"type\": \"solid\", \"material\": \"m\", "
             "\"temperature_k\": -1, \"shape\": " BOX "}], " SENSORS "}",
             "objects[0].temperature_k: expected a number in [0, 1e+06], got -1");
    load_bad(HEAD CHANNELS MATERIALS OBJECT("{\"type\": \"cone\"}") SENSORS "}",
             "objects[0].shape.type: expected one of");
    load_bad(HEAD CHANNELS MATERIALS OBJECT("{\"type\": \"mesh\", \"file\": \"nope.obj\"}") SENSORS
             "}",
             "objects[0].shape.file:");
    load_bad(HEAD "\"channels\": [], " MATERIALS OBJECT(BOX) SENSORS "}",
             "channels: expected at least one");
    load_bad("{\"format\": \"thzmap-scene/2\"}", "format: expected \"thzmap-scene/1\"");
    load_bad("{\"format\": \"thzmap-scene/1.2\"}",
             "format: expected \"thzmap-scene/1\" or \"thzmap-scene/1.1\"");
    load_bad("[1, 2]", "expected a JSON object");
    load_bad(HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS
             ", \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.1, "
             "\"temperature_k\": 290, \"emitting\": false}}",
             "atmosphere.temperature_k: only the air of itu-p676 and lines, or an emitting");
    load_bad(HEAD CHANNELS MATERIALS OBJECT(BOX) SENSORS
             ", \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.1, "
             "\"temperature_k\": 290, \"emitting\": 1}}",
             "atmosphere.emitting: expected true or false");
    /* a Ward slope so small that the lobe's normalisation underflowed (photon-map's
     * images were NaN below about 1e-155) */
    load_bad(HEAD CHANNELS
             "\"materials\": {\"m\": {\"reflectivity\": 0.5, \"reflection\": {\"model\": "
             "\"ward\", \"alpha_x\": 0.2, \"alpha_y\": 1e-200}}}, " OBJECT(BOX) SENSORS "}",
             "materials.m.reflection.alpha_y: expected a number in [1e-06, 1], got 1e-200");
    /* a sum just above 1 is shown with the digits that make it exceed 1 (it read
     * "must not exceed 1, got 0.6 + 0.4 = 1") */
    load_bad(HEAD CHANNELS
             "\"materials\": {\"m\": {\"reflectivity\": 0.4, \"emissivity\": 0.6000001}}, " OBJECT(
                 BOX) SENSORS "}",
             "materials.m.emissivity: emissivity + reflectivity must not exceed 1, got 0.6000001 + "
             "0.4 = 1.0000001");
}

/* A direction or up vector of huge (or tiny) components is that direction: it was
 * refused as "non-zero" when its length overflowed. */
static void test_sensor_vectors_of_any_scale(void **state)
{
    (void)state;
    const char *scales[2] = {"1e308", "1e-300"};
    for (int k = 0; k < 2; k++) {
        char json[1024];
        snprintf(json, sizeof json,
                 HEAD CHANNELS MATERIALS OBJECT(
                     BOX) "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], "
                          "\"direction\": [0, %s, 0], \"up\": [0, 0, %s], \"fov_deg\": 40, "
                          "\"resolution\": [16, 8]}]}",
                 scales[k], scales[k]);
        thz_scene *s = load_ok(json);
        assert_true(s->sensors[0].direction[1] == 1.0 && s->sensors[0].up[2] == 1.0);
        thz_scene_destroy(s);
    }
}

/* An up vector is refused when it is parallel to the viewing direction within 1e-6 rad
 * (docs/scene-format.md), where the picture's right-hand side direction x up has no
 * reliable direction; 1e-5 rad off is a camera like any other, its up the direction's
 * perpendicular. A tolerance of 1e-12 (a mutant) passed every test. */
static void test_sensor_up_nearly_parallel(void **state)
{
    (void)state;
    const char *ups[2] = {"1e-7", "1e-5"};
    for (int k = 0; k < 2; k++) {
        char json[1024];
        snprintf(json, sizeof json,
                 HEAD CHANNELS MATERIALS OBJECT(
                     BOX) "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], "
                          "\"direction\": [0, 1, 0], \"up\": [0, 1, %s], \"fov_deg\": 40, "
                          "\"resolution\": [16, 8]}]}",
                 ups[k]);
        if (k == 0) {
            load_bad(json, "sensors[0].up: the up vector is parallel to the viewing direction");
            continue;
        }
        thz_scene *s = load_ok(json);
        thz_scene_destroy(s);
    }
}

/* scene-format.md ("Reflection"): Ward's alpha_x is the spread along the tangent (a
 * rectangle's: x), alpha_y across it. Seen at normal incidence, a lobe of alpha_x 0.5,
 * alpha_y 0.05 reflects far more towards a direction tilted 20 degrees along x than
 * along y (exp(-0.12) against exp(-12) in Ward's exponent). The loader handing the
 * table alpha_y, alpha_x (a mutant) passed every test: every brushed surface would have
 * been brushed across. */
static void test_ward_alpha_x_along_tangent(void **state)
{
    (void)state;
    thz_scene *s = load_ok(
        HEAD CHANNELS "\"materials\": {\"m\": {\"reflectivity\": 0.5, \"reflection\": {\"model\": "
                      "\"ward\", \"alpha_x\": 0.5, \"alpha_y\": 0.05}}}, " OBJECT(
                          "{\"type\": \"rectangle\", \"size_m\": [1, 1]}") SENSORS "}");
    const thz_object *o = &s->objects[0];
    optics_point op = scene_object_optics(s, o, 0.35e12);
    brdf_lobe lobe;
    scene_object_lobe(s, o, &op, &lobe);
    brdf_frame f = scene_triangle_frame(o, 0, 0);
    assert_true(f.t.x == 1.0 && f.n.z == 1.0); /* the rectangle's tangent x, normal z */
    double a = 20.0 * M_PI / 180.0;
    vec3 wi = v3(0, 0, 1), along = v3(sin(a), 0, cos(a)), across = v3(0, sin(a), cos(a));
    double fx = brdf_eval(&lobe, &f, wi, along), fy = brdf_eval(&lobe, &f, wi, across);
    if (!(fx > 3.0 * fy))
        fail_msg("f along the tangent %g, across it %g", fx, fy);
    thz_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_example),
        cmocka_unit_test(test_defaults_and_range),
        cmocka_unit_test(test_blocks),
        cmocka_unit_test(test_shape_defaults),
        cmocka_unit_test(test_far_object_within_limit),
        cmocka_unit_test(test_optics_constant),
        cmocka_unit_test(test_default_channel_names),
        cmocka_unit_test(test_unique_names),
        cmocka_unit_test(test_mesh_file_named_thrice),
        cmocka_unit_test(test_sensor_model),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_sensor_vectors_of_any_scale),
        cmocka_unit_test(test_sensor_up_nearly_parallel),
        cmocka_unit_test(test_ward_alpha_x_along_tangent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
