/* The three integrators against each other (physics.md "Integrators"), and the honesty
 * of their per-pixel standard errors, on a scene with reflective solids, a diffuse and a
 * straight shell and temperature contrasts:
 *
 *   cross-validation (without and with an attenuating atmosphere): `path` with many
 *     paths is the reference; photon-map and final-gather agree with it, pixel by
 *     pixel away from object borders, within
 *     IDENT_Z combined standard errors plus a bias allowance (the density estimates'
 *     edge and disk bias, measured and printed), their mean deviation over the
 *     picture stays within that allowance, and the mean of their z-scores within
 *     5 / sqrt(pixels), with no allowance; with 2 x 2 samples per pixel, whose first
 *     scattered directions are stratified together, final-gather and path itself;
 *   honesty: over M runs with different seeds, the observed spread of each pixel
 *     matches its reported standard error: pooled over the pixels, the ratio of the
 *     observed variance to the mean reported variance is within 20 % of 1. With M runs
 *     and P pixels its relative precision is about sqrt(2 / ((M - 1) P)) (a few %), so
 *     the 20 % test can fail. final-gather's error holds the map's own noise (the spread
 *     between the map's photon batches), so it is checked over photon seeds, also from
 *     the paper's map of L where that noise is large, and against the same without the
 *     map term, which must fail; photon-map's Poisson estimate over photon seeds, also
 *     through a straight cover 1 mm in front of a reflective solid (a garment on a body),
 *     where one photon is recorded on the cover and again behind it. */
#include "identity.h"
#include "xval_scene.h"

/* The others against the reference, `path` with one sample per pixel. With n x n samples
 * per pixel (n > 1), whose first scattered directions are stratified together
 * (render_stratum), the others are final-gather and path itself, with the estimates per
 * sample divided by n^2 so that a pixel gets as many as with n = 1: interior pixels' mean
 * over their samples differs from their centre's value at second order only. */
