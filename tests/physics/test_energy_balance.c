/* Energy balance of the photon phase: absorbed + escaped + atmosphere + terminated power
 * equals the power fired (exactly, up to rounding), the power fired equals the band-mean
 * emitted power P_A within its statistical error, and the counts close (every hit is
 * reflected, transmitted or absorbed; every path ends absorbed, escaped or terminated).
 * Scenes: the closed box scene with every kind of surface and an atmosphere, an open one
 * (a plate and a shell in free space) where photons escape, and a room with a Ward plate,
 * whose reflections weigh the power (the weights' difference from 1 is booked as
 * terminated power, so the balance still closes). Then the rules that end or send on a
 * path: the bounce cap, a one-sided solid's back face, a diffuse transmission. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon/trace.h"
#include "photon_scenes.h"

typedef struct moment_ctx {
    const thz_scene *scene;
    int power; /* 1: P_A(nu), 2: P_A(nu)^2 */
} moment_ctx;

static double moment_at(double freq_hz, void *ctx)
{
    const moment_ctx *m = ctx;
    double p = scene_emitted_power_w_per_hz(m->scene, freq_hz);
    return m->power == 2 ? p * p : p;
}

/* weighted: some reflections weigh the power (a Ward lobe), so the terminated power holds
 * their differences from 1 besides the roulette's, and is not bounded by it. (A lobe's
 * sample lost below the surface counts as absorbed, not reflected: every hit is one of the
 * three, so summary.json's fractions per hit sum to 1 in such scenes too.) */
static void check_balance(thz_scene *s, const char *name, bool weighted)
{
    photon_map *map;
    photon_stats st;
    ps_fire(s, &(photon_phase_options){.threads = 2}, &map, &st);
    uint64_t k = s->photons.per_channel;

    /* Counts. */
    assert_int_equal(st.fired, k);
    assert_int_equal(st.stored, photon_map_count(map));
    assert_int_equal(st.hits, st.stored);
    assert_int_equal(st.hits, st.reflected + st.transmitted + st.absorbed);
    assert_int_equal(st.fired, st.absorbed + st.escaped + st.terminated);
    assert_int_equal(st.bounce_capped, 0);
    assert_float_equal(st.mean_bounces, (double)st.hits / (double)k, 1e-12);

    /* Exact balance of what was fired. */
    double out = st.absorbed_power_w_per_hz + st.escaped_power_w_per_hz +
                 st.atmosphere_power_w_per_hz + st.terminated_power_w_per_hz;
    printf("# %s: fired %.6e = absorbed %.6e + escaped %.6e + atmosphere %.6e + terminated "
           "%.3e (%.2e relative); %.2f hits per photon\n",
           name, st.fired_power_w_per_hz, st.absorbed_power_w_per_hz, st.escaped_power_w_per_hz,
           st.atmosphere_power_w_per_hz, st.terminated_power_w_per_hz,
           out / st.fired_power_w_per_hz - 1, st.mean_bounces);
    assert_float_equal(out, st.fired_power_w_per_hz, 1e-9 * st.fired_power_w_per_hz);

    /* Fired vs emitted: the photons' powers P_A(nu_i)/K have the band's mean and variance;
     * their sum's standard error follows from the band moments of P_A. */
    moment_ctx m1 = {s, 1}, m2 = {s, 2};
    double mean = channel_band_mean(&s->channels[0], moment_at, &m1);
    double var = channel_band_mean(&s->channels[0], moment_at, &m2) - mean * mean;
    double se = sqrt(fmax(var, 0.0) / (double)k) + 1e-12 * mean;
    assert_float_equal(st.emitted_power_w_per_hz, mean, 1e-12 * mean);
    printf("# %s: fired %.8e emitted %.8e (%.1f se)\n", name, st.fired_power_w_per_hz, mean,
           (st.fired_power_w_per_hz - mean) / se);
    assert_true(fabs(st.fired_power_w_per_hz - mean) < 5 * se);

    /* The terminated power is zero in expectation: each low-power roulette decision
     * (at most one per hit or termination) moves at most w_min = min_relative_power * Phi
     * (Phi within a factor 2 of its mean in these bands), so the sum stays within
     * 5 w_min sqrt(decisions); a plain cut-off would lose about terminated * w_min / 2. */
    double w_min = 2.0 * s->photons.min_relative_power * mean / (double)k;
    printf("# %s: %llu terminated, net terminated power %.3e (bound %.3e)\n", name,
           (unsigned long long)st.terminated, st.terminated_power_w_per_hz,
           5 * w_min * sqrt((double)(st.terminated + st.hits)));
    if (!weighted)
        assert_true(fabs(st.terminated_power_w_per_hz) <=
                    5 * w_min * sqrt((double)(st.terminated + st.hits)));
    photon_map_destroy(map);
}

