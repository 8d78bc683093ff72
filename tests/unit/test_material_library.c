/* The material library (data/materials/library.json) and the scene keys of a complex
 * index: every entry loads, has a source and evaluates to finite n, k with k > 0 and
 * n >= 1 (n > 0 for Drude metals) at 0.1-3 THz; `library`, `refractive_index`,
 * `permittivity_model` and CSV n, k columns in scenes, keys beside them overriding;
 * refusals with their JSON paths (P.2040 outside its range names the range). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "scene/material_library.h"
#include "scene/scene.h"

#define SRC THZ_SOURCE_DIR

static void test_every_entry(void **state)
{
    (void)state;
    material_library *lib = NULL;
    thz_error err = {0};
    if (material_library_load(&lib, &err) != THZ_OK)
        fail_msg("library refused: %s", err.message);
    assert_true(lib->n >= 25);
    const char *required[] = {"skin",  "water",     "cotton",   "denim", "leather", "polyester",
                              "paper", "wood",      "concrete", "glass", "pe",      "ptfe",
                              "pmma",  "aluminium", "copper",   "steel", "rdx",     NULL};
    for (size_t r = 0; required[r]; r++)
        if (!material_library_find(lib, required[r]))
            fail_msg("the library lacks \"%s\"", required[r]);
    for (size_t i = 0; i < lib->n; i++) {
        const material_library_entry *e = &lib->entries[i];
        assert_true(strlen(e->source) > 10);
        assert_non_null(e->index);
        const permittivity_model *pm = material_index_model_of(e->index);
        bool metal = pm && pm->kind == PERMITTIVITY_DRUDE;
        for (double f = 0.1e12; f <= 3.0001e12; f += 0.05e12) {
            double n, k;
            assert_true(material_index_at(e->index, f, &n, &k));
            if (!(isfinite(n) && isfinite(k) && k > 0.0 && (metal ? n > 0.0 : n >= 1.0)))
                fail_msg("%s at %g THz: n = %g, k = %g", e->name, f * 1e-12, n, k);
        }
    }
    /* RDX's signature: its absorption coefficient peaks near 0.82 THz */
    const material_library_entry *rdx = material_library_find(lib, "rdx");
    double best = 0, best_f = 0;
    for (double f = 0.5e12; f < 0.95e12; f += 1e9) {
        double n, k;
        material_index_at(rdx->index, f, &n, &k);
        if (k * f > best) {
            best = k * f;
            best_f = f;
        }
    }
    assert_true(fabs(best_f - 0.82e12) < 0.01e12);
    material_library_destroy(lib);
}

#define HEAD                                                                                       \
    "{\"format\": \"thzmap-scene/1\", \"channels\": [{\"frequency_thz\": %s, "                     \
    "\"relative_width\": 0.01}], \"materials\": {\"m\": %s}, "                                     \
    "\"objects\": [{\"name\": \"o\", \"type\": \"solid\", \"material\": \"m\", "                   \
    "\"temperature_k\": 300, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1]}}], "            \
    "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], \"look_at_m\": [0, 0, 0], "       \
    "\"fov_deg\": 40, \"resolution\": [16, 8]}]}"

static thz_status load(const char *thz, const char *material, thz_scene **s, thz_error *err)
{
    char json[4096];
    snprintf(json, sizeof json, HEAD, thz, material);
    return scene_load_string(json, SRC "/tests/inputs/scenes", "test.json", s, err);
}

static thz_scene *load_ok(const char *thz, const char *material)
{
    thz_scene *s = NULL;
    thz_error err = {0};
    if (load(thz, material, &s, &err) != THZ_OK)
        fail_msg("refused %s: %s", material, err.message);
    return s;
}

static void load_bad(const char *thz, const char *material, const char *expect)
{
    thz_scene *s = NULL;
    thz_error err = {0};
    assert_int_equal(load(thz, material, &s, &err), THZ_ERR_INPUT);
    assert_null(s);
    if (!strstr(err.message, expect))
        fail_msg("message '%s' lacks '%s'", err.message, expect);
}