static void cross_validation(double alpha_per_m, uint32_t oversampling)
{
    char json[8192], json_n[8192];
    xval_scene(json, sizeof json, 20, 1, alpha_per_m, 21);
    xval_scene(json_n, sizeof json_n, 20, oversampling, alpha_per_m, 21);
    print_message("atmosphere: %g 1/m, the others with %u x %u samples per pixel\n", alpha_per_m,
                  oversampling, oversampling);
    double per_pixel = (double)(oversampling * oversampling);
    ident_run ref;
    ident_run_scene_with(&ref, json, 0, INTEGRATOR_PATH, ident_estimates(1024));
    size_t px = (size_t)ref.img.columns * ref.img.rows;
    const bool strata = oversampling > 1;
    const thz_integrator others[] = {strata ? INTEGRATOR_PATH : INTEGRATOR_PHOTON_MAP,
                                     INTEGRATOR_FINAL_GATHER};
    /* bias allowances, relative to L: the density estimates' edge and disk bias in this
     * scene (photon-map: footprint disks, widened where photons are sparse; final-gather:
     * the 64-photon disks of its secondary hits, over its deviation map: only the
     * deviation from B(T0) is blurred); path against path none per pixel, and for the mean
     * over the interior 0.02 %, about 10 of its standard errors (a polar band's uniform
     * halved in path's strata fails by a pixel at z = -6.2, the azimuth's halved by far) */
    const double allowance[] = {strata ? 0.0 : 0.01, 0.005};
    const double mean_allowance[] = {strata ? 0.0002 : 0.01, 0.005};
    for (size_t k = 0; k < 2; k++) {
        ident_run r;
        ident_run_scene_with(
            &r, strata ? json_n : json, ident_photons(300000), others[k],
            ident_estimates((others[k] == INTEGRATOR_PATH ? 1024 : 64) / per_pixel));
        size_t n = 0, failed = 0;
        double sum_rel = 0.0, worst_z = 0.0, sum_se_ref = 0.0, sum_z = 0.0;
        for (uint32_t row = 0; row < r.img.rows; row++)
            for (uint32_t col = 0; col < r.img.columns; col++) {
                size_t i = ident_at(&r, 0, col, row);
                if (!ident_pixel_interior(&r, col, row))
                    continue;
                double l = r.img.radiance[i], l_ref = ref.img.radiance[i];
                double se = hypot(r.img.radiance_stderr[i], ref.img.radiance_stderr[i]);
                double tol = IDENT_Z * se + allowance[k] * l_ref;
                double z = (l - l_ref) / se;
                n++;
                sum_z += z;
                sum_rel += (l - l_ref) / l_ref;
                sum_se_ref += ref.img.radiance_stderr[i] / l_ref;
                if (fabs(z) > fabs(worst_z))
                    worst_z = z;
                if (!(fabs(l - l_ref) <= tol)) {
                    if (failed < 8)
                        print_message(
                            "%s pixel (%u, %u): L = %.5e, path %.5e (%+.3f %%, z = %.1f)\n",
                            render_integrator_name(others[k]), col, row, l, l_ref,
                            100.0 * (l - l_ref) / l_ref, z);
                    failed++;
                }
            }
        double mean_rel = sum_rel / (double)n;
        print_message("%s vs path: %zu interior of %zu pixels, mean deviation %+.3f %%, worst z "
                      "%.2f, mean z %+.3f, path's mean stderr %.4f %%\n",
                      render_integrator_name(others[k]), n, px, 100.0 * mean_rel, worst_z,
                      sum_z / (double)n, 100.0 * sum_se_ref / (double)n);
        assert_true(n > px / 3);
        assert_int_equal(failed, 0);
        assert_true(fabs(mean_rel) <= mean_allowance[k]);
        /* and the mean of the pixels' z-scores within 5 / sqrt(n) (measured |mean z| <= 0.11
         * at THZ_TEST_SCALE 1 and 0.25): no allowance, so a bias that the per-pixel
         * allowance hides fails here (final-gather without its photon guide's weight,
         * -0.15 % of L: mean z -1.4 to -1.9, and -0.5 at scale 0.25) */
        assert_true(fabs(sum_z / (double)n) <= 5.0 / sqrt((double)n));
        ident_run_fini(&r);
    }
    /* the reference is tight: its standard errors are far below the allowances */
    double worst = 0.0;
    for (size_t i = 0; i < px; i++)
        if (ref.img.radiance[i] > 0.0)
            worst = fmax(worst, ref.img.radiance_stderr[i] / ref.img.radiance[i]);
    print_message("path reference: largest pixel stderr %.4f %%\n", 100.0 * worst);
    /* (through the atmosphere the reflected radiance varies with the distance behind, a
     * real variance that the B0 control variate cannot remove) */
    assert_true(worst < (alpha_per_m > 0.0 ? 0.01 : 0.004) / sqrt(ident_scale()));
    /* the scene has contrast: the picture spans more than 30 K of brightness temperature */
    double tmin = 1e9, tmax = 0.0;
    for (size_t i = 0; i < px; i++) {
        tmin = fmin(tmin, ref.img.brightness_temperature[i]);
        tmax = fmax(tmax, ref.img.brightness_temperature[i]);
    }
    assert_true(tmax - tmin > 30.0);
    ident_run_fini(&ref);
}

static void test_cross_validation(void **state)
{
    (void)state;
    cross_validation(0.0, 1);
    /* an attenuating atmosphere (e^-0.6 across the room): path's (tau - 1) B0 terms */
    cross_validation(0.3, 1);
    /* the strata across a pixel's 2 x 2 samples keep final-gather and path unbiased */
    cross_validation(0.0, 2);
}

/* Renders channel 0 of sensor 0 M times and pools observed against reported variance. */
#define HONEST_RUNS 16
#define HONEST_RES 12

/* How the honesty runs vary: one photon map for all runs; photons and estimates per
 * sample (base values, scaled by THZ_TEST_SCALE); final-gather without its map term (the
 * map's batches withheld, as for a map without them). */