static void test_closed_box(void **state)
{
    (void)state;
    thz_scene *s = ps_box_scene(ps_scaled(200000), 21, 0.4);
    s->channels[0].relative_width = 0.3; /* wide: the fired power varies with nu */
    check_balance(s, "box", false);
    scene_destroy(s);
}

static void test_open_scene(void **state)
{
    (void)state;
    thz_scene *s = ps_scene(0.6, 0.05, ps_scaled(200000), 22);
    size_t grey = ps_material(s, 0.4, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t cloth = ps_material(s, 0.1, 150.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plate = ps_object(s, OBJECT_SOLID, grey, 305, 0, false);
    ps_face(s, plate, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0));
    size_t shell = ps_object(s, OBJECT_SHELL, cloth, 280, 2e-3, true);
    ps_box(s, shell, v3(-0.3, -0.3, 0.1), v3(0.3, 0.3, 0.5), false);
    ps_finalize(s);
    check_balance(s, "open", false);
    scene_destroy(s);
}

/* A brushed Ward plate of a complex index on the floor of a closed room, lit by a hot
 * block: a photon reflected by the lobe's sampled branch carries its power times the
 * sample's weight f cos / pdf (mean 1, not 1 each), and the balance closes only if the
 * path goes on with that weighted power. Reflections that kept the unweighted power, with
 * the weight's difference still booked as terminated, left it open by 0.2 % of the
 * fired power (and sent the reflected power out in the sampling's directions rather than
 * the lobe's). */
static void test_ward_room(void **state)
{
    (void)state;
    static const char *json =
        "{\"format\": \"thzmap-scene/1\", \"name\": \"ward-room\","
        " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.03}],"
        " \"materials\": {\"wall\": {\"reflectivity\": 0.1},"
        "   \"brushed\": {\"refractive_index\": [2.5, 1.5],"
        "     \"reflection\": {\"model\": \"ward\", \"alpha_x\": 0.25, \"alpha_y\": 0.5}}},"
        " \"objects\": ["
        "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\","
        "    \"temperature_k\": 290,"
        "    \"shape\": {\"type\": \"box\", \"size_m\": [3, 3, 3], \"inward\": true}},"
        "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"brushed\","
        "    \"temperature_k\": 290, \"shape\": {\"type\": \"box\", \"size_m\": [1.2, 1.2, 0.05]},"
        "    \"transform\": {\"translate_m\": [0, 0, -0.6]}},"
        "   {\"name\": \"hot\", \"type\": \"solid\", \"material\": \"wall\","
        "    \"temperature_k\": 400, \"shape\": {\"type\": \"box\", \"size_m\": [0.6, 0.2, 0.6]},"
        "    \"transform\": {\"translate_m\": [0, 0.8, 0]}}],"
        " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0.3],"
        "   \"look_at_m\": [0, 0, -0.6], \"up\": [0, 0, 1], \"fov_deg\": 40,"
        "   \"resolution\": [4, 4]}],"
        " \"photons\": {\"per_channel\": 1000, \"seed\": 23}}";
    thz_scene *s;
    thz_error err;
    if (scene_load_string(json, ".", "ward-room", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    s->photons.per_channel = ps_scaled(100000);
    check_balance(s, "ward room", true);
    scene_destroy(s);
}

/* A closed room of perfect mirrors (R = 1) that emits (an explicit emissivity; unphysical,
 * but nothing ends a path in it): every photon is stopped by the bounce cap, and the
 * statistics count each one as terminated (photon_stats.h: the capped are included), so
 * that fired = absorbed + escaped + terminated still holds, as summary.json reports it.
 * The capped paths left out of "terminated" (a mutant) passed every test, since no other
 * scene reaches the cap. */
static void test_bounce_cap(void **state)
{
    (void)state;
    const uint64_t k = 24;
    thz_scene *s = ps_scene(0.35, 0.05, k, 24);
    size_t mirror = ps_material(s, 1.0, 0.0, 1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, mirror, 300, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2), true);
    ps_finalize(s);
    photon_map *map;
    photon_stats st;
    ps_fire(s, &(photon_phase_options){.threads = 2}, &map, &st);
    printf("# mirror room: %llu fired, %llu capped, %llu terminated, %llu absorbed, %llu hits\n",
           (unsigned long long)st.fired, (unsigned long long)st.bounce_capped,
           (unsigned long long)st.terminated, (unsigned long long)st.absorbed,
           (unsigned long long)st.hits);
    assert_int_equal(st.fired, k);
    assert_int_equal(st.bounce_capped, k);
    assert_int_equal(st.terminated, k);
    assert_int_equal(st.absorbed + st.escaped, 0);
    assert_int_equal(st.hits, k * TRACE_MAX_BOUNCES);
    assert_int_equal(st.reflected, st.hits);
    assert_float_equal(st.terminated_power_w_per_hz, st.fired_power_w_per_hz,
                       1e-12 * st.fired_power_w_per_hz);
    photon_map_destroy(map);
    scene_destroy(s);
}

/* A one-sided mirror (R = 0.9, 0 K) whose back faces a hot black plate 0.5 m below it:
 * a photon that meets the back of a one-sided solid ends there, absorbed (trace.h), so
 * every record is a first hit, nothing is reflected, and every hit on the mirror is a
 * back-face hit. Back faces reflecting by the material's optics (a mutant) passed every
 * test but the T0 = 0 checksums of test_deviation_photons, which pin the bytes, not the
 * rule: the photons reflected back down lit the hot plate, 0.9 of what met the mirror. */
static void test_back_face_absorbs(void **state)
{
    (void)state;
    const uint64_t k = ps_scaled(20000);
    thz_scene *s = ps_scene(0.35, 0.05, k, 25);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t mirror = ps_material(s, 0.9, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t hot = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, hot, v3(0, 0, 0), v3(0.5, 0, 0), v3(0, 0.5, 0)); /* normal +z */
    size_t plate = ps_object(s, OBJECT_SOLID, mirror, 0, 0, false);
    ps_face(s, plate, v3(0, 0, 0.5), v3(0.5, 0, 0), v3(0, 0.5, 0)); /* +z: its back below */
    ps_finalize(s);
    photon_map *map;
    photon_stats st;
    ps_fire(s, &(photon_phase_options){.threads = 2}, &map, &st);
    const photon_record *r = photon_map_records(map);
    size_t on_back = 0, later = 0;
    for (size_t i = 0; i < photon_map_count(map); i++) {
        on_back += photon_object(&r[i]) == plate && photon_side(&r[i]) == 1;
        later += !photon_first_hit(&r[i]);
    }
    printf("# back of a one-sided mirror: %zu of %llu photons met it, %llu reflected, %zu later "
           "hits\n",
           on_back, (unsigned long long)k, (unsigned long long)st.reflected, later);
    assert_true(on_back > k / 10); /* the plates' view factor is about 0.4 */
    assert_int_equal(st.back_face_hits, on_back);
    assert_int_equal(photon_map_count(map), on_back);
    assert_int_equal(st.reflected, 0);
    assert_int_equal(later, 0);
    assert_float_equal(st.absorbed_power_w_per_hz + st.escaped_power_w_per_hz,
                       st.fired_power_w_per_hz, 1e-9 * st.fired_power_w_per_hz);
    photon_map_destroy(map);
    scene_destroy(s);
}

/* A small hot black plate (z = 0, facing up), a shell 10 m across (reflectivity r,
 * attenuation alpha over 5 mm, 0 K, diffuse transmission) at z = 0.5 m and a small cold black
 * plate (z = 1 m, facing down), which sees the hot one only through the shell: k photons
 * fired; their hits on each (hot, shell, cold) into on[], the statistics into *st. */
static void fire_sandwich(uint64_t k, double r, double alpha_per_m, size_t on[3], photon_stats *st)
{
    thz_scene *s = ps_scene(0.35, 0.05, k, 26);
    size_t black = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t veil = ps_material(s, r, alpha_per_m, -1.0, TRANSMISSION_DIFFUSE);
    size_t hot = ps_object(s, OBJECT_SOLID, black, 300, 0, false);
    ps_face(s, hot, v3(0, 0, 0), v3(0.25, 0, 0), v3(0, 0.25, 0)); /* normal +z */
    size_t shell = ps_object(s, OBJECT_SHELL, veil, 0, 5e-3, true);
    ps_face(s, shell, v3(0, 0, 0.5), v3(5, 0, 0), v3(0, 5, 0));
    size_t cold = ps_object(s, OBJECT_SOLID, black, 0, 0, false);
    ps_face(s, cold, v3(0, 0, 1.0), v3(0, 0.25, 0), v3(0.25, 0, 0)); /* normal -z */
    ps_finalize(s);
    photon_map *map;
    ps_fire(s, &(photon_phase_options){.threads = 2}, &map, st);
    const photon_record *rec = photon_map_records(map);
    on[0] = on[1] = on[2] = 0;
    for (size_t i = 0; i < photon_map_count(map); i++)
        on[photon_object(&rec[i])]++;
    printf("# shell (R %.1f, alpha t %.2f) between plates: %llu reflected, %llu transmitted, "
           "%llu absorbed; %zu hits on the hot plate, %zu on the shell, %zu on the cold plate\n",
           r, alpha_per_m * 5e-3, (unsigned long long)st->reflected,
           (unsigned long long)st->transmitted, (unsigned long long)st->absorbed, on[hot],
           on[shell], on[cold]);
    assert_true(on[shell] > k * 9 / 10); /* the rest pass its edge, grazing */
    photon_map_destroy(map);
    scene_destroy(s);
}

/* A shell without reflection (alpha t = 0.5): a photon transmitted through it leaves on
 * its far side (trace_diffuse_transmission_dir about -n_in), so the cold plate receives
 * photons and nothing ever comes back down onto the hot one. Transmitted photons sent back
 * to the side they came from (a mutant) was caught only by test_deviation_photons' T0 = 0
 * checksums, which pin the bytes rather than the rule: the plate behind got nothing and the
 * hot one what the shell let through. */
static void test_diffuse_transmission_goes_through(void **state)
{
    (void)state;
    const uint64_t k = ps_scaled(20000);
    size_t on[3];
    photon_stats st;
    fire_sandwich(k, 0.0, 100.0, on, &st);
    assert_true(st.transmitted > k / 10);
    assert_int_equal(on[0], 0);
    assert_true(on[2] > 0);
}

/* A lossless shell (R = 0.3, alpha = 0: T = 1 - R = 0.7 at every angle, A = 0): at each
 * hit on it the roulette reflects with probability 0.3 and transmits with 0.7 (trace_roulette:
 * u < R, else u < R + T), and absorbs nothing; only the black plates absorb. Counts within
 * 5 standard errors of the shell's hits. A transmission drawn as u < T instead of u < R + T
 * (a mutant: T - R = 0.4 transmitted, 0.3 absorbed) was caught only by test_deviation_photons'
 * T0 = 0 checksums. */
static void test_shell_roulette(void **state)
{
    (void)state;
    const uint64_t k = ps_scaled(20000);
    size_t on[3];
    photon_stats st;
    fire_sandwich(k, 0.3, 0.0, on, &st);
    double n = (double)on[1], se = sqrt(0.3 * 0.7 / n);
    double fr = (double)st.reflected / n, ft = (double)st.transmitted / n;
    printf("# lossless shell: reflected %.4f (0.3), transmitted %.4f (0.7), se %.4f\n", fr, ft, se);
    assert_true(fabs(fr - 0.3) < 5.0 * se);
    assert_true(fabs(ft - 0.7) < 5.0 * se);
    assert_int_equal(st.reflected + st.transmitted, on[1]);
    assert_int_equal(st.absorbed, on[0] + on[2]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_box),
        cmocka_unit_test(test_open_scene),
        cmocka_unit_test(test_ward_room),
        cmocka_unit_test(test_bounce_cap),
        cmocka_unit_test(test_back_face_absorbs),
        cmocka_unit_test(test_diffuse_transmission_goes_through),
        cmocka_unit_test(test_shell_roulette),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
