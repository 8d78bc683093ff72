/* Atmosphere in the photon phase (eq. 7): the power arriving after a free path d is
 * exp(-alpha d) times the power sent, exactly along a fixed ray and on average where the
 * low-power roulette is at work; a cosine emitter facing a black plane at distance d
 * delivers on average 2 E3(alpha d) of its power (E3 the exponential integral); and the
 * power lost on the way is booked as atmosphere power; emitting air sends its photons
 * in every direction alike; non-emitting humid air is air at 0 K for a deviation map.
 * Tolerances: 5 standard errors (the last, deterministic in its power: 1e-3). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon/trace.h"
#include "deviation_photons.h"
#include "physics/channel.h"
#include "physics/planck.h"
#include "photon_scenes.h"

/* A black plane at z = 0 (normal +z, half-size `half` m), a constant atmosphere. */
static thz_scene *plane_scene(double alpha_per_m, double half, uint64_t photons)
{
    thz_scene *s = ps_scene(0.35, 0.01, photons, 8);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plane = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, plane, v3(0, 0, 0), v3(half, 0, 0), v3(0, half, 0));
    s->atmosphere.model = ATM_CONSTANT;
    ps_check(spectrum_set_constant(&s->atmosphere.attenuation_per_m, alpha_per_m));
    return s;
}

/* Traces photons of power 1 straight down from height d onto the plane. */
static void straight_down(double alpha, double d, uint64_t n, double *mean_power,
                          double *stored_power, uint64_t *stored, trace_counters *c)
{
    thz_scene *s = plane_scene(alpha, 10, n);
    /* A small "source" plate above, facing down, only to name the leaving triangle. */
    size_t src = ps_object(s, OBJECT_SOLID, 0, 0, 0, false);
    ps_face(s, src, v3(0, 0, d), v3(0, 0.01, 0), v3(0.01, 0, 0));
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    trace_buffer buf = {0};
    memset(c, 0, sizeof *c);
    double sum = 0.0;
    *stored = 0;
    for (uint64_t i = 0; i < n; i++) {
        emission_photon e = {.freq_hz = 0.35e12,
                             .power_w_per_hz = 1.0,
                             .position_m = v3(0, 0, d),
                             .dir = v3(0, 0, -1),
                             .object = (uint32_t)src,
                             .triangle = 0};
        rng_stream rng;
        rng_init(&rng, 8, 0, RNG_PURPOSE_PHOTON, i);
        buf.count = 0;
        assert_true(trace_photon(s, acc, NULL, &e, &rng, &buf, c));
        assert_true(buf.count <= 1);
        if (buf.count == 1) {
            *stored_power = buf.records[0].power_w_per_hz;
            sum += buf.records[0].power_w_per_hz;
            (*stored)++;
        }
    }
    *mean_power = sum / (double)n;
    trace_buffer_fini(&buf);
    accel_destroy(acc);
    scene_destroy(s);
}

static void test_fixed_path(void **state)
{
    (void)state;
    double mean, one;
    uint64_t stored;
    trace_counters c;
    /* alpha d = 0.5: above the roulette threshold, every photon arrives with exp(-0.5). */
    straight_down(0.25, 2.0, 1000, &mean, &one, &stored, &c);
    assert_int_equal(stored, 1000);
    assert_float_equal(one, exp(-0.5), 1e-6);
    assert_float_equal(mean, exp(-0.5), 1e-6);
    assert_float_equal(c.atmosphere_power, 1000 * (1 - exp(-0.5)), 1e-9 * 1000);
    assert_float_equal(c.absorbed_power + c.atmosphere_power, c.fired_power, 1e-9 * c.fired_power);
}

