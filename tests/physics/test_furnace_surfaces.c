/* The furnace (physics.md identity 1) with the surfaces of a complex index and the new
 * lobes: Fresnel walls (diffuse, R(theta)), a mirror ball, a Ward plate with its
 * Kulla-Conty complement, a Fresnel slab with diffuse transmission and a straight slab
 * that is also a mirror, all at 300 K: every pixel sees B(T), N = 1, for every
 * integrator (path and final-gather exactly, photon-map within its noise). */
#include "identity.h"

static const char *furnace_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"furnace-surfaces\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"
    " \"materials\": {"
    "   \"wall\": {\"refractive_index\": [2.0, 0.3]},"
    "   \"ball\": {\"refractive_index\": [1.5, 0.05], \"reflection\": \"specular\"},"
    "   \"brushed\": {\"refractive_index\": [3.0, 0.5],"
    "     \"reflection\": {\"model\": \"ward\", \"alpha_x\": 0.15, \"alpha_y\": 0.4}},"
    "   \"foam\": {\"refractive_index\": [1.5, 0.02], \"transmission\": \"diffuse\"},"
    "   \"glass\": {\"refractive_index\": [1.8, 0.01], \"transmission\": \"straight\","
    "     \"reflection\": \"specular\"}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 300,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"
    "   {\"name\": \"ball\", \"type\": \"solid\", \"material\": \"ball\", \"temperature_k\": 300,"
    "    \"shape\": {\"type\": \"sphere\", \"radius_m\": 0.3},"
    "    \"transform\": {\"translate_m\": [0.45, 0.2, -0.3]}},"
    "   {\"name\": \"sheet\", \"type\": \"solid\", \"two_sided\": true, \"material\": \"brushed\","
    "    \"temperature_k\": 300, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.7, 0.7]},"
    "    \"transform\": {\"rotate_deg\": [60, 0, 30], \"translate_m\": [-0.4, 0.4, 0.3]}},"
    "   {\"name\": \"can\", \"type\": \"shell\", \"thickness_m\": 0.002, \"material\": \"foam\","
    "    \"temperature_k\": 300,"
    "    \"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.25, \"height_m\": 0.7, \"caps\": "
    "false},"
    "    \"transform\": {\"translate_m\": [-0.2, 0.6, -0.8]}},"
    "   {\"name\": \"veil\", \"type\": \"shell\", \"thickness_m\": 0.002, \"material\": \"glass\","
    "    \"temperature_k\": 300, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.6, 0.6]},"
    "    \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [-0.3, -0.5, 0]}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0], \"direction\": [0, 1, 0],"
    "   \"up\": [0, 0, 1], \"fov_deg\": 90, \"resolution\": [16, 16], \"oversampling\": 1,"
    "   \"aperture_m2\": 0.01, \"normalize_to_k\": 300}],"
    " \"photons\": {\"per_channel\": 200000, \"seed\": 3}}";

static void furnace_case(thz_integrator integrator)
{
    ident_run r;
    ident_run_scene_with(&r, furnace_json, ident_photons(200000), integrator, ident_estimates(16));
    const thz_channel *ch = &r.scene->channels[0];
    double b = ident_band_planck(ch, 300.0);
    assert_int_equal(r.rstats[0].escaped_samples, 0);
    assert_int_equal(r.rstats[0].back_face_samples, 0);
    /* final-gather's deviation map at the furnace's 300 K is empty: exact like path */
    ident_tally t = {.exact = integrator == INTEGRATOR_FINAL_GATHER};
    ident_check_furnace_channel(&t, &r, 0, integrator, b);
    char what[96];
    snprintf(what, sizeof what, "furnace with Fresnel, mirror and Ward surfaces, %s",
             render_integrator_name(integrator));
    if (integrator == INTEGRATOR_PHOTON_MAP)
        ident_tally_assert(&t, what, 0.15 / sqrt(ident_scale()), 0.0);
    else
        print_message("%s: %zu pixels exact (N = 1 to 1e-9)\n", what, t.pixels);
    ident_run_fini(&r);
}

/* final-gather and path with T0 = 0 K: nothing cancels against B(T0), so the lobes'
 * sampling weights (Ward's, the Fresnel BRDF's, the slab's) carry the whole reflected and
 * transmitted radiance; interior pixels within their noise. */
static void furnace_t0_zero(thz_integrator integrator)
{
    ident_run r;
    ident_run_scene_t0(&r, furnace_json, ident_photons(200000), integrator, ident_estimates(32),
                       0.0);
    double b = ident_band_planck(&r.scene->channels[0], 300.0);
    double expects[256];
    for (size_t i = 0; i < 256; i++)
        expects[i] = b;
    /* a pixel's own error from 32 estimates is Student-t distributed: pooled (identity.h) */
    ident_tally t = {.pooled_rel_se = ident_pooled_rel_se(&r, 0, expects)};
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++)
            if (ident_pixel_interior(&r, col, row))
                ident_check_pixel(&t, &r, 0, col, row, b,
                                  integrator == INTEGRATOR_FINAL_GATHER ? 3e-3 : 1e-5);
    char what[96];
    snprintf(what, sizeof what, "furnace with new surfaces, %s, T0 = 0 K",
             render_integrator_name(integrator));
    ident_tally_assert(&t, what, 0.15 / sqrt(ident_scale()), 3e-3);
    ident_run_fini(&r);
}

static void test_furnace_surfaces(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        furnace_case(ident_integrators[k]);
    furnace_t0_zero(INTEGRATOR_PATH);
    furnace_t0_zero(INTEGRATOR_FINAL_GATHER);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_furnace_surfaces)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
