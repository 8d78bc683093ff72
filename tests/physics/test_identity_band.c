/* Identity 6 (physics.md): a material whose reflectivity has a line narrower than the
 * band gives the response-weighted band mean, not the value at the centre. Two setups
 * with a grey plate whose R(nu) has a triangular line (half-width sigma/5, peak 0.9 on a
 * base of 0.1, 0.3 sigma above the centre, so R(nu_c) = 0.1 while the band mean of R is
 * ~0.16):
 *   emission:   plate at 300 K in a black enclosure at 0 K: L = <(1 - R) B(300 K)>,
 *               deterministic (the channel quadrature);
 *   reflection: plate at 0 K in a black enclosure at 300 K: L = <R B(300 K)>, from the
 *               photons' own frequencies (Monte Carlo).
 *   air:        the line in a tabled atmosphere's attenuation (below).
 * <.> is an independent band mean (trapezoid over +-8 sigma). Every integrator; `path`
 * samples the frequency, so its emission pixels are checked within 5 standard errors. */
#include <unistd.h>

#include "identity.h"

#define BAND_NU_C 0.5e12
#define BAND_W 0.05

typedef struct band_line {
    double f[5], r[5]; /* the table, Hz */
    double temp_k;
} band_line;

static double band_sigma(void)
{
    return BAND_W * BAND_NU_C / (2.0 * sqrt(2.0 * log(2.0)));
}

static void band_line_init(band_line *l)
{
    double s = band_sigma(), nu_l = BAND_NU_C + 0.3 * s, hw = s / 5.0;
    double f[5] = {0.3e12, nu_l - hw, nu_l, nu_l + hw, 0.7e12};
    double r[5] = {0.1, 0.1, 0.9, 0.1, 0.1};
    memcpy(l->f, f, sizeof f);
    memcpy(l->r, r, sizeof r);
}

static double band_r(const band_line *l, double nu)
{
    if (nu <= l->f[0])
        return l->r[0];
    for (int i = 1; i < 5; i++)
        if (nu <= l->f[i])
            return l->r[i - 1] +
                   (l->r[i] - l->r[i - 1]) * (nu - l->f[i - 1]) / (l->f[i] - l->f[i - 1]);
    return l->r[4];
}

static double band_emitted(double nu, void *ctx)
{
    const band_line *l = ctx;
    return (1.0 - band_r(l, nu)) * planck_radiance(nu, l->temp_k);
}

static double band_reflected(double nu, void *ctx)
{
    const band_line *l = ctx;
    return band_r(l, nu) * planck_radiance(nu, l->temp_k);
}

typedef struct band_air {
    const band_line *line; /* its r[] read as the table's shape; alpha from band_alpha */
    double distance_m, temp_k;
} band_air;

/* The line as attenuation: 0.05 /m with a peak of 1 /m (r 0.1 -> 0.05, 0.9 -> 1). */
static double band_alpha(const band_line *l, double nu)
{
    return 0.05 + (band_r(l, nu) - 0.1) * (0.95 / 0.8);
}

static double band_through_air(double nu, void *ctx)
{
    const band_air *a = ctx;
    return planck_radiance(nu, a->temp_k) * exp(-band_alpha(a->line, nu) * a->distance_m);
}

static void band_scene(char *json, size_t size, const band_line *l, double t_plate, double t_room)
{
    snprintf(
        json, size,
        "{\"format\": \"thzmap-scene/1\", \"name\": \"band-line\","
        " \"channels\": [{\"frequency_thz\": %.12g, \"relative_width\": %g}],"
        " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
        "   \"lined\": {\"reflectivity\": [[%.12g, %g], [%.12g, %g], [%.12g, %g],"
        "                                 [%.12g, %g], [%.12g, %g]]}},"
        " \"objects\": ["
        "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
        "    \"temperature_k\": %g,"
        "    \"shape\": {\"type\": \"box\", \"size_m\": [1.2, 0.6, 1.2], \"inward\": true}},"
        "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"lined\","
        "    \"temperature_k\": %g, \"shape\": {\"type\": \"box\", \"size_m\": [1.0, 0.1, 1.0]}}],"
        " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.28, 0],"
        "   \"direction\": [0, 1, 0], \"fov_deg\": 100, \"resolution\": [8, 8]}],"
        " \"photons\": {\"per_channel\": 300000, \"seed\": 11}}",
        BAND_NU_C / 1e12, BAND_W, l->f[0] / 1e12, l->r[0], l->f[1] / 1e12, l->r[1], l->f[2] / 1e12,
        l->r[2], l->f[3] / 1e12, l->r[3], l->f[4] / 1e12, l->r[4], t_room, t_plate);
}

