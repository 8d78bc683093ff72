/* Identity 3 (physics.md): a shell (R, alpha_M, t, temperature T_s) in front of a black
 * background, all else black at T_b, shows
 *   L = (1 - R - T(theta)) B(T_s) + (R + T(theta)) B(T_b),  T = min(exp(-alpha t/mu), 1-R)
 * for both transmission modes: `straight` sees the background through T(theta);
 * `diffuse` transmits T(theta_o) B(T_b) by reciprocity, the incident radiance being
 * uniform. At normal incidence this is the spec's T_0 form; each pixel is compared at
 * its own angle (one sample per pixel, through the pixel centre). For every integrator.
 * A third case gives the diffuse shell R = 0.05, a reflected part light enough to be
 * traced by roulette (path's first-hit branches, final-gather's split gather rays), and
 * a fourth a dense cold shell whose transmitted part is (T(theta) <= 0.05).
 * Two more put the cap's kink mu* = alpha t / -ln(1 - R) = 0.7 inside the view: pixels
 * nearer the normal see T = 1 - R, where the shell absorbs and emits nothing, and the
 * shell's mean emissivity and its diffuse transmission's directions come from both
 * pieces of T(mu) (optics.c). Without the cap those pixels would read 3.6 % low. */
#include "identity.h"

#define SHELL_ALPHA 200.0
#define SHELL_ALPHA_KINK 78.1    /* alpha t = 0.156, mu* = 0.7 at R = 0.2 */
#define SHELL_ALPHA_DENSE 1500.0 /* alpha t = 3: T(theta) <= 0.05 */
#define SHELL_T_M 0.002
#define SHELL_TS 400.0
#define SHELL_TB 250.0

static void shell_case_with(const char *mode, uint64_t seed, double refl, double alpha, double ts,
                            thz_integrator integrator, double t0_k)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\", \"name\": \"shell-%s\","
             " \"channels\": [{\"frequency_thz\": 0.6, \"relative_width\": 0.05}],"
             " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
             "   \"cloth\": {\"reflectivity\": %g, \"attenuation_per_m\": %g,"
             "             \"transmission\": \"%s\"}},"
             " \"objects\": ["
             "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
             "    \"temperature_k\": %g,"
             "    \"shape\": {\"type\": \"box\", \"size_m\": [1.2, 1.2, 1.2], \"inward\": true}},"
             "   {\"name\": \"cover\", \"type\": \"shell\", \"thickness_m\": %g,"
             "    \"material\": \"cloth\", \"temperature_k\": %g,"
             "    \"shape\": {\"type\": \"rectangle\", \"size_m\": [1.0, 1.0]},"
             "    \"transform\": {\"rotate_deg\": [90, 0, 0]}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.3, 0],"
             "   \"direction\": [0, 1, 0], \"fov_deg\": 100, \"resolution\": [12, 12]}],"
             " \"photons\": {\"per_channel\": 300000, \"seed\": %llu}}",
             mode, refl, alpha, mode, SHELL_TB, SHELL_T_M, ts, (unsigned long long)seed);
    /* The diffuse shell at the kink is the noisiest photon-map case (its pixels' standard
     * errors up to 8.6 % at 300 000 photons, over the bound of 8 %). */
    double photons = alpha == SHELL_ALPHA ? 300000 : 450000;
    ident_run r;
    ident_run_scene_t0(&r, json, ident_photons(photons), integrator, ident_estimates(32), t0_k);
    const thz_channel *ch = &r.scene->channels[0];
    double bs = ident_band_planck(ch, ts), bb = ident_band_planck(ch, SHELL_TB);
    double t_min = 1.0, t_max = 0.0, expects[144];
    size_t capped = 0;
    assert_true((size_t)r.img.rows * r.img.columns <= 144);
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            double mu = fabs(camera_pixel_center_dir(&r.cam, col, row).y); /* normal is -y */
            double tr = fmin(exp(-alpha * SHELL_T_M / mu), 1.0 - refl);
            capped += tr == 1.0 - refl;
            t_min = fmin(t_min, tr);
            t_max = fmax(t_max, tr);
            expects[row * r.img.columns + col] = (1.0 - refl - tr) * bs + (refl + tr) * bb;
        }
    ident_tally t = {.pooled_rel_se = ident_pooled_rel_se(&r, 0, expects)};
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            assert_int_equal(r.img.object_id[row * r.img.columns + col], 1);
            /* no edge of the cover within a disk (the black background needs none) */
            assert_true(strcmp(mode, "straight") == 0 || ident_pixel_interior(&r, col, row));
            ident_check_pixel(&t, &r, 0, col, row, expects[row * r.img.columns + col], 1e-5);
        }
    size_t pixels = (size_t)r.img.rows * r.img.columns;
    if (alpha == SHELL_ALPHA)
        assert_true(t_max - t_min > 0.1); /* the view spans a real range of T(theta) */
    else if (alpha == SHELL_ALPHA_DENSE)
        assert_true(t_max < 0.15 && t_max > 0.04); /* every T(theta) light, the largest not 0 */
    else
        assert_true(capped >= pixels / 4 && pixels - capped >= pixels / 4); /* both pieces */
    char label[64], what[128];
    ident_label(label, sizeof label, integrator, t0_k);
    snprintf(what, sizeof what, "%s shell, R = %g, alpha t = %g, %s", mode, refl, alpha * SHELL_T_M,
             label);
    ident_tally_assert(&t, what, 0.08 / sqrt(ident_scale()), 1e-5);
    ident_run_fini(&r);
}

static void shell_case_ts(const char *mode, uint64_t seed, double refl, double alpha, double ts)
{
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        for (size_t v = 0; v < IDENT_N_T0; v++)
            if (ident_t0_applies(ident_integrators[k], v))
                shell_case_with(mode, seed, refl, alpha, ts, ident_integrators[k], ident_t0s[v]);
}

static void shell_case(const char *mode, uint64_t seed, double refl, double alpha)
{
    shell_case_ts(mode, seed, refl, alpha, SHELL_TS);
}

static void test_shell_straight(void **state)
{
    (void)state;
    shell_case("straight", 7, 0.2, SHELL_ALPHA);
}

static void test_shell_diffuse(void **state)
{
    (void)state;
    shell_case("diffuse", 8, 0.2, SHELL_ALPHA);
}

static void test_shell_diffuse_light_reflection(void **state)
{
    (void)state;
    shell_case("diffuse", 9, 0.05, SHELL_ALPHA);
}

static void test_shell_straight_cap(void **state)
{
    (void)state;
    shell_case("straight", 10, 0.2, SHELL_ALPHA_KINK);
}

static void test_shell_diffuse_cap(void **state)
{
    (void)state;
    shell_case("diffuse", 11, 0.2, SHELL_ALPHA_KINK);
}

/* A dense shell, T(theta) <= 0.05 over the view: final-gather's transmitted part of a split
 * gather ray is traced by roulette everywhere (q = T / 0.15). The shell is cold (50 K), so
 * that what it transmits from the 250 K room is a large part of what the pixels see (at
 * normal incidence 14 %); from a map of L (T0 = 0 K) that part is not zero. */
static void test_shell_diffuse_light_transmission(void **state)
{
    (void)state;
    shell_case_ts("diffuse", 12, 0.2, SHELL_ALPHA_DENSE, 50.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shell_straight),
        cmocka_unit_test(test_shell_diffuse),
        cmocka_unit_test(test_shell_diffuse_light_reflection),
        cmocka_unit_test(test_shell_straight_cap),
        cmocka_unit_test(test_shell_diffuse_cap),
        cmocka_unit_test(test_shell_diffuse_light_transmission),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
