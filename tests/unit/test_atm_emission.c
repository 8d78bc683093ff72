/* The emitting atmosphere's pieces: volume emission 4 pi alpha B and the extent's exit
 * distance against closed forms (what a ray sees through emitting air, the renderers'
 * band means, is checked by tests/physics/test_air_emission.c); and the scene keys that
 * set it up. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "atmosphere/atmosphere.h"
#include "physics/planck.h"
#include "scene/scene.h"
#include "scene/scene_hash.h"

static void constant_atm(thz_atmosphere *atm, double alpha)
{
    memset(atm, 0, sizeof *atm);
    atm->model = ATM_CONSTANT;
    assert_true(spectrum_set_constant(&atm->attenuation_per_m, alpha));
}

static void test_volume_emission(void **state)
{
    (void)state;
    thz_atmosphere atm;
    thz_error err = {0};
    constant_atm(&atm, 0.2);
    double f = 0.5e12, b = planck_radiance(f, 290.0);
    assert_true(atmosphere_volume_emission_w_per_m3_hz(&atm, f) == 0.0); /* not emitting yet */
    assert_int_equal(atmosphere_set_emitting(&atm, 290.0, 3.0, &err), THZ_OK);
    assert_true(fabs(atmosphere_volume_emission_w_per_m3_hz(&atm, f) / (4 * M_PI * 0.2 * b) - 1) <
                1e-12);
    atmosphere_fini(&atm);
}

/* Transmittance exp(-alpha d), and 1 where alpha = 0 even over an infinite path (no
 * 0 * inf = NaN): a constant atmosphere of alpha 0 and a table that is 0 in part. */
static void test_transmittance(void **state)
{
    (void)state;
    thz_atmosphere atm;
    constant_atm(&atm, 0.2);
    assert_true(fabs(atmosphere_transmittance(&atm, 0.5e12, 3.0) / exp(-0.6) - 1) < 1e-15);
    assert_true(atmosphere_transmittance(&atm, 0.5e12, INFINITY) == 0.0);
    atmosphere_fini(&atm);

    constant_atm(&atm, 0.0);
    assert_true(atmosphere_transmittance(&atm, 0.5e12, 3.0) == 1.0);
    assert_true(atmosphere_transmittance(&atm, 0.5e12, INFINITY) == 1.0);
    atmosphere_fini(&atm);

    memset(&atm, 0, sizeof atm);
    atm.model = ATM_TABLE;
    const double f[] = {0.1e12, 0.2e12, 1.0e12}, a[] = {0.0, 0.0, 0.5};
    assert_true(spectrum_set_table(&atm.attenuation_per_m, 3, f, a));
    assert_true(atmosphere_transmittance(&atm, 0.15e12, INFINITY) == 1.0);
    assert_true(atmosphere_transmittance(&atm, 0.6e12, INFINITY) == 0.0);
    atmosphere_fini(&atm);

    memset(&atm, 0, sizeof atm); /* ATM_NONE */
    assert_true(atmosphere_transmittance(&atm, 0.5e12, INFINITY) == 1.0);
}

static void test_extent(void **state)
{
    (void)state;
    thz_atmosphere atm;
    thz_error err = {0};
    constant_atm(&atm, 0.1);
    assert_int_equal(atmosphere_set_emitting(&atm, 280.0, 3.0, &err), THZ_OK);
    double lo[3] = {-1, -2, -3}, hi[3] = {1, 2, 3}, bad[3] = {1, -2, 3};
    assert_int_equal(atmosphere_set_extent(&atm, lo, bad, &err), THZ_ERR_INPUT);
    assert_int_equal(atmosphere_set_extent(&atm, lo, hi, &err), THZ_OK);
    double o[3] = {0, 0, 0}, dx[3] = {1, 0, 0}, dz[3] = {0, 0, -1};
    double d45[3] = {M_SQRT1_2, M_SQRT1_2, 0}, out[3] = {5, 0, 0};
    assert_true(fabs(atmosphere_extent_exit_m(&atm, o, dx) - 1.0) < 1e-12);
    assert_true(fabs(atmosphere_extent_exit_m(&atm, o, dz) - 3.0) < 1e-12);
    assert_true(fabs(atmosphere_extent_exit_m(&atm, o, d45) - M_SQRT2) < 1e-12);
    assert_true(atmosphere_extent_exit_m(&atm, out, dx) == 0.0);
    /* from off the box's centre, along each negative axis: the distance to the min face
     * (a centred origin cannot tell it from the max face's; a helper's mutant measuring
     * to the wrong face survived) */
    double off[3] = {0.5, -1.5, 2.0}, mx[3] = {-1, 0, 0}, my[3] = {0, -1, 0}, mz[3] = {0, 0, -1};
    assert_true(fabs(atmosphere_extent_exit_m(&atm, off, mx) - 1.5) < 1e-12);
    assert_true(fabs(atmosphere_extent_exit_m(&atm, off, my) - 0.5) < 1e-12);
    assert_true(fabs(atmosphere_extent_exit_m(&atm, off, mz) - 5.0) < 1e-12);
    atmosphere_fini(&atm);
}

static const char *scene_with(const char *atmosphere, char *buf, size_t n)
{
    snprintf(buf, n,
             "{\"format\": \"thzmap-scene/1\","
             " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.02}],"
             " \"materials\": {\"wall\": {\"reflectivity\": 0.0}},"
             " \"atmosphere\": %s,"
             " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
             "   \"temperature_k\": 295, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1],"
             "   \"inward\": true}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, 0, 0],"
             "   \"look_at_m\": [1, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}]}",
             atmosphere);
    return buf;
}