static void band_emission_case(thz_integrator integrator)
{
    band_line l;
    band_line_init(&l);
    l.temp_k = 300.0;
    char json[4096];
    band_scene(json, sizeof json, &l, 300.0, 0.0);
    ident_run r;
    ident_run_scene_with(&r, json, ident_photons(20000), integrator, ident_estimates(32));
    bool sampled = integrator == INTEGRATOR_PATH;
    const thz_channel *ch = &r.scene->channels[0];
    double expect = ident_band_mean(ch, band_emitted, &l);
    double at_centre = (1.0 - band_r(&l, BAND_NU_C)) * ident_band_planck(ch, 300.0);
    assert_true(fabs(expect / at_centre - 1.0) > 0.05); /* the line matters */
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            size_t i = ident_at(&r, 0, col, row);
            double v = r.img.radiance[i], se = r.img.radiance_stderr[i];
            /* the line's kinks are nodes of the quadrature: float storage only (a kink
             * between two nodes cost ~1e-4) */
            double tol = 1e-6 * expect + (sampled ? IDENT_Z * se : 0.0);
            if (!(fabs(v - expect) <= tol))
                print_message("%s pixel (%u, %u): L = %.8e, expected %.8e (centre value %.8e)\n",
                              render_integrator_name(integrator), col, row, v, expect, at_centre);
            assert_true(fabs(v - expect) <= tol);
            /* the tolerance stays far below the line's effect */
            assert_true(tol < 0.2 * fabs(expect - at_centre));
        }
    ident_run_fini(&r);
}

static void test_band_emission(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        band_emission_case(ident_integrators[k]);
}

static void band_reflection_case(thz_integrator integrator, double t0_k)
{
    band_line l;
    band_line_init(&l);
    l.temp_k = 300.0;
    char json[4096];
    band_scene(json, sizeof json, &l, 0.0, 300.0);
    ident_run r;
    /* R B is heavy-tailed in frequency: 128 gather rays or paths keep a pixel's standard
     * error below the bound */
    ident_run_scene_t0(&r, json, ident_photons(300000), integrator, ident_estimates(128), t0_k);
    const thz_channel *ch = &r.scene->channels[0];
    double expect = ident_band_mean(ch, band_reflected, &l);
    double at_centre = band_r(&l, BAND_NU_C) * ident_band_planck(ch, 300.0);
    /* R B is heavy-tailed (the line is 9x the base over a small part of the band): a
     * pixel's tolerance uses at least the image's pooled standard error */
    ident_tally t = {.pooled_rel_se = ident_pooled_rel_se_of(&r, 0, expect)};
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            assert_true(ident_pixel_interior(&r, col, row));
            /* floor: the channel quadrature across the line's kinks (path's reflected part
             * is its band mean, deterministic here) */
            ident_check_pixel(&t, &r, 0, col, row, expect, 2e-4);
        }
    char label[64], what[128];
    ident_label(label, sizeof label, integrator, t0_k);
    snprintf(what, sizeof what, "reflection with a line, %s", label);
    ident_tally_assert(&t, what, 0.2 / sqrt(ident_scale()), 2e-4);
    /* the centre value is excluded by many standard errors of the mean */
    double se_mean = t.pooled_rel_se / sqrt((double)t.pixels);
    print_message("band mean %.6e vs centre value %.6e W m^-2 sr^-1 Hz^-1 (%.1f se apart)\n",
                  expect, at_centre, fabs(expect / at_centre - 1.0) / se_mean);
    assert_true(fabs(expect / at_centre - 1.0) > 10.0 * se_mean);
    ident_run_fini(&r);
}

