/* A measured response across a narrow line (issue 14): a top-hat channel over a material
 * whose reflectivity has a narrow line near the band's edge shows the top-hat band mean
 * of L = (1 - R) B(T1) + R B(T2) (identity 2 of physics.md), not the band mean over the
 * Gaussian of the same FWHM, which weights the line less. Checked per pixel against the
 * renderer's standard error for every integrator; the Gaussian's value must lie far
 * outside the top-hat image's tolerance, so that the test can tell the two apart. */
#include "identity.h"
#include "sensor/render_context.h"
#include "sensor/render_terms.h"

/* R(nu): 0 except a line of 1 from 0.357 to 0.3595 THz (ramps of 0.4 GHz), inside the
 * top-hat [0.34, 0.36] THz, where a Gaussian of FWHM 20 GHz centred on 0.35 THz has
 * fallen to about 0.6. */
static const double line_thz[] = {0.2, 0.3566, 0.357, 0.3595, 0.3599, 1.2};
static const double line_r[] = {0.0, 0.0, 1.0, 1.0, 0.0, 0.0};
#define LINE_POINTS 6

static const char *line_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"line-plate\","
    " \"channels\": [{\"name\": \"top-hat\", \"response\": [[0.34, 1], [0.36, 1]]},"
    "                {\"name\": \"gauss\", \"frequency_thz\": 0.35,"
    "                 \"relative_width\": 0.05714285714285714}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
    "   \"lined\": {\"reflectivity\": [[0.2, 0], [0.3566, 0], [0.357, 1], [0.3595, 1],"
    "                                [0.3599, 0], [1.2, 0]]}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\", \"temperature_k\": 350,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [1.2, 0.6, 1.2], \"inward\": true}},"
    "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"lined\", \"temperature_k\": 100,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [1.0, 0.1, 1.0]}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.28, 0], \"direction\": [0, 1, 0],"
    "   \"fov_deg\": 100, \"resolution\": [12, 12], \"normalize_to_k\": 300}],"
    " \"photons\": {\"per_channel\": 300000, \"seed\": 5}}";

static const double t1_k = 100.0, t2_k = 350.0;

/* The plate's radiance at freq_hz, R by linear interpolation of the table above. */
static double plate_radiance_at(double freq_hz, void *ctx)
{
    (void)ctx;
    double thz = freq_hz * 1e-12, r = 0.0;
    for (size_t i = 0; i + 1 < LINE_POINTS; i++)
        if (thz >= line_thz[i] && thz <= line_thz[i + 1])
            r = line_r[i] +
                (line_r[i + 1] - line_r[i]) * (thz - line_thz[i]) / (line_thz[i + 1] - line_thz[i]);
    return (1.0 - r) * planck_radiance(freq_hz, t1_k) + r * planck_radiance(freq_hz, t2_k);
}

/* The top-hat band mean of the plate's radiance: trapezoid on 200001 points over
 * [0.34, 0.36] THz (not the library's quadrature). */
static double top_hat_mean(void)
{
    const int n = 200000;
    double lo = 0.34e12, h = 0.02e12 / n, sum = 0.0;
    for (int i = 0; i <= n; i++)
        sum += plate_radiance_at(lo + h * i, NULL) * ((i == 0 || i == n) ? 0.5 : 1.0);
    return sum / n;
}

static void response_case(thz_integrator integrator)
{
    ident_run r;
    ident_run_scene_t0(&r, line_json, ident_photons(1000000), integrator, ident_estimates(32), NAN);
    assert_int_equal(r.scene->channels[0].n_response, 2);
    double expect[2] = {top_hat_mean(),
                        ident_band_mean(&r.scene->channels[1], plate_radiance_at, NULL)};
    /* the line: about 12 % of the top-hat, about 7 % of the Gaussian (weighted ~0.6) */
    print_message("top-hat band mean %.6e, Gaussian %.6e W m^-2 sr^-1 Hz^-1 (%+.2f %%)\n",
                  expect[0], expect[1], 100.0 * (expect[1] - expect[0]) / expect[0]);
    assert_true(fabs(expect[1] - expect[0]) > 0.01 * expect[0]);
    size_t pixels = (size_t)r.img.rows * r.img.columns;
    assert_true(pixels <= 144);
    for (size_t c = 0; c < 2; c++) {
        double expects[144];
        for (size_t i = 0; i < pixels; i++)
            expects[i] = expect[c];
        /* Deterministic floor: the renderer's fixed band-mean nodes (render_context's
         * 401 over +-6 sigma, 0.25 GHz apart for the Gaussian) resolve the line's 0.4 GHz
         * ramps to ~6e-4; over the top-hat they are 0.05 GHz apart and the table's points
         * are among them. */
        double floor_rel = c == 0 ? 1e-4 : 1e-3;
        ident_tally t = {.pooled_rel_se = ident_pooled_rel_se(&r, c, expects)};
        ident_tally wrong = t; /* the top-hat image against the Gaussian's value */
        for (uint32_t row = 0; row < r.img.rows; row++)
            for (uint32_t col = 0; col < r.img.columns; col++) {
                assert_int_equal(r.img.object_id[row * r.img.columns + col], 1);
                assert_true(ident_pixel_interior(&r, col, row));
                ident_check_pixel(&t, &r, c, col, row, expect[c], floor_rel);
                if (c == 0) {
                    size_t i = ident_at(&r, 0, col, row);
                    wrong.sum_diff += (r.img.radiance[i] - expect[1]) / expect[1];
                    wrong.pixels++;
                }
            }
        char label[64], what[192];
        ident_label(label, sizeof label, integrator, NAN);
        snprintf(what, sizeof what, "line plate, %s, %s", label, r.scene->channels[c].name);
        ident_tally_assert(&t, what, 0.12 / sqrt(ident_scale()), floor_rel);
        if (c == 0) {
            /* the image's mean is as far from the Gaussian's value as the two values are
             * apart, many times the mean's standard error */
            double mean = wrong.sum_diff / (double)wrong.pixels;
            double se_mean = 1.3 * sqrt(t.sum_var) / (double)t.pixels;
            assert_true(fabs(mean) > IDENT_Z * se_mean + floor_rel);
        }
    }
    ident_run_fini(&r);
}

