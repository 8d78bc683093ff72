/* Russian roulette at a hit (eq. 8-10): the fractions reflected, transmitted and
 * absorbed equal R, T(theta) and A(theta); the diffuse BTDF's exit directions follow
 * T(theta_o) cos(theta_o) (histogram); and in a traced scene a photon crossing a
 * straight shell keeps its direction and power; reflection is Lambertian on the side of
 * incidence; the back of a one-sided solid absorbs. Tolerances: 5 binomial standard errors
 * of the sample count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/trace.h"
#include "photon_scenes.h"

static void check_fraction(uint64_t count, uint64_t n, double p, const char *what)
{
    double f = (double)count / (double)n;
    double se = sqrt(fmax(p * (1 - p), 1.0 / (double)n) / (double)n);
    printf("# %s: %.5f expected %.5f (%.1f se)\n", what, f, p, (f - p) / se);
    assert_true(fabs(f - p) < 5.0 * se);
}

static void roulette_case(const optics_point *o, double mu, uint64_t seed)
{
    uint64_t n = ps_scaled(1000000), c[3] = {0};
    rng_stream rng;
    rng_init(&rng, seed, 0, RNG_PURPOSE_TEST, 0);
    for (uint64_t i = 0; i < n; i++)
        c[trace_roulette(o, mu, rng_uniform(&rng))]++;
    double t = optics_transmission(o, mu);
    check_fraction(c[TRACE_REFLECT], n, o->reflectivity, "reflected");
    check_fraction(c[TRACE_TRANSMIT], n, t, "transmitted");
    check_fraction(c[TRACE_ABSORB], n, optics_absorption(o, mu), "absorbed");
    assert_float_equal(o->reflectivity + t + optics_absorption(o, mu), 1.0, 1e-12);
}

static void test_fractions(void **state)
{
    (void)state;
    /* Shell, tau = 0.3, at 53 deg: T = exp(-0.5) = 0.607 below the cap 0.8. */
    optics_point shell = {.reflectivity = 0.2, .attenuation_per_m = 300, .thickness_m = 1e-3};
    roulette_case(&shell, 0.6, 1);
    assert_float_equal(optics_transmission(&shell, 0.6), exp(-0.5), 1e-12);
    /* Grazing: T = exp(-3) = 0.05. */
    roulette_case(&shell, 0.1, 2);
    /* Capped: tau = 0.05 at normal incidence, T = 1 - R = 0.8, A = 0. */
    optics_point thin = {.reflectivity = 0.2, .attenuation_per_m = 50, .thickness_m = 1e-3};
    roulette_case(&thin, 1.0, 3);
    assert_float_equal(optics_transmission(&thin, 1.0), 0.8, 1e-12);
    /* Solid: never transmits. */
    optics_point solid = {.reflectivity = 0.35};
    roulette_case(&solid, 0.5, 4);
}

/* 2 int_lo^hi T(mu) mu dmu by composite Simpson (fine enough for the kink). */
static double t_mass(const optics_point *o, double lo, double hi)
{
    const int n = 2000;
    double h = (hi - lo) / n, s = 0.0;
    for (int i = 0; i <= n; i++) {
        double mu = lo + i * h;
        double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        s += w * optics_transmission(o, mu) * mu;
    }
    return 2.0 * s * h / 3.0;
}