static void test_band_reflection(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        for (size_t v = 0; v < IDENT_N_T0; v++)
            if (ident_t0_applies(ident_integrators[k], v))
                band_reflection_case(ident_integrators[k], ident_t0s[v]);
}

/* The same line in the air: a black wall at 310 K seen down a corridor through a tabled
 * atmosphere (not emitting) whose attenuation has the triangular line (0.05 /m, 1 /m at
 * its peak): L = <B(310 K) exp(-alpha(nu) d)>, deterministic for photon-map and
 * final-gather (Identity 4 with a line; the kinks are nodes of the quadrature, which
 * integrated them to ~1e-3 when they fell between nodes). */
static void band_atmosphere_case(thz_integrator integrator)
{
    band_line l;
    band_line_init(&l);
    char csv[] = "/tmp/thz_band_air_XXXXXX";
    int fd = mkstemp(csv);
    assert_true(fd >= 0);
    FILE *fp = fdopen(fd, "w");
    assert_non_null(fp);
    fprintf(fp, "frequency_thz,attenuation_per_m\n");
    for (int i = 0; i < 5; i++)
        fprintf(fp, "%.17g,%.17g\n", l.f[i] / 1e12, band_alpha(&l, l.f[i]));
    assert_int_equal(fclose(fp), 0);
    char json[4096];
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\", \"name\": \"band-air\","
             " \"channels\": [{\"frequency_thz\": %.12g, \"relative_width\": %g}],"
             " \"materials\": {\"black\": {\"reflectivity\": 0.0}},"
             " \"atmosphere\": {\"model\": \"table\", \"emitting\": false,"
             "   \"file\": \"%s\"},"
             " \"objects\": ["
             "   {\"name\": \"corridor\", \"type\": \"solid\", \"material\": \"black\","
             "    \"temperature_k\": 310,"
             "    \"shape\": {\"type\": \"box\", \"size_m\": [1, 10, 1], \"inward\": true}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -4.9, 0],"
             "   \"direction\": [0, 1, 0], \"fov_deg\": 4, \"resolution\": [8, 6]}],"
             " \"photons\": {\"per_channel\": 2000, \"seed\": 1}}",
             BAND_NU_C / 1e12, BAND_W, csv);
    ident_run r;
    ident_run_scene_with(&r, json, 0, integrator, ident_estimates(32));
    unlink(csv);
    bool sampled = integrator == INTEGRATOR_PATH;
    const thz_channel *ch = &r.scene->channels[0];
    double worst = 0.0;
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            vec3 dir = camera_pixel_center_dir(&r.cam, col, row);
            band_air a = {.line = &l, .distance_m = (5.0 + 4.9) / dir.y, .temp_k = 310.0};
            double expect = ident_band_mean(ch, band_through_air, &a);
            double flat = ident_band_planck(ch, 310.0) * exp(-0.05 * a.distance_m);
            assert_true(expect < 0.9 * flat); /* the line matters */
            size_t i = ident_at(&r, 0, col, row);
            double v = r.img.radiance[i], se = r.img.radiance_stderr[i];
            double tol = 1e-6 * expect + (sampled ? IDENT_Z * se : 0.0);
            if (!(fabs(v - expect) <= tol))
                print_message("%s pixel (%u, %u): L = %.8e, expected %.8e\n",
                              render_integrator_name(integrator), col, row, v, expect);
            assert_true(fabs(v - expect) <= tol);
            /* path's standard error (its band noise of B0) stays small, so its tolerance
             * cannot hide the line: 5 of them are below a tenth of the line's effect */
            assert_true(sampled ? IDENT_Z * se < 0.1 * (flat - expect) : se == 0.0);
            worst = fmax(worst, fabs(v / expect - 1.0));
        }
    print_message("%s: the line in the air, largest |L / expected - 1| %.2e\n",
                  render_integrator_name(integrator), worst);
    ident_run_fini(&r);
}

static void test_band_atmosphere(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        band_atmosphere_case(ident_integrators[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_band_emission),
        cmocka_unit_test(test_band_reflection),
        cmocka_unit_test(test_band_atmosphere),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
