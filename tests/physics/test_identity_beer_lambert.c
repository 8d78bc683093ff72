/* Identity 4 (physics.md): a black surface at T seen through an atmosphere of constant
 * alpha at distance d shows L = B(T) exp(-alpha d) (band mean of B times the
 * transmittance: alpha is constant over the band). Black surfaces reflect nothing, so
 * the answer is deterministic and checked to 1e-5 (float images, float ray distances). */
#include "identity.h"

static const char *corridor_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"corridor\","
    " \"channels\": [{\"frequency_thz\": 0.3, \"relative_width\": 0.2},"
    "                {\"frequency_thz\": 0.9, \"relative_width\": 0.01}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0}},"
    " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.15},"
    " \"objects\": ["
    "   {\"name\": \"corridor\", \"type\": \"solid\", \"material\": \"black\","
    "    \"temperature_k\": 310,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [1, 10, 1], \"inward\": true}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -4.9, 0], \"direction\": [0, 1, 0],"
    "   \"fov_deg\": 4, \"resolution\": [8, 6], \"normalize_to_k\": 310}],"
    " \"photons\": {\"per_channel\": 2000, \"seed\": 1}}";

static void test_beer_lambert(void **state)
{
    (void)state;
    ident_run r;
    ident_run_scene(&r, corridor_json, 0);
    const double alpha = 0.15, temp_k = 310.0, wall_y = 5.0, cam_y = -4.9;
    for (size_t c = 0; c < r.scene->n_channels; c++) {
        double b = ident_band_planck(&r.scene->channels[c], temp_k);
        for (uint32_t row = 0; row < r.img.rows; row++)
            for (uint32_t col = 0; col < r.img.columns; col++) {
                vec3 dir = camera_pixel_center_dir(&r.cam, col, row);
                double d = (wall_y - cam_y) / dir.y; /* every pixel sees the far wall */
                double expect = b * exp(-alpha * d);
                size_t i = ident_at(&r, c, col, row);
                double l = r.img.radiance[i];
                if (!(fabs(l - expect) <= 1e-5 * expect))
                    print_message("channel %zu pixel (%u, %u): L = %.8e, expected %.8e\n", c, col,
                                  row, l, expect);
                assert_true(fabs(l - expect) <= 1e-5 * expect);
                assert_true(r.img.radiance_stderr[i] == 0.0f); /* no photon term */
                /* the attenuation is real: without it L would be e^{alpha d} ~ 4.4x larger */
                assert_true(r.img.normalized[i] < 0.3);
                assert_true(fabs(r.img.distance_m[row * r.img.columns + col] - d) < 1e-5 * d);
            }
    }
    ident_run_fini(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_beer_lambert)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