static void test_diffuse_exit_distribution(void **state)
{
    (void)state;
    /* tau = 0.1, cap 0.8: the kink mu* = 0.1 / -ln 0.8 = 0.45 lies inside the range. */
    optics_point o = {.reflectivity = 0.2, .attenuation_per_m = 100, .thickness_m = 1e-3};
    enum { BINS = 20 };
    uint64_t n = ps_scaled(400000), hist[BINS] = {0};
    double sx = 0, sy = 0;
    rng_stream rng;
    vec3 n_out = v3_normalize(v3(0.3, -0.2, 0.9));
    for (uint64_t i = 0; i < n; i++) {
        rng_init(&rng, 9, 0, RNG_PURPOSE_TEST, i);
        vec3 d = trace_diffuse_transmission_dir(&o, n_out, &rng);
        assert_float_equal(v3_length(d), 1.0, 1e-9);
        double mu = v3_dot(d, n_out);
        assert_true(mu > 0.0);
        int b = (int)(mu * BINS);
        hist[b < BINS ? b : BINS - 1]++;
        vec3 t, bb;
        v3_basis(n_out, &t, &bb);
        sx += v3_dot(d, t);
        sy += v3_dot(d, bb);
    }
    double total = t_mass(&o, 0, 1);
    assert_float_equal(total, optics_mean_transmission(&o), 1e-6);
    for (int b = 0; b < BINS; b++) {
        double p = t_mass(&o, (double)b / BINS, (double)(b + 1) / BINS) / total;
        char what[32];
        snprintf(what, sizeof what, "exit bin %d", b);
        check_fraction(hist[b], n, p, what);
    }
    /* Uniform azimuth: the tangential components average to 0 (each has variance < 1). */
    assert_true(fabs(sx / (double)n) < 5.0 / sqrt((double)n));
    assert_true(fabs(sy / (double)n) < 5.0 / sqrt((double)n));
}

/* A photon crossing a straight shell keeps its direction and power; a diffuse shell
 * sends it out of the other side. Traced in a scene: a shell plate above a black floor. */
static void test_transmission_in_scene(void **state)
{
    (void)state;
    for (int mode = 0; mode < 2; mode++) {
        thz_scene *s = ps_scene(0.35, 0.01, 1000, 5);
        size_t cloth =
            ps_material(s, 0.0, 300.0, -1.0, mode ? TRANSMISSION_STRAIGHT : TRANSMISSION_DIFFUSE);
        size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t shell = ps_object(s, OBJECT_SHELL, cloth, 0, 1e-3, true);
        ps_face(s, shell, v3(0, 0, 1), v3(50, 0, 0), v3(0, 50, 0));
        size_t floor = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
        ps_face(s, floor, v3(0, 0, 0), v3(50, 0, 0), v3(0, 50, 0));
        ps_finalize(s);
        accel *acc;
        thz_error err;
        assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
        const double mu = 0.8;
        vec3 dir = v3(-sqrt(1 - mu * mu), 0, -mu);
        uint64_t n = ps_scaled(100000), through = 0;
        trace_buffer buf = {0};
        trace_counters c = {0};
        for (uint64_t i = 0; i < n; i++) {
            /* Starts in free space at z = 2; the "source" triangle (for the offset and
             * the filter of the first ray) is a floor triangle, 2 m away. */
            emission_photon e = {.freq_hz = 0.35e12,
                                 .power_w_per_hz = 1.0,
                                 .position_m = v3(0, 0, 2),
                                 .dir = dir,
                                 .object = (uint32_t)floor,
                                 .triangle = 0};
            rng_stream rng;
            rng_init(&rng, 5, 0, RNG_PURPOSE_TEST, i);
            buf.count = 0;
            assert_true(trace_photon(s, acc, NULL, &e, &rng, &buf, &c));
            assert_true(buf.count >= 1);
            const photon_record *r = buf.records;
            assert_int_equal(photon_object(&r[0]), shell);
            assert_int_equal(photon_side(&r[0]), 0); /* front: the normal points up, at it */
            if (buf.count == 2) {
                through++;
                assert_int_equal(photon_object(&r[1]), floor);
                assert_false(photon_first_hit(&r[1]));
                assert_true(photon_first_hit(&r[0]));
                assert_true(r[1].power_w_per_hz == 1.0f);
                vec3 d = photon_decode_direction(r[1].dir_oct);
                assert_true(d.z < 0.0);
                if (mode)
                    assert_true(v3_dot(d, dir) > 1.0 - 1e-6);
            }
        }
        optics_point o = scene_object_optics(s, &s->objects[shell], 0.35e12);
        check_fraction(through, n, optics_transmission(&o, mu), mode ? "straight" : "diffuse");
        trace_buffer_fini(&buf);
        accel_destroy(acc);
        scene_destroy(s);
    }
}

/* Reflection is Lambertian on the side of incidence: a photon arriving on either side of
 * a two-sided mirror-white (R = 1) plate leaves into that side's hemisphere with
 * mu ~ 2 mu (histogram of the direction recorded at the next hit, on a black plane).
 * On the back of a one-sided solid it is absorbed however high R is, and recorded. */