typedef struct honesty_case {
    bool fixed_map;
    double photons, estimates;
    bool no_batches;
    bool planck_map;       /* final-gather from the paper's map of L (T0 = 0), as `render` does
                              with a map that `simulate --integrator photon-map` saved */
    bool deviation_map;    /* photon-map from a deviation map, as `render` does with a map
                              that `simulate --integrator final-gather` saved */
    uint32_t oversampling; /* n x n samples per pixel (0: 1) */
    bool tight_cover;      /* the scene TIGHT_COVER_JSON instead of the cross-validation's */
} honesty_case;

/* A straight film 1 mm in front of a reflective box, filling the view: a sample's density
 * estimates on the film and on the box behind it share the photons that crossed the film
 * there (each is recorded at both hits), so their errors are correlated; with the film's
 * R about the box's R x T(film) the two are of one size. */
#define TIGHT_COVER_JSON                                                                           \
    "{\"format\": \"thzmap-scene/1\", \"name\": \"tight-cover\","                                  \
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"                         \
    " \"materials\": {\"wall\": {\"reflectivity\": 0.2}, \"grey\": {\"reflectivity\": 0.3},"       \
    "   \"film\": {\"reflectivity\": 0.2, \"attenuation_per_m\": 100,"                             \
    "            \"transmission\": \"straight\"}},"                                                \
    " \"objects\": ["                                                                              \
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 295," \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"                \
    "   {\"name\": \"body\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 320," \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.6, 0.2, 0.6]},"                             \
    "    \"transform\": {\"translate_m\": [0, 0.1, 0]}},"                                          \
    "   {\"name\": \"cover\", \"type\": \"shell\", \"thickness_m\": 0.001, \"material\": "         \
    "\"film\","                                                                                    \
    "    \"temperature_k\": 300, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.6, 0.6]},"    \
    "    \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [0, -0.001, 0]}}],"          \
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.6, 0], \"direction\": [0, 1, 0],"   \
    "   \"up\": [0, 0, 1], \"fov_deg\": 40, \"resolution\": [%u, %u], \"aperture_m2\": 0.01}],"    \
    " \"photons\": {\"per_channel\": 100000, \"seed\": 1}}"