static void test_scene_keys(void **state)
{
    (void)state;
    double n, k;
    thz_scene *s = load_ok("1.0", "{\"refractive_index\": [1.6, 0.03]}");
    assert_true(material_index_at(s->materials[0].index, 1e12, &n, &k));
    assert_true(n == 1.6 && k == 0.03);
    assert_int_equal(s->materials[0].reflectivity.n, 0);      /* from the index */
    assert_int_equal(s->materials[0].attenuation_per_m.n, 0); /* from the index */
    scene_destroy(s);
    s = load_ok("1.0", "{\"refractive_index\": [[0.5, 1.5, 0.01], [1.5, 1.7, 0.05]]}");
    material_index_at(s->materials[0].index, 1e12, &n, &k);
    assert_true(fabs(n - 1.6) < 1e-12 && fabs(k - 0.03) < 1e-12);
    scene_destroy(s);
    /* a library entry, with reflectivity and the index overridden beside it */
    s = load_ok("1.0", "{\"library\": \"water\", \"reflectivity\": 0.3}");
    material_index_at(s->materials[0].index, 1e12, &n, &k);
    assert_true(fabs(n - 2.11) < 0.01);
    assert_int_equal(s->materials[0].reflectivity.n, 1);
    assert_true(s->materials[0].color[2] == 0.9); /* the entry's colour */
    scene_destroy(s);
    s = load_ok("1.0", "{\"library\": \"water\", \"refractive_index\": [1.3, 0.1], "
                       "\"color\": [1, 0, 0]}");
    material_index_at(s->materials[0].index, 1e12, &n, &k);
    assert_true(n == 1.3 && k == 0.1 && s->materials[0].color[0] == 1.0);
    scene_destroy(s);
    /* CSV columns n and k (tests/inputs/scenes/materials/nk.csv) */
    s = load_ok("1.0", "{\"file\": \"materials/nk.csv\"}");
    material_index_at(s->materials[0].index, 0.6e12, &n, &k);
    assert_true(fabs(n - 1.55) < 1e-12 && fabs(k - 0.02) < 1e-12);
    scene_destroy(s);
    /* ITU-R P.2040 inside its range */
    s = load_ok("0.2", "{\"permittivity_model\": {\"model\": \"itu-p2040\", \"material\": "
                       "\"wood\"}}");
    scene_destroy(s);
    s = load_ok("0.3", "{\"permittivity_model\": {\"model\": \"lorentz\", \"eps_inf\": 2.5, "
                       "\"oscillators\": [{\"frequency_thz\": 1, \"strength\": 0.1, "
                       "\"width_thz\": 0.1}]}}");
    assert_string_equal(material_index_form(s->materials[0].index), "lorentz");
    scene_destroy(s);
}

/* The one warning of a scene that has exactly one, containing `expect`. */
static void expect_warning(const thz_scene *s, const char *expect)
{
    if (s->n_warnings != 1 || !strstr(s->warnings[0], expect))
        fail_msg("%zu warning(s), the first '%s'; expected one with '%s'", s->n_warnings,
                 s->n_warnings ? s->warnings[0] : "", expect);
}

static void test_warnings(void **state)
{
    (void)state;
    thz_scene *s = load_ok("0.5", "{\"library\": \"water\"}");
    assert_int_equal(s->n_warnings, 0);
    scene_destroy(s);
    s = load_ok("2.0", "{\"library\": \"water\"}");
    expect_warning(s, "materials.m.library: the source of this library entry covers 0.001 to 1 "
                      "THz but channel \"2.000 THz\" (band 1.96 to 2.04 THz");
    scene_destroy(s);
    /* an index given beside the entry replaces it: no warning about the entry's range */
    s = load_ok("2.0", "{\"library\": \"water\", \"refractive_index\": [2, 0.3]}");
    assert_int_equal(s->n_warnings, 0);
    scene_destroy(s);
    s = load_ok("2.0", "{\"refractive_index\": [[0.5, 1.5, 0.01], [1.5, 1.7, 0.05]]}");
    expect_warning(s, "materials.m: the table of n and k covers 0.5 to 1.5 THz but channel");
    scene_destroy(s);
}