static void test_scene_keys(void **state)
{
    (void)state;
    char buf[4096];
    thz_scene *s = NULL;
    thz_error err = {0};
    const char *ok = "{\"model\": \"lines\", \"temperature_k\": 290, \"pressure_hpa\": 1000,"
                     " \"relative_humidity\": 0.4, \"emitting\": true,"
                     " \"background_temperature_k\": 2.7,"
                     " \"extent_min_m\": [-2, -2, -2], \"extent_max_m\": [2, 2, 2]}";
    if (scene_load_string(scene_with(ok, buf, sizeof buf), THZ_SOURCE_DIR, "t.json", &s, &err) !=
        THZ_OK)
        fail_msg("%s", err.message);
    assert_int_equal(s->atmosphere.model, ATM_LINES);
    assert_true(s->atmosphere.emitting && s->atmosphere.has_extent);
    assert_int_equal(s->atmosphere.n_tables, 1); /* prepared by the loader */
    double f = 0.35e12;
    assert_true(atmosphere_alpha_per_m(&s->atmosphere, f) > 0.0);
    assert_true(fabs(atmosphere_alpha_per_m(&s->atmosphere, f) /
                         atmosphere_alpha_direct_per_m(&s->atmosphere, f) -
                     1) < 1e-4);
    scene_destroy(s);
    s = NULL;

    /* catalogue paths are relative to the scene */
    const char *par =
        "{\"model\": \"lines\", \"temperature_k\": 290, \"pressure_hpa\": 1000,"
        " \"h2o_vmr\": 0.01, \"h2o_lines_file\": \"tests/inputs/atm_h2o_o2_subset.par\"}";
    if (scene_load_string(scene_with(par, buf, sizeof buf), THZ_SOURCE_DIR, "t.json", &s, &err) !=
        THZ_OK)
        fail_msg("%s", err.message);
    scene_destroy(s);
    s = NULL;

    static const struct {
        const char *atm, *expect;
    } bad[] = {
        {"{\"model\": \"itu-p676\", \"temperature_k\": 290, \"pressure_hpa\": 1000}",
         "atmosphere: the air needs one of"},
        {"{\"model\": \"lines\", \"temperature_k\": 290, \"pressure_hpa\": 1000, \"h2o_vmr\": 0,"
         " \"h2o_lines_file\": \"missing.par\"}",
         "missing.par"},
        {"{\"model\": \"itu-p676\", \"temperature_k\": 90, \"pressure_hpa\": 1000, \"h2o_vmr\": 0}",
         "atmosphere.temperature_k"},
        /* changed with emitting air by default: the background needs emitting air,
         * and its temperature, optional now, must still be in range */
        {"{\"model\": \"constant\", \"attenuation_per_m\": 0.1, \"emitting\": false,"
         " \"background_temperature_k\": 3}",
         "atmosphere.background_temperature_k"},
        {"{\"model\": \"constant\", \"attenuation_per_m\": 0.1, \"temperature_k\": 0,"
         " \"background_temperature_k\": 3}",
         "atmosphere.temperature_k"},
        {"{\"model\": \"itu-p676\", \"temperature_k\": 290, \"pressure_hpa\": 1000, \"h2o_vmr\": 0,"
         " \"continuum\": true}",
         "atmosphere.continuum: unknown key"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        thz_status st = scene_load_string(scene_with(bad[i].atm, buf, sizeof buf), THZ_SOURCE_DIR,
                                          "t.json", &s, &err);
        if (st != THZ_ERR_INPUT || !strstr(err.message, bad[i].expect))
            fail_msg("%s: status %d, message '%s', expected '%s'", bad[i].atm, st, err.message,
                     bad[i].expect);
        scene_destroy(s);
        s = NULL;
    }
}

/* The scene hash (which a saved photon map is checked against) sees the emitting flag
 * and the emitting air's temperature, also for models without an air state. */
static void test_scene_hash(void **state)
{
    (void)state;
    static const char *const atms[] = {
        "{\"model\": \"constant\", \"attenuation_per_m\": 0.1}",
        "{\"model\": \"constant\", \"attenuation_per_m\": 0.1, \"emitting\": true,"
        " \"temperature_k\": 290, \"background_temperature_k\": 3}",
        "{\"model\": \"constant\", \"attenuation_per_m\": 0.1, \"emitting\": true,"
        " \"temperature_k\": 291, \"background_temperature_k\": 3}",
    };
    scene_hash h[3];
    char buf[4096];
    for (size_t i = 0; i < 3; i++) {
        thz_scene *s = NULL;
        thz_error err = {0};
        if (scene_load_string(scene_with(atms[i], buf, sizeof buf), THZ_SOURCE_DIR, "t.json", &s,
                              &err) != THZ_OK)
            fail_msg("%s", err.message);
        scene_hash_compute(s, &h[i]);
        scene_destroy(s);
    }
    assert_true(h[0].optics != h[1].optics);
    assert_true(h[1].optics != h[2].optics);
    assert_true(h[0].geometry == h[2].geometry);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_volume_emission), cmocka_unit_test(test_transmittance),
        cmocka_unit_test(test_extent),          cmocka_unit_test(test_scene_keys),
        cmocka_unit_test(test_scene_hash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