static void test_low_power_roulette(void **state)
{
    (void)state;
    /* alpha d = 6: exp(-6) = 0.0025 < min_relative_power 0.01; photons survive with
     * p = 0.248 at power 0.01 and the mean stays exp(-6). */
    uint64_t n = ps_scaled(200000);
    double mean, one;
    uint64_t stored;
    trace_counters c;
    straight_down(3.0, 2.0, n, &mean, &one, &stored, &c);
    double p = exp(-6) / 0.01;
    assert_float_equal(one, 0.01, 1e-8);
    double se_p = sqrt(p * (1 - p) / (double)n);
    printf("# survivors %.5f expected %.5f; mean power %.6e expected %.6e\n",
           (double)stored / (double)n, p, mean, exp(-6));
    assert_true(fabs((double)stored / (double)n - p) < 5 * se_p);
    assert_true(fabs(mean - exp(-6)) < 5 * 0.01 * se_p);
    assert_int_equal(c.terminated, n - stored);
    /* Balance: what was lost in the air, absorbed, and the roulette's net removal. */
    assert_float_equal(c.absorbed_power + c.atmosphere_power + c.terminated_power, c.fired_power,
                       1e-9 * c.fired_power);
}

/* 2 int_0^1 exp(-tau/mu) mu dmu = 2 E3(tau), by Simpson. */
static double two_e3(double tau)
{
    const int n = 20000;
    double h = 1.0 / n, s = 0.0;
    for (int i = 1; i <= n; i++) {
        double mu = i * h;
        double w = i == n ? 1 : (i % 2 ? 4 : 2);
        s += w * exp(-tau / mu) * mu;
    }
    return 2.0 * s * h / 3.0;
}

static void test_cosine_emitter(void **state)
{
    (void)state;
    const double alpha = 0.5, d = 1.0;
    uint64_t k = ps_scaled(300000);
    thz_scene *s = plane_scene(alpha, 1000, k);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t src = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, src, v3(0, 0, d), v3(0, 0.005, 0), v3(0.005, 0, 0)); /* 1 cm, facing down */
    ps_finalize(s);
    photon_map *map;
    photon_stats st;
    ps_fire(s, NULL, &map, &st);
    const photon_record *r = photon_map_records(map);
    double phi = st.fired_power_w_per_hz / (double)k, sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < photon_map_count(map); i++) {
        assert_int_equal(photon_object(&r[i]), 0);
        double x = r[i].power_w_per_hz / phi;
        sum += x;
        sum2 += x * x;
    }
    double mean = sum / (double)k, se = sqrt((sum2 / (double)k - mean * mean) / (double)k);
    double expect = two_e3(alpha * d);
    printf("# cosine emitter: arriving %.5f expected 2 E3(%.2f) = %.5f (%.1f se); escaped %llu\n",
           mean, alpha * d, expect, (mean - expect) / se, (unsigned long long)st.escaped);
    assert_true(fabs(mean - expect) < 5 * se);
    assert_float_equal(st.absorbed_power_w_per_hz + st.atmosphere_power_w_per_hz +
                           st.terminated_power_w_per_hz + st.escaped_power_w_per_hz,
                       st.fired_power_w_per_hz, 1e-9 * st.fired_power_w_per_hz);
    photon_map_destroy(map);
    scene_destroy(s);
}

/* Emitting air (alpha 0.2 /m at 300 K) filling a closed black room at 0 K (its extent the
 * room): every photon is an air photon, emitted isotropically (air_emission.h), so by
 * symmetry the floor and the ceiling receive as many, each within 5 standard errors of
 * their sum. Air photons sent upwards only (a mutant: the direction's z drawn from
 * (0, 1] instead of (-1, 1]) was caught only by test_deviation_photons' T0 = 0 checksums,
 * which pin the bytes rather than the rule: the floor received nothing. */
