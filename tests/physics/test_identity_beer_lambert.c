/* Identity 4 (physics.md): a black surface at T seen through an atmosphere of constant
 * alpha at distance d shows L = B(T) exp(-alpha d) (band mean of B times the
 * transmittance: alpha is constant over the band). Black surfaces reflect nothing, so
 * the answer is deterministic and checked to 1e-5 (float images, float ray distances)
 * for photon-map and final-gather (nothing to gather); `path` samples the frequency, so
 * its pixels carry the band noise of (tau - 1) B(T0) and are checked within 5 of their
 * standard errors on top. */
#include "identity.h"

static const char *corridor_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"corridor\","
    " \"channels\": [{\"frequency_thz\": 0.3, \"relative_width\": 0.2},"
    "                {\"frequency_thz\": 0.9, \"relative_width\": 0.01}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0}},"
    " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.15,"
    " \"emitting\": false},"
    " \"objects\": ["
    "   {\"name\": \"corridor\", \"type\": \"solid\", \"material\": \"black\","
    "    \"temperature_k\": 310,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [1, 10, 1], \"inward\": true}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -4.9, 0], \"direction\": [0, 1, 0],"
    "   \"fov_deg\": 4, \"resolution\": [8, 6], \"normalize_to_k\": 310}],"
    " \"photons\": {\"per_channel\": 2000, \"seed\": 1}}";

static void beer_lambert_case(thz_integrator integrator, double t0_k)
{
    ident_run r;
    ident_run_scene_t0(&r, corridor_json, 0, integrator, ident_estimates(32), t0_k);
    bool sampled = integrator == INTEGRATOR_PATH;
    const double alpha = 0.15, temp_k = 310.0, wall_y = 5.0, cam_y = -4.9;
    for (size_t c = 0; c < r.scene->n_channels; c++) {
        double b = ident_band_planck(&r.scene->channels[c], temp_k);
        for (uint32_t row = 0; row < r.img.rows; row++)
            for (uint32_t col = 0; col < r.img.columns; col++) {
                vec3 dir = camera_pixel_center_dir(&r.cam, col, row);
                double d = (wall_y - cam_y) / dir.y; /* every pixel sees the far wall */
                double expect = b * exp(-alpha * d);
                size_t i = ident_at(&r, c, col, row);
                double l = r.img.radiance[i], se = r.img.radiance_stderr[i];
                double tol = 1e-5 * expect + (sampled ? 5.0 * se : 0.0);
                if (!(fabs(l - expect) <= tol))
                    print_message("%s channel %zu pixel (%u, %u): L = %.8e, expected %.8e\n",
                                  render_integrator_name(integrator), c, col, row, l, expect);
                assert_true(fabs(l - expect) <= tol);
                /* no photon term; path: the band noise only (well below 1 %) */
                if (!(sampled ? se < 0.01 * expect : se == 0.0))
                    print_message("%s: stderr %.3e of %.3e\n", render_integrator_name(integrator),
                                  se, expect);
                assert_true(sampled ? se < 0.01 * expect : se == 0.0);
                /* the attenuation is real: without it L would be e^{alpha d} ~ 4.4x larger */
                assert_true(r.img.normalized[i] < 0.3);
                assert_true(fabs(r.img.distance_m[row * r.img.columns + col] - d) < 1e-5 * d);
            }
    }
    ident_run_fini(&r);
}

static void test_beer_lambert(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        for (size_t v = 0; v < IDENT_N_T0; v++)
            if (ident_t0_applies(ident_integrators[k], v))
                beer_lambert_case(ident_integrators[k], ident_t0s[v]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_beer_lambert)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
