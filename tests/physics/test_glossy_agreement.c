/* All integrators agree on a glossy scene (issue 15): a brushed Ward plate of a complex
 * index (and its Kulla-Conty complement) reflects a hot block in a cool room; the mean
 * radiance over the plate's pixels from photon-map and final-gather must match path's
 * (the unbiased reference) within their combined standard errors plus the density
 * estimate's blur (1 %: photon-map averages the lobe's view over its gather disk). */
#include "identity.h"

static const char *glossy_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"glossy\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.03}],"
    " \"materials\": {\"wall\": {\"reflectivity\": 0.1},"
    "   \"brushed\": {\"refractive_index\": [2.5, 1.5],"
    "     \"reflection\": {\"model\": \"ward\", \"alpha_x\": 0.25, \"alpha_y\": 0.5}}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 290,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [3, 3, 3], \"inward\": true}},"
    "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"brushed\","
    "    \"temperature_k\": 290, \"shape\": {\"type\": \"box\", \"size_m\": [1.2, 1.2, 0.05]},"
    "    \"transform\": {\"translate_m\": [0, 0, -0.6]}},"
    "   {\"name\": \"hot\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 400,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.6, 0.2, 0.6]},"
    "    \"transform\": {\"translate_m\": [0, 0.8, 0]}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0.3], \"look_at_m\": [0, 0, "
    "-0.6],"
    "   \"up\": [0, 0, 1], \"fov_deg\": 40, \"resolution\": [12, 12], \"oversampling\": 2,"
    "   \"normalize_to_k\": 300}],"
    " \"photons\": {\"per_channel\": 400000, \"seed\": 9, \"gather_min_photons\": 64}}";

typedef struct plate_mean {
    double mean, se;
} plate_mean;

static plate_mean run(thz_integrator integrator)
{
    ident_run r;
    ident_run_scene_with(&r, glossy_json, ident_photons(400000), integrator, ident_estimates(32));
    plate_mean m = {0.0, 0.0};
    size_t n = 0;
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            size_t i = ident_at(&r, 0, col, row);
            if (r.img.object_id[row * r.img.columns + col] != 1)
                continue;
            m.mean += r.img.radiance[i];
            m.se += r.img.radiance_stderr[i] * r.img.radiance_stderr[i];
            n++;
        }
    assert_true(n >= 60);
    m.mean /= (double)n;
    m.se = sqrt(m.se) / (double)n;
    print_message("glossy plate, %s: mean L %.6e W m^-2 sr^-1 Hz^-1 over %zu pixels (se %.3f %%)\n",
                  render_integrator_name(integrator), m.mean, n, 100.0 * m.se / m.mean);
    ident_run_fini(&r);
    return m;
}

static void test_glossy_agreement(void **state)
{
    (void)state;
    plate_mean ref = run(INTEGRATOR_PATH);
    assert_true(ref.se <= 0.01 * ref.mean);
    const thz_integrator others[] = {INTEGRATOR_PHOTON_MAP, INTEGRATOR_FINAL_GATHER};
    for (size_t k = 0; k < 2; k++) {
        plate_mean m = run(others[k]);
        double tol = IDENT_Z * sqrt(m.se * m.se + ref.se * ref.se) + 0.01 * ref.mean;
        print_message("%s - path: %+.3f %% (tolerance %.3f %%)\n",
                      render_integrator_name(others[k]), 100.0 * (m.mean / ref.mean - 1.0),
                      100.0 * tol / ref.mean);
        assert_true(fabs(m.mean - ref.mean) <= tol);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_glossy_agreement)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
