/* The material library (data/materials/library.json) and the scene keys of a complex
 * index: every entry loads, has a source and evaluates to finite n, k with k > 0 and
 * n >= 1 (n > 0 for Drude metals) at 0.1-3 THz; `library`, `refractive_index`,
 * `permittivity_model` and CSV n, k columns (one row: a constant) in scenes, keys beside them
 * overriding; refusals with their JSON paths (P.2040 outside its range names the range); the
 * absorption lines of explosives and drugs at their cited frequencies. */
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
    material_library_destroy(lib);
}

/* The power attenuation 4 pi k nu / c of an index at freq_hz, in 1/m. */
static double attenuation_per_m(const material_index *index, double freq_hz)
{
    double n, k;
    material_index_at(index, freq_hz, &n, &k);
    return 4.0 * M_PI * k * freq_hz / 299792458.0;
}

/* The spectral signatures of explosives and drugs: every absorption line the cited
 * sources give (positions typed here from the citations in library.json, not read from
 * it) is an oscillator of the entry, the attenuation peaks there (to 10 GHz, and 1.5
 * times its value 0.1 THz either side), and the line lies within the entry's validity. */
static void test_signatures(void **state)
{
    (void)state;
    static const struct {
        const char *name;
        double lines_thz[6];
    } cited[] = {
        {"rdx", {0.82, 1.05, 1.36, 1.96}},                  /* Leahy-Hoppa et al. 2007 */
        {"petn", {1.0793, 1.6489, 2.1585, 2.3983, 2.4583}}, /* Whitley et al. 2011, 20 K */
        {"hmx-alpha", {0.82, 1.51}},                        /* Du et al. 2015 */
        {"lactose", {0.531, 1.195, 1.38, 1.81}},            /* Jung et al. 2008 */
    };
    material_library *lib = NULL;
    thz_error err = {0};
    if (material_library_load(&lib, &err) != THZ_OK)
        fail_msg("library refused: %s", err.message);
    for (size_t s = 0; s < sizeof cited / sizeof cited[0]; s++) {
        const material_library_entry *e = material_library_find(lib, cited[s].name);
        if (!e)
            fail_msg("the library lacks \"%s\"", cited[s].name);
        const permittivity_model *pm = material_index_model_of(e->index);
        assert_non_null(pm);
        assert_int_equal(pm->kind, PERMITTIVITY_LORENTZ);
        assert_true(e->has_range);
        for (size_t l = 0; l < 6 && cited[s].lines_thz[l] > 0; l++) {
            double f = cited[s].lines_thz[l] * 1e12;
            bool listed = false;
            for (size_t j = 0; j < pm->n_oscillators; j++)
                listed |= fabs(pm->oscillators[j].freq_hz - f) < 1e9;
            if (!listed)
                fail_msg("%s: no oscillator at the cited %g THz", e->name, f * 1e-12);
            double a = attenuation_per_m(e->index, f);
            double below = attenuation_per_m(e->index, f - 0.1e12);
            double above = attenuation_per_m(e->index, f + 0.1e12);
            if (!(a > 1.5 * below && a > 1.5 * above))
                fail_msg("%s: alpha %g 1/m at %g THz is no distinct peak (%g, %g 1/m 0.1 THz "
                         "either side)",
                         e->name, a, f * 1e-12, below, above);
            /* the maximum of alpha near the line lies at the line (to 10 GHz) */
            double best = 0.0, best_hz = 0.0;
            for (int i = -40; i <= 40; i++) {
                double g = f + i * 0.5e9, v = attenuation_per_m(e->index, g);
                if (v > best) {
                    best = v;
                    best_hz = g;
                }
            }
            if (fabs(best_hz - f) > 10e9)
                fail_msg("%s: alpha peaks at %g THz, not at the cited %g THz", e->name,
                         best_hz * 1e-12, f * 1e-12);
            if (!(f >= e->lo_hz && f <= e->hi_hz))
                fail_msg("%s: the line at %g THz lies outside its validity", e->name, f * 1e-12);
        }
    }
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
    /* one row: that n and k at every frequency (it crashed the loader) */
    s = load_ok("1.0", "{\"file\": \"materials/nk1.csv\"}");
    material_index_at(s->materials[0].index, 2e12, &n, &k);
    assert_true(n == 2.5 && k == 0.04);
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
             "{\"permittivity_model\": {\"model\": \"double-debye\", \"eps_inf\": 3, "
             "\"eps_2\": 80, \"eps_s\": 70, \"tau1_ps\": 8, \"tau2_ps\": 0.2}}",
             "materials.m.permittivity_model.eps_2: expected eps_s >= eps_2 >= eps_inf, got 70, "
             "80, 3");
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
        cmocka_unit_test(test_every_entry), cmocka_unit_test(test_signatures),
        cmocka_unit_test(test_scene_keys),  cmocka_unit_test(test_warnings),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