static void test_top_hat_over_a_line(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        response_case(ident_integrators[k]);
}

/* The renderer's band tables (T-bar, R-bar, Ward's scale: render_context) are read at a
 * photon's frequency by interpolation between the quadrature nodes. A measured
 * response's nodes are not evenly spaced (each piece has its own Simpson spacing), so at
 * every node the interpolation must give that node's own entry, not a neighbour's. A
 * diffuse shell whose index changes across the band makes T-bar differ from node to
 * node. */
static void test_band_tables_at_nodes(void **state)
{
    (void)state;
    const char *json =
        "{\"format\": \"thzmap-scene/1\", \"name\": \"uneven-nodes\","
        " \"channels\": [{\"response\": [[0.3, 0.2], [0.3137, 1], [0.3571, 1], [0.371, 0.1]]}],"
        " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
        "   \"foam\": {\"refractive_index\": [[0.25, 1.4, 0.01], [0.45, 2.6, 0.3]],"
        "     \"transmission\": \"diffuse\"}},"
        " \"objects\": ["
        "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
        "    \"temperature_k\": 300, \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2],"
        "    \"inward\": true}},"
        "   {\"name\": \"veil\", \"type\": \"shell\", \"thickness_m\": 0.002,"
        "    \"material\": \"foam\", \"temperature_k\": 300,"
        "    \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.5, 0.5]}}],"
        " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0],"
        "   \"direction\": [0, 1, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}],"
        " \"render\": {\"integrator\": \"path\"}}";
    thz_scene *scene = NULL;
    thz_error err = {0};
    if (scene_load_string(json, ".", "uneven-nodes.json", &scene, &err) != THZ_OK)
        fail_msg("refused: %s", err.message);
    render_context *ctx = NULL;
    if (render_context_create(scene, NULL, NULL, 0, NULL, &ctx, &err) != THZ_OK)
        fail_msg("render context: %s", err.message);
    size_t n = ctx->quad.n;
    const double *f = ctx->quad.freq_hz;
    double spacing_min = INFINITY, spacing_max = 0.0;
    for (size_t k = 0; k + 1 < n; k++) {
        spacing_min = fmin(spacing_min, f[k + 1] - f[k]);
        spacing_max = fmax(spacing_max, f[k + 1] - f[k]);
    }
    print_message("%zu nodes, spacing %.4f..%.4f GHz; T-bar %.5f..%.5f\n", n, 1e-9 * spacing_min,
                  1e-9 * spacing_max, ctx->tbar[n], ctx->tbar[2 * n - 1]);
    assert_true(spacing_max > 1.01 * spacing_min); /* uneven: the case under test */
    assert_true(fabs(ctx->tbar[2 * n - 1] / ctx->tbar[n] - 1.0) > 0.01);
    const thz_object *veil = &scene->objects[1];
    for (size_t k = 0; k + 1 < n; k++) {
        double v = render_tbar(ctx, veil, 1, f[k]), expect = ctx->tbar[n + k];
        if (!(fabs(v - expect) <= 1e-12 * expect))
            fail_msg("node %zu (%.6f THz): interpolated T-bar %.9f, the node's %.9f", k,
                     1e-12 * f[k], v, expect);
    }
    render_context_destroy(ctx);
    scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_band_tables_at_nodes),
                                       cmocka_unit_test(test_top_hat_over_a_line)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