static void test_refusals(void **state)
{
    (void)state;
    load_bad("1.0", "{\"color\": [1, 0, 0]}", "materials.m.reflectivity: missing key");
    load_bad("1.0", "{\"refractive_index\": [0, 0.1]}", "materials.m.refractive_index[0]");
    load_bad("1.0", "{\"refractive_index\": [1.5, -0.1]}", "materials.m.refractive_index[1]");
    load_bad("1.0", "{\"refractive_index\": [1.5]}", "got a list of 1 numbers");
    load_bad("1.0", "{\"refractive_index\": [[1, 1.5, 0.1], [0.5, 1.5, 0.1]]}",
             "materials.m.refractive_index[1][0]: frequencies must increase strictly");
    load_bad("1.0", "{\"refractive_index\": [[1, 1.5]]}", "refractive_index[0]: expected a row");
    load_bad("1.0",
             "{\"refractive_index\": [1.5, 0.1], \"permittivity_model\": "
             "{\"model\": \"drude\"}}",
             "either refractive_index or permittivity_model");
    load_bad("1.0", "{\"permittivity_model\": {\"model\": \"debeye\"}}",
             "materials.m.permittivity_model.model: expected one of");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"debye\", \"eps_inf\": 3, "
             "\"eps_s\": 70}}",
             "materials.m.permittivity_model.tau_ps: missing key");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"debye\", \"eps_inf\": 3, "
             "\"eps_s\": 70, \"tau_ps\": 8, \"tau2_ps\": 1}}",
             "materials.m.permittivity_model.tau2_ps");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"debye\", \"eps_inf\": 30, "
             "\"eps_s\": 7, \"tau_ps\": 8}}",
             "expected eps_s >= eps_inf");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"drude\", "
             "\"plasma_frequency_thz\": 2000}}",
             "permittivity_model.collision_frequency_thz: missing key");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"lorentz\", \"eps_inf\": 2, "
             "\"oscillators\": [{\"frequency_thz\": 1, \"strength\": 0.1}]}}",
             "permittivity_model.oscillators[0].width_thz: missing key");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"itu-p2040\", \"material\": "
             "\"woood\"}}",
             "permittivity_model.material: unknown ITU-R P.2040 material \"woood\"");
    load_bad("1.0",
             "{\"permittivity_model\": {\"model\": \"itu-p2040\", \"material\": "
             "\"wood\"}}",
             "materials.m.permittivity_model: ITU-R P.2040 gives \"wood\" only for 0.001 to "
             "100 GHz, 110 to 330 GHz, 100 to 400 GHz, but channel \"1.000 THz\"");
    load_bad("0.105", "{\"library\": \"concrete\"}",
             "materials.m.library: ITU-R P.2040 gives \"concrete\" only for 1 to 100 GHz");
    /* a measured response has no relative width: its band is where it is > 0 */
    char json[4096];
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\", \"channels\": [{\"frequency_thz\": 0.1, "
             "\"response\": [[0.05, 1], [0.9, 1]]}], \"materials\": {\"m\": "
             "{\"library\": \"concrete\"}}, %s",
             strstr(HEAD, "\"objects\""));
    thz_scene *s = NULL;
    thz_error err = {0};
    assert_int_equal(scene_load_string(json, SRC, "test.json", &s, &err), THZ_ERR_INPUT);
    assert_null(s);
    if (!strstr(err.message, "(band 50 to 900 GHz, where its response is > 0)"))
        fail_msg("message '%s' lacks the table's band", err.message);
    load_bad("1.0", "{\"library\": \"unobtainium\"}",
             "materials.m.library: unknown library material \"unobtainium\"");
    load_bad("1.0", "{\"file\": \"materials/n_only.csv\"}", "the columns n and k go together");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_entry),
        cmocka_unit_test(test_scene_keys),
        cmocka_unit_test(test_warnings),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