static void test_air_isotropic(void **state)
{
    (void)state;
    const uint64_t k = ps_scaled(20000);
    thz_scene *s = ps_scene(0.35, 0.05, k, 9);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2), true);
    ps_finalize(s);
    thz_error err;
    double lo[3] = {-1, -1, 0}, hi[3] = {1, 1, 2};
    s->atmosphere.model = ATM_CONSTANT;
    ps_check(spectrum_set_constant(&s->atmosphere.attenuation_per_m, 0.2));
    ps_check(atmosphere_set_emitting(&s->atmosphere, 300.0, 0.0, &err) == THZ_OK);
    ps_check(atmosphere_set_extent(&s->atmosphere, lo, hi, &err) == THZ_OK);
    photon_map *map;
    photon_stats st;
    ps_fire(s, &(photon_phase_options){.threads = 2}, &map, &st);
    const photon_record *r = photon_map_records(map);
    size_t floor_hits = 0, ceiling_hits = 0;
    for (size_t i = 0; i < photon_map_count(map); i++) {
        floor_hits += fabsf(r[i].position_m[2]) < 1e-4f;
        ceiling_hits += fabsf(r[i].position_m[2] - 2.0f) < 1e-4f;
    }
    double sum = (double)(floor_hits + ceiling_hits);
    printf("# emitting air in a black room: %zu records, %zu on the floor, %zu on the ceiling\n",
           photon_map_count(map), floor_hits, ceiling_hits);
    assert_true(photon_map_count(map) > k / 2);             /* alpha 0.2 /m: most reach a wall */
    assert_true(sum > 0.2 * (double)photon_map_count(map)); /* 2 of 6 equal faces: 1/3 */
    assert_true(fabs((double)floor_hits - (double)ceiling_hits) < 5.0 * sqrt(sum));
    photon_map_destroy(map);
    scene_destroy(s);
}

static double alpha_b_at(double freq_hz, void *s)
{
    const thz_atmosphere *atm = &((const thz_scene *)s)->atmosphere;
    return atmosphere_alpha_per_m(atm, freq_hz) * planck_radiance(freq_hz, 300.0);
}

/* Non-emitting air with an air state (itu-p676 humid air at 290 K, "emitting": false) is,
 * as the constant model's, air at 0 K for the photons: with T0 = 300 K it fires
 * -4 pi V <alpha B(T0)>, its band mean by channel_band_mean. Its air's 290 K taken as an
 * emitter's (a mutant) passed every test, whose non-emitting air had no temperature: the
 * deviation map of such a scene then held the air's 4 pi alpha B(290 K) as well. */
static void test_non_emitting_humid_air(void **state)
{
    (void)state;
    const double t0 = 300.0;
    thz_error err = {0};
    thz_scene *s = ps_scene(0.35, 0.1, ps_scaled(200000), 23);
    size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, wall, t0, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
    ps_finalize(s);
    atm_air_state air;
    ps_check(atm_air_state_init(&air, 290.0, 1013.25, ATM_HUMIDITY_RELATIVE, 0.6, &err) == THZ_OK);
    ps_check(atmosphere_init_itu_p676(&s->atmosphere, &air, NULL, &err) == THZ_OK);
    ps_check(atmosphere_prepare(&s->atmosphere, s->channels, s->n_channels, &err) == THZ_OK);
    double lo[3] = {-0.99, -0.99, 0.01}, hi[3] = {0.99, 0.99, 2.49};
    ps_check(atmosphere_set_extent(&s->atmosphere, lo, hi, &err) == THZ_OK);
    double v = 1.98 * 1.98 * 2.48;
    double expected = -4.0 * M_PI * v * channel_band_mean(&s->channels[0], alpha_b_at, s);
    photon_map *map;
    photon_stats st;
    fire(s, t0, 2, &map, &st);
    printf("# non-emitting humid air: fired %.6e W/Hz, expected %.6e\n", st.fired_power_w_per_hz,
           expected);
    assert_true(fabs(st.fired_power_w_per_hz - expected) <= 1e-3 * fabs(expected));
    photon_map_destroy(map);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fixed_path),
        cmocka_unit_test(test_low_power_roulette),
        cmocka_unit_test(test_cosine_emitter),
        cmocka_unit_test(test_air_isotropic),
        cmocka_unit_test(test_non_emitting_humid_air),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