static double honesty_ratio(thz_integrator integrator, honesty_case hc)
{
    bool fixed_map = hc.fixed_map;
    char json[8192];
    if (hc.tight_cover)
        snprintf(json, sizeof json, TIGHT_COVER_JSON, HONEST_RES, HONEST_RES);
    else
        xval_scene(json, sizeof json, HONEST_RES, hc.oversampling ? hc.oversampling : 1, 0.0, 1);
    size_t px = (size_t)HONEST_RES * HONEST_RES;
    double sum[HONEST_RES * HONEST_RES] = {0}, sum2[HONEST_RES * HONEST_RES] = {0};
    double rep[HONEST_RES * HONEST_RES] = {0};
    thz_error err;
    thz_scene *scene = NULL;
    assert_int_equal(scene_load_string(json, ".", "honesty", &scene, &err), THZ_OK);
    scene->render.integrator = integrator;
    scene->render.paths_per_sample = ident_estimates(hc.estimates);
    scene->render.gather_rays = ident_estimates(hc.estimates);
    scene->photons.per_channel = ident_photons(hc.photons);
    accel *acc = NULL;
    assert_int_equal(accel_create(scene, &acc, &err), THZ_OK);
    photon_map *map = NULL;
    photon_phase_options po = ident_photon_options(scene, 0, integrator);
    if (hc.planck_map)
        po.reference_temperature_k = 0.0;
    if (hc.deviation_map)
        po.reference_temperature_k = scene_reference_temperature_k(scene, 0);
    render_options ro = {.threads = 2};
    for (int m = 0; m < HONEST_RUNS; m++) {
        scene->photons.seed = 1000 + (uint64_t)m;
        if (render_integrator_needs_photons(integrator) && (!fixed_map || !map)) {
            photon_map_destroy(map);
            map = NULL;
            assert_int_equal(photon_phase_run(scene, acc, 0, &po, &map, NULL, &err), THZ_OK);
            if (hc.no_batches)
                photon_map_set_batches(map, 1);
        }
        sensor_images img;
        assert_int_equal(sensor_images_init(&img, HONEST_RES, HONEST_RES, 1, 1, &err), THZ_OK);
        assert_int_equal(render_sensor_channel(scene, acc, map, 0, 0, &img, &ro, NULL, &err),
                         THZ_OK);
        for (size_t p = 0; p < px; p++) {
            sum[p] += img.radiance[p];
            sum2[p] += (double)img.radiance[p] * img.radiance[p];
            rep[p] += (double)img.radiance_stderr[p] * img.radiance_stderr[p];
        }
        sensor_images_fini(&img);
    }
    double obs = 0.0, reported = 0.0;
    size_t used = 0;
    for (size_t p = 0; p < px; p++) {
        double mean = sum[p] / HONEST_RUNS;
        double var = (sum2[p] - HONEST_RUNS * mean * mean) / (HONEST_RUNS - 1);
        if (!(rep[p] > 0.0))
            continue;
        /* relative to the pixel's value, so that bright pixels do not dominate */
        obs += var / (mean * mean);
        reported += rep[p] / HONEST_RUNS / (mean * mean);
        used++;
    }
    photon_map_destroy(map);
    accel_destroy(acc);
    scene_destroy(scene);
    double ratio = sqrt(obs / reported);
    print_message(
        "%s%s%s%s%s%s%s, %llu photons, %u estimates: observed / reported standard error = "
        "%.3f over %zu pixels x %d runs (precision ~%.1f %%)\n",
        render_integrator_name(integrator), hc.tight_cover ? " (tight cover)" : "",
        fixed_map ? " (one photon map)" : "", hc.no_batches ? " (no map term)" : "",
        hc.planck_map ? " (map of L)" : "", hc.deviation_map ? " (deviation map)" : "",
        hc.oversampling > 1 ? " (strata)" : "", (unsigned long long)ident_photons(hc.photons),
        ident_estimates(hc.estimates), ratio, used, HONEST_RUNS,
        100.0 * sqrt(1.0 / (2.0 * (HONEST_RUNS - 1) * (double)used)));
    assert_true(used > px / 2);
    return ratio;
}

static void test_stderr_is_honest_path(void **state)
{
    (void)state;
    double r = honesty_ratio(INTEGRATOR_PATH, (honesty_case){.estimates = 16});
    assert_true(fabs(r - 1.0) <= 0.2);
}

/* final-gather over photon seeds, so that the map's own noise is in the spread: with its
 * deviation map (simulate's), and from the paper's map of L, whose noise is a large part
 * of the error; there, without the map term (batches withheld) the reported error falls
 * short by more than the 1.2 x the checks allow (1.27 and 1.31 x on two triangulations
 * of the room, whose maps' noise is shared by neighbouring pixels): the check that the
 * term is needed and that the test can fail. */
static void test_stderr_is_honest_final_gather(void **state)
{
    (void)state;
    double r =
        honesty_ratio(INTEGRATOR_FINAL_GATHER, (honesty_case){.photons = 100000, .estimates = 16});
    assert_true(fabs(r - 1.0) <= 0.2);
    r = honesty_ratio(INTEGRATOR_FINAL_GATHER,
                      (honesty_case){.photons = 100000, .estimates = 16, .planck_map = true});
    assert_true(fabs(r - 1.0) <= 0.2);
    r = honesty_ratio(INTEGRATOR_FINAL_GATHER,
                      (honesty_case){.photons = 100000, .estimates = 64, .planck_map = true});
    assert_true(fabs(r - 1.0) <= 0.2);
    r = honesty_ratio(
        INTEGRATOR_FINAL_GATHER,
        (honesty_case){.photons = 100000, .estimates = 16, .no_batches = true, .planck_map = true});
    assert_true(r > 1.2);
}