static void test_reflection_and_back_faces(void **state)
{
    (void)state;
    for (int from_below = 0; from_below < 2; from_below++) {
        thz_scene *s = ps_scene(0.35, 0.01, 1000, 6);
        size_t white = ps_material(s, 1.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t plate = ps_object(s, OBJECT_SOLID, white, 0, 0, true);
        ps_face(s, plate, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)); /* normal +z */
        double zc = from_below ? -1.0 : 1.0;
        size_t cover = ps_object(s, OBJECT_SOLID, black, 0, 0, true);
        ps_face(s, cover, v3(0, 0, zc), v3(1000, 0, 0), v3(0, 1000, 0));
        size_t one_sided = ps_object(s, OBJECT_SOLID, white, 0, 0, false);
        ps_face(s, one_sided, v3(50, 0, 0), v3(1, 0, 0), v3(0, 1, 0)); /* normal +z */
        ps_finalize(s);
        accel *acc;
        thz_error err;
        assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
        enum { BINS = 10 };
        uint64_t n = ps_scaled(100000), hist[BINS] = {0};
        trace_buffer buf = {0};
        trace_counters c = {0};
        vec3 in = v3_normalize(v3(0.3, 0.1, from_below ? 1.0 : -1.0));
        for (uint64_t i = 0; i < n; i++) {
            emission_photon e = {.freq_hz = 0.35e12,
                                 .power_w_per_hz = 1.0,
                                 .position_m = v3(-0.15, -0.05, 0.5 * zc),
                                 .dir = in,
                                 .object = (uint32_t)cover,
                                 .triangle = 0};
            rng_stream rng;
            rng_init(&rng, 6, 0, RNG_PURPOSE_TEST, i);
            buf.count = 0;
            assert_true(trace_photon(s, acc, NULL, &e, &rng, &buf, &c));
            assert_int_equal(buf.count, 2);
            assert_int_equal(photon_object(&buf.records[0]), plate);
            assert_int_equal(photon_side(&buf.records[0]), from_below);
            assert_int_equal(photon_object(&buf.records[1]), cover);
            vec3 d = photon_decode_direction(buf.records[1].dir_oct);
            assert_true(from_below ? d.z < 0 : d.z > 0); /* back into the side it came from */
            int b = (int)(fabs(d.z) * BINS);
            hist[b < BINS ? b : BINS - 1]++;
        }
        assert_int_equal(c.reflected, n);
        assert_int_equal(c.back_face_hits, 0);
        for (int b = 0; b < BINS; b++) {
            double lo = (double)b / BINS, hi = (double)(b + 1) / BINS;
            char what[48];
            snprintf(what, sizeof what, "reflected mu bin %d", b);
            check_fraction(hist[b], n, hi * hi - lo * lo, what);
        }

        /* From below onto the one-sided plate: its back side. */
        if (from_below) {
            memset(&c, 0, sizeof c);
            emission_photon e = {.freq_hz = 0.35e12,
                                 .power_w_per_hz = 1.0,
                                 .position_m = v3(50, 0, -0.5),
                                 .dir = v3(0, 0, 1),
                                 .object = (uint32_t)cover,
                                 .triangle = 0};
            rng_stream rng;
            rng_init(&rng, 6, 1, RNG_PURPOSE_TEST, 0);
            buf.count = 0;
            assert_true(trace_photon(s, acc, NULL, &e, &rng, &buf, &c));
            assert_int_equal(buf.count, 1);
            assert_int_equal(photon_object(&buf.records[0]), one_sided);
            assert_int_equal(photon_side(&buf.records[0]), 1);
            assert_int_equal(c.back_face_hits, 1);
            assert_int_equal(c.absorbed, 1);
            assert_float_equal(c.absorbed_power, 1.0, 0.0);
        }
        trace_buffer_fini(&buf);
        accel_destroy(acc);
        scene_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fractions),
        cmocka_unit_test(test_diffuse_exit_distribution),
        cmocka_unit_test(test_transmission_in_scene),
        cmocka_unit_test(test_reflection_and_back_faces),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
