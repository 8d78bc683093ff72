/* Emission sampling (eq. 5-6): sampled frequencies follow the channel's Gaussian
 * response; source fractions follow eq. 5 (pi eps-bar A B_nu(T) per emitting side) for
 * surfaces at different temperatures, emissivities and sidedness, 0 K emits nothing;
 * the photons' mean power is the band-mean P_A; directions leave the emitting side,
 * cosine-distributed for constant eps and eps(theta) cos(theta) for a Kirchhoff shell.
 * Tolerances: 5 standard errors of the sample count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "photon/emission.h"
#include "physics/planck.h"
#include "photon_scenes.h"

static void check_fraction(uint64_t count, uint64_t n, double p, const char *what)
{
    double f = (double)count / (double)n;
    double se = sqrt(fmax(p * (1 - p), 1.0 / (double)n) / (double)n);
    printf("# %s: %.5f expected %.5f (%.1f se)\n", what, f, p, (f - p) / se);
    assert_true(fabs(f - p) < 5.0 * se);
}

static double planck_at(double freq_hz, void *ctx)
{
    return planck_radiance(freq_hz, *(const double *)ctx);
}

static double band_planck(const thz_channel *ch, double temp_k)
{
    return channel_band_mean(ch, planck_at, &temp_k);
}

static double table_emission_at(double freq_hz, void *ctx)
{
    double r = 0.8 * (freq_hz - 0.3e12) / 0.1e12;
    r = r < 0 ? 0 : (r > 0.8 ? 0.8 : r);
    return (1.0 - r) * planck_radiance(freq_hz, *(const double *)ctx);
}

static double band_table_emission(const thz_channel *ch, double temp_k)
{
    return channel_band_mean(ch, table_emission_at, &temp_k);
}

static void test_frequencies_follow_band(void **state)
{
    (void)state;
    uint64_t n = ps_scaled(400000);
    thz_scene *s = ps_scene(0.5, 0.3, n, 3); /* wide band: sigma = 64 GHz */
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plate = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, plate, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
    ps_finalize(s);
    emission_table t;
    thz_error err;
    assert_int_equal(emission_table_init(&t, s, NULL, 0, n, 0.0, NULL, &err), THZ_OK);
    const thz_channel *ch = &s->channels[0];
    double sigma = channel_sigma_hz(ch);
    enum { BINS = 16 };
    uint64_t hist[BINS + 2] = {0};
    double sum = 0.0, sum2 = 0.0;
    for (uint64_t i = 0; i < n; i++) {
        rng_stream rng;
        rng_init(&rng, 3, 0, RNG_PURPOSE_PHOTON, i);
        emission_photon e;
        assert_true(emission_sample(&t, &rng, &e));
        double z = (e.freq_hz - ch->center_hz) / sigma; /* bins of 0.5 sigma over +-4 */
        int b = z < -4 ? 0 : (z >= 4 ? BINS + 1 : 1 + (int)floor((z + 4) * 2));
        hist[b]++;
        sum += e.power_w_per_hz * (double)n;
        sum2 += (e.power_w_per_hz * (double)n) * (e.power_w_per_hz * (double)n);
        /* The photon's power is P_A at its own frequency over K. */
        double v = M_PI * planck_radiance(e.freq_hz, 300) * 1.0;
        assert_true(fabs(e.power_w_per_hz * (double)n - v) <= 1e-12 * v);
    }
    for (int b = 0; b < BINS + 2; b++) {
        double lo = b == 0 ? -INFINITY : -4 + (b - 1) * 0.5;
        double hi = b == 0 ? -4 : (b == BINS + 1 ? INFINITY : lo + 0.5);
        double p = 0.5 * (erf(hi / sqrt(2.0)) - erf(lo / sqrt(2.0)));
        char what[48];
        snprintf(what, sizeof what, "frequency bin %d", b);
        check_fraction(hist[b], n, p, what);
    }
    /* Mean power: the band mean of P_A = pi A B_nu(T). */
    double mean = sum / (double)n, se = sqrt((sum2 / (double)n - mean * mean) / (double)n);
    double expect = M_PI * band_planck(ch, 300);
    printf("# mean power %.6e expected %.6e (%.1f se)\n", mean, expect, (mean - expect) / se);
    assert_true(fabs(mean - expect) < 5 * se);
    assert_float_equal(scene_band_emitted_power_w_per_hz(s, 0), expect, 1e-9 * expect);
    emission_table_fini(&t);
    scene_destroy(s);
}