/* With one photon map the spread holds the gather rays' noise only: the reported error
 * (which includes the map's) may exceed it, never fall short. */
static void test_final_gather_one_map(void **state)
{
    (void)state;
    double r = honesty_ratio(INTEGRATOR_FINAL_GATHER,
                             (honesty_case){.fixed_map = true, .photons = 100000, .estimates = 16});
    assert_true(r >= 0.6 && r <= 1.2);
}

/* The strata of the j-th gather rays (paths) of a pixel's samples (render_stratum):
 * estimate j stays independent of the others, so the spread between estimates still gives
 * the error. For final-gather with one map and without its term (batches withheld), the
 * reported error is the gather rays' alone and must match the spread over seeds; strata
 * shared between estimates make it fall 2.8 x short. From the map of L, whose noise is
 * much of the error, with 2 x 2 samples: the map term's disk variance summed with the
 * samples' weight 1/n^2 (not its square) took out 4 x the disks' share and reported
 * 1/1.225 of the error (1.047 right); the check there is 0.15, 10 x its precision. */
static void test_strata_honest(void **state)
{
    (void)state;
    double r = honesty_ratio(INTEGRATOR_FINAL_GATHER, (honesty_case){.fixed_map = true,
                                                                     .photons = 100000,
                                                                     .estimates = 16,
                                                                     .no_batches = true,
                                                                     .oversampling = 2});
    assert_true(fabs(r - 1.0) <= 0.2);
    r = honesty_ratio(INTEGRATOR_FINAL_GATHER,
                      (honesty_case){.photons = 100000, .estimates = 16, .oversampling = 2});
    assert_true(fabs(r - 1.0) <= 0.2);
    r = honesty_ratio(
        INTEGRATOR_FINAL_GATHER,
        (honesty_case){.photons = 100000, .estimates = 16, .planck_map = true, .oversampling = 2});
    assert_true(fabs(r - 1.0) <= 0.15);
    r = honesty_ratio(INTEGRATOR_PATH, (honesty_case){.estimates = 16, .oversampling = 2});
    assert_true(fabs(r - 1.0) <= 0.2);
    /* 5 x 5 samples: a set of 16 and one of 9 */
    r = honesty_ratio(INTEGRATOR_PATH, (honesty_case){.estimates = 4, .oversampling = 5});
    assert_true(fabs(r - 1.0) <= 0.2);
}

static void test_stderr_is_honest_photon_map(void **state)
{
    (void)state;
    double r = honesty_ratio(INTEGRATOR_PHOTON_MAP, (honesty_case){.photons = 100000});
    assert_true(fabs(r - 1.0) <= 0.2);
    /* from a deviation map (re-rendering final-gather's saved map) */
    r = honesty_ratio(INTEGRATOR_PHOTON_MAP,
                      (honesty_case){.photons = 100000, .deviation_map = true});
    assert_true(fabs(r - 1.0) <= 0.2);
}

/* Through a straight cover close over a solid: with the sample's variance the sum of its
 * density estimates' variances, as if their photons were independent, the error was
 * 1.32 x the reported one (the CLI over 16 seeds; 1.25 with a film of R = 0.1); with the
 * sum of their standard errors, the bound of perfect correlation, 0.95. */
static void test_stderr_is_honest_photon_map_cover(void **state)
{
    (void)state;
    double r = honesty_ratio(INTEGRATOR_PHOTON_MAP,
                             (honesty_case){.photons = 100000, .tight_cover = true});
    assert_true(fabs(r - 1.0) <= 0.2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cross_validation),
        cmocka_unit_test(test_stderr_is_honest_path),
        cmocka_unit_test(test_stderr_is_honest_final_gather),
        cmocka_unit_test(test_stderr_is_honest_photon_map),
        cmocka_unit_test(test_stderr_is_honest_photon_map_cover),
        cmocka_unit_test(test_final_gather_one_map),
        cmocka_unit_test(test_strata_honest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