static void test_source_fractions(void **state)
{
    (void)state;
    uint64_t n = ps_scaled(400000);
    thz_scene *s = ps_scene(0.35, 0.1, n, 4); /* wide: g's R varies by 0.28 across it */
    size_t grey = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t explicit = ps_material(s, 0.1, 50.0, 0.4, TRANSMISSION_DIFFUSE);
    size_t kirchhoff = ps_material(s, 0.1, 200.0, -1.0, TRANSMISSION_DIFFUSE);
    /* a: one-sided grey solid, 1 m2, 300 K; b: two-sided black, 0.5 m2, 200 K;
     * c: shell with explicit eps 0.4, 0.25 m2, 350 K; d: Kirchhoff shell, 0.3 m2, 280 K;
     * e: 0 K, 2 m2. */
    size_t a = ps_object(s, OBJECT_SOLID, grey, 300, 0, false);
    ps_face(s, a, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
    size_t b = ps_object(s, OBJECT_SOLID, black, 200, 0, true);
    ps_face(s, b, v3(2, 0, 0), v3(0.5, 0, 0), v3(0, 0.25, 0));
    size_t c = ps_object(s, OBJECT_SHELL, explicit, 350, 1e-3, true);
    ps_face(s, c, v3(4, 0, 0), v3(0.25, 0, 0), v3(0, 0.25, 0));
    size_t d = ps_object(s, OBJECT_SHELL, kirchhoff, 280, 1e-3, true);
    ps_face(s, d, v3(6, 0, 0), v3(0, 0.3, 0), v3(0, 0, 0.25));
    size_t e0 = ps_object(s, OBJECT_SOLID, black, 0, 0, true);
    ps_face(s, e0, v3(8, 0, 0), v3(1, 0, 0), v3(0, 0.5, 0));
    /* f: another 300 K constant-optics source (shares a's group), R = 0.5, 0.5 m2;
     * g: a 300 K source whose R varies across the band (a group of its own), 0.2 m2. */
    size_t half = ps_material(s, 0.5, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t f6 = ps_object(s, OBJECT_SOLID, half, 300, 0, false);
    ps_face(s, f6, v3(10, 0, 0), v3(0.5, 0, 0), v3(0, 0.25, 0));
    size_t table = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    const double fr[2] = {0.3e12, 0.4e12}, rv[2] = {0.0, 0.8};
    ps_check(spectrum_set_table(&s->materials[table].reflectivity, 2, fr, rv));
    size_t g7 = ps_object(s, OBJECT_SOLID, table, 300, 0, false);
    ps_face(s, g7, v3(12, 0, 0), v3(0.1, 0, 0), v3(0, 0.5, 0));
    ps_finalize(s);
    const thz_channel *ch = &s->channels[0];
    optics_point od = scene_object_optics(s, &s->objects[d], ch->center_hz);
    double eps_d = optics_mean_emissivity(&od);
    assert_true(eps_d > 0.05 && eps_d < 0.9 - 0.05);
    /* g's emissivity 1 - R(nu) is linear across the band: 1 - 8 (nu - 0.3 THz) / THz
     * at 0.35 THz is 0.6; the band mean of (1 - R) B is computed by quadrature. */
    double w[7] = {
        M_PI * 0.7 * 1.0 * 1 * band_planck(ch, 300),
        M_PI * 1.0 * 0.5 * 2 * band_planck(ch, 200),
        M_PI * 0.4 * 0.25 * 2 * band_planck(ch, 350),
        M_PI * eps_d * 0.3 * 2 * band_planck(ch, 280),
        0.0,
        M_PI * 0.5 * 0.5 * 1 * band_planck(ch, 300),
        M_PI * 1.0 * 0.2 * 1 * band_table_emission(ch, 300),
    };
    double total = w[0] + w[1] + w[2] + w[3] + w[5] + w[6];
    assert_float_equal(scene_band_emitted_power_w_per_hz(s, 0), total, 1e-6 * total);

    emission_table t;
    thz_error err;
    assert_int_equal(emission_table_init(&t, s, NULL, 0, n, 0.0, NULL, &err), THZ_OK);
    assert_int_equal(t.n_sources, 6);
    assert_int_equal(t.n_groups, 5);
    uint64_t count[7] = {0}, side1[7] = {0};
    double power[7] = {0}, fired = 0.0;
    double *phi = malloc(n * sizeof *phi);
    uint32_t *src = malloc(n * sizeof *src);
    for (uint64_t i = 0; i < n; i++) {
        rng_stream rng;
        rng_init(&rng, 4, 0, RNG_PURPOSE_PHOTON, i);
        emission_photon e;
        assert_true(emission_sample(&t, &rng, &e));
        count[e.object]++;
        side1[e.object] += (uint64_t)e.side;
        power[e.object] += e.power_w_per_hz;
        fired += e.power_w_per_hz;
        phi[i] = e.power_w_per_hz;
        src[i] = e.object;
        const thz_mesh *m = &s->objects[e.object].mesh;
        const float *nf = &m->normals[3 * (size_t)e.triangle];
        double cn = v3_dot(e.dir, v3(nf[0], nf[1], nf[2]));
        assert_true(e.side == 0 ? cn > 0.0 : cn < 0.0); /* leaves its emitting side */
        for (int k = 0; k < 3; k++) {
            double x = k == 0 ? e.position_m.x : (k == 1 ? e.position_m.y : e.position_m.z);
            assert_true(x >= m->bbox_min_m[k] - 1e-9 && x <= m->bbox_max_m[k] + 1e-9);
        }
    }
    const char *names[7] = {
        "one-sided grey",     "two-sided black", "explicit shell", "Kirchhoff shell", "0 K",
        "same group as grey", "R(nu) table"};
    /* Eq. 5 in the band mean: each source's share of the power fired is its share of
     * P-bar_A. Standard error of the ratio estimator: sqrt(sum Phi^2 (I - f)^2) / sum Phi. */
    for (uint32_t k = 0; k < 7; k++) {
        double f = power[k] / fired, v = 0.0;
        for (uint64_t i = 0; i < n; i++) {
            double dev = (src[i] == k ? 1.0 : 0.0) - f;
            v += phi[i] * phi[i] * dev * dev;
        }
        double se = fmax(sqrt(v) / fired, 1.0 / (double)n), p = w[k] / total;
        printf("# %s: power share %.5f expected %.5f (%.1f se)\n", names[k], f, p, (f - p) / se);
        assert_true(fabs(f - p) < 5.0 * se);
    }
    assert_int_equal(count[e0], 0);
    free(phi);
    free(src);
    assert_int_equal(side1[a], 0);
    check_fraction(side1[b], count[b], 0.5, "two-sided: back side");
    check_fraction(side1[c], count[c], 0.5, "shell: back side");
    emission_table_fini(&t);
    scene_destroy(s);
}

/* 2 int_lo^hi X(mu) mu dmu by composite Simpson, X = eps(mu) or 1. */
static double eps_mass(const optics_point *o, double lo, double hi)
{
    const int n = 2000;
    double h = (hi - lo) / n, s = 0.0;
    for (int i = 0; i <= n; i++) {
        double mu = lo + i * h;
        double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        s += w * (o ? optics_emissivity(o, mu) : 1.0) * mu;
    }
    return 2.0 * s * h / 3.0;
}

/* Directions: eps(theta) cos(theta) for a Kirchhoff shell (tau = 0.05, cap 0.9: T
 * reaches the cap at mu* = 0.47, above which eps = 0), cosine for a solid. */
static void test_direction_distribution(void **state)
{
    (void)state;
    for (int kind = 0; kind < 2; kind++) {
        uint64_t n = ps_scaled(300000);
        thz_scene *s = ps_scene(0.35, 0.01, n, 6);
        size_t m = kind ? ps_material(s, 0.1, 50.0, -1.0, TRANSMISSION_DIFFUSE)
                        : ps_material(s, 0.25, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t obj = ps_object(s, kind ? OBJECT_SHELL : OBJECT_SOLID, m, 300, 1e-3, false);
        ps_face(s, obj, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
        ps_finalize(s);
        optics_point o = scene_object_optics(s, &s->objects[obj], s->channels[0].center_hz);
        emission_table t;
        thz_error err;
        assert_int_equal(emission_table_init(&t, s, NULL, 0, n, 0.0, NULL, &err), THZ_OK);
        enum { BINS = 20 };
        uint64_t hist[BINS] = {0};
        for (uint64_t i = 0; i < n; i++) {
            rng_stream rng;
            rng_init(&rng, 6, 0, RNG_PURPOSE_PHOTON, i);
            emission_photon e;
            assert_true(emission_sample(&t, &rng, &e));
            double mu = fabs(e.dir.z);
            int b = (int)(mu * BINS);
            hist[b < BINS ? b : BINS - 1]++;
        }
        double total = eps_mass(kind ? &o : NULL, 0, 1);
        for (int b = 0; b < BINS; b++) {
            double p = eps_mass(kind ? &o : NULL, (double)b / BINS, (double)(b + 1) / BINS) / total;
            char what[48];
            snprintf(what, sizeof what, "%s mu bin %d", kind ? "shell" : "solid", b);
            check_fraction(hist[b], n, p, what);
        }
        emission_table_fini(&t);
        scene_destroy(s);
    }
}

/* The group is drawn from a tabulation q_g on a grid over the band and the photon
 * carries w_g Q / (q_g K), w_g exact: a reflectivity line lying wholly between two grid
 * nodes, which the tabulation cannot see, must still get exactly its share of the
 * power (eq. 5 in the band mean). Object a: a solid whose R(nu) is 0 but 1 on a
 * plateau filling most of the gap between two nodes near the centre (no emission
 * there); b: a black solid at the same temperature (a group of its own, constant
 * optics). Without the exact w_g, a's share would be 0.5 instead of 0.494 (~6 se). */
static void test_line_between_nodes(void **state)
{
    (void)state;
    uint64_t n = ps_scaled(400000);
    thz_scene *s = ps_scene(0.35, 0.1, n, 7);
    size_t lined = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t a = ps_object(s, OBJECT_SOLID, lined, 300, 0, false);
    ps_face(s, a, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
    size_t b = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, b, v3(2, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
    const thz_channel *ch = &s->channels[0];
    double sigma = channel_sigma_hz(ch);
    double step = 2.0 * EMISSION_TABLE_SIGMAS * sigma / (EMISSION_TABLE_NODES - 1);
    double c = ch->center_hz; /* a node: the grid is symmetric about the centre */
    const double fr[4] = {c + 0.05 * step, c + 0.06 * step, c + 0.94 * step, c + 0.95 * step};
    const double rv[4] = {0.0, 1.0, 1.0, 0.0};
    ps_check(spectrum_set_table(&s->materials[lined].reflectivity, 4, fr, rv));
    ps_finalize(s);

    /* Expected share of a: band means by a fine Simpson rule over +-8.5 sigma. */
    const int m = 400000;
    double lo = c - 8.5 * sigma, h = 17.0 * sigma / m, wa = 0.0, wb = 0.0;
    for (int i = 0; i <= m; i++) {
        double nu = lo + i * h, g = exp(-0.5 * ((nu - c) / sigma) * ((nu - c) / sigma));
        double k = (i == 0 || i == m) ? 1 : (i % 2 ? 4 : 2);
        double bb = k * g * planck_radiance(nu, 300);
        wa += bb * (1.0 - spectrum_eval(&s->materials[lined].reflectivity, nu));
        wb += bb;
    }
    double p = wa / (wa + wb);
    assert_true(1.0 - wa / wb > 0.01); /* the line takes more than 1 % of a's power */

    emission_table t;
    thz_error err;
    assert_int_equal(emission_table_init(&t, s, NULL, 0, n, 0.0, NULL, &err), THZ_OK);
    assert_int_equal(t.n_groups, 2);
    double pa = 0.0, fired = 0.0;
    uint64_t zero = 0;
    for (uint64_t i = 0; i < n; i++) {
        rng_stream rng;
        rng_init(&rng, 7, 0, RNG_PURPOSE_PHOTON, i);
        emission_photon e;
        if (!emission_sample(&t, &rng, &e)) {
            zero++;
            continue;
        }
        fired += e.power_w_per_hz;
        if (e.object == a)
            pa += e.power_w_per_hz;
    }
    double f = pa / fired;
    double se = sqrt(p * (1.0 - p) / (double)n) * 1.2; /* spread of powers: a few % */
    printf("# line between nodes: a's power share %.5f expected %.5f (%.1f se), %llu photons of "
           "power 0\n",
           f, p, (f - p) / se, (unsigned long long)zero);
    assert_true(fabs(f - p) < 5.0 * se);
    assert_true(zero > 0); /* photons drawn from a inside the line carry nothing */
    emission_table_fini(&t);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frequencies_follow_band),
        cmocka_unit_test(test_source_fractions),
        cmocka_unit_test(test_direction_distribution),
        cmocka_unit_test(test_line_between_nodes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
