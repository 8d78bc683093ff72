/* Deviation photon maps (phase.h, photon_map.h "Reference temperature"): with T0 > 0
 * the photon phase fires the map of L - B_nu(T0), whose sources are signed. This file
 * checks the power they fire; test_deviation_photons.c pins the map's bytes (T0 = 0
 * checksums, thread count).
 *
 * - Furnace: a closed isothermal enclosure at T = T0 (solids, shells of both modes,
 *   an absorbing atmosphere at T0) fires no power.
 * - Fired power = the analytic band power of the deviation sources, for T0 between and
 *   outside the object temperatures, with an explicit-emissivity shell (two sources of
 *   different angular law), explicit-emissivity solids (with a refractive index, with a
 *   reflectivity varying over the band), a non-emitting absorbing atmosphere (air at
 *   0 K: the air fires -4 pi alpha B(T0) per volume) and an open boundary (-B0).
 *   Tolerances: 5 standard errors of the mean photon power, estimated from the photons
 *   themselves; a sign or factor-2 error is far beyond them.
 * - The energy balance closes exactly.
 */
#include <complex.h>

#include "deviation_photons.h"
#include "photon/emission.h"
#include "physics/channel.h"
#include "physics/planck.h"
#include "physics/spectrum.h"

static double planck_at(double freq_hz, void *t_k)
{
    return planck_radiance(freq_hz, *(const double *)t_k);
}

/* Band mean of B_nu(T) over channel 0. */
static double band_b(const thz_scene *s, double t_k)
{
    return channel_band_mean(&s->channels[0], planck_at, &t_k);
}

/* Moments of the photons' initial powers, from the first-hit records (bounce 0) of a
 * scene without atmosphere where every photon hits something: n photons in all (those
 * of power 0 count as 0). */
typedef struct power_moments {
    double sum, sum2, sum_abs;
    size_t n_neg, n_pos;
} power_moments;

static power_moments first_hits(const photon_map *map)
{
    power_moments m = {0};
    const photon_record *r = photon_map_records(map);
    for (size_t i = 0; i < photon_map_count(map); i++) {
        if (!photon_first_hit(&r[i]))
            continue;
        double p = r[i].power_w_per_hz;
        m.sum += p;
        m.sum2 += p * p;
        m.sum_abs += fabs(p);
        m.n_neg += p < 0.0;
        m.n_pos += p > 0.0;
    }
    return m;
}

/* 5 standard errors of a sum of n photon powers with these moments. */
static double five_sigma(const power_moments *m, uint64_t n)
{
    double mean = m->sum / (double)n;
    double var = m->sum2 / (double)n - mean * mean;
    return 5.0 * sqrt(fmax(var, 0.0) * (double)n);
}

static void assert_balance(const photon_stats *st, double scale)
{
    double out = st->absorbed_power_w_per_hz + st->escaped_power_w_per_hz +
                 st->atmosphere_power_w_per_hz + st->terminated_power_w_per_hz;
    assert_true(fabs(out - st->fired_power_w_per_hz) <= 1e-9 * scale);
    assert_int_equal(st->fired, st->absorbed + st->escaped + st->terminated);
    assert_int_equal(st->hits, st->reflected + st->transmitted + st->absorbed);
}

/* A closed room (inward, one-sided, R = 0.3) at T with a solid cube, a diffuse and a
 * straight Kirchhoff shell, a two-sided plate with frequency-dependent R, all at T. */
static thz_scene *furnace_scene(uint64_t photons, double t_k)
{
    thz_scene *s = ps_scene(0.35, 0.05, photons, 3);
    size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t paint = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t cloth = ps_material(s, 0.05, 200.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t film = ps_material(s, 0.1, 100.0, -1.0, TRANSMISSION_STRAIGHT);
    size_t tile = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    double f[3] = {0.30e12, 0.35e12, 0.40e12}, r[3] = {0.1, 0.4, 0.2};
    ps_check(spectrum_set_table(&s->materials[tile].reflectivity, 3, f, r));
    size_t room = ps_object(s, OBJECT_SOLID, wall, t_k, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
    size_t cube = ps_object(s, OBJECT_SOLID, paint, t_k, 0, false);
    ps_box(s, cube, v3(-0.3, -0.3, 0.05), v3(0.3, 0.3, 0.6), false);
    size_t shell = ps_object(s, OBJECT_SHELL, cloth, t_k, 1e-3, true);
    ps_box(s, shell, v3(-0.4, -0.4, 0.02), v3(0.4, 0.4, 0.8), false);
    size_t straight = ps_object(s, OBJECT_SHELL, film, t_k, 2e-3, true);
    ps_face(s, straight, v3(0, 0.8, 1.2), v3(0.5, 0, 0), v3(0, 0, 0.5));
    size_t plate = ps_object(s, OBJECT_SOLID, tile, t_k, 0, true);
    ps_face(s, plate, v3(0.6, -0.6, 1.8), v3(0.2, 0, 0), v3(0, 0.2, 0));
    ps_finalize(s);
    return s;
}

/* Isothermal furnace at T = T0: no source anywhere, so no photon carries power; with an
 * absorbing atmosphere emitting at T too, and (closed scene) without atmosphere, where
 * the boundary's -B0 is hidden. The physical P_A is still reported. */
static void test_furnace(void **state)
{
    (void)state;
    thz_error err;
    for (int atm = 0; atm < 2; atm++) {
        thz_scene *s = furnace_scene(20000, 300.0);
        if (atm) {
            s->atmosphere.model = ATM_CONSTANT;
            ps_check(spectrum_set_constant(&s->atmosphere.attenuation_per_m, 0.2));
            ps_check(atmosphere_set_emitting(&s->atmosphere, 300.0, 300.0, &err) == THZ_OK);
        }
        photon_map *map;
        photon_stats st;
        fire(s, 300.0, 2, &map, &st);
        printf("# furnace%s: %zu records, fired %.3e W/Hz (P_A %.3e W/Hz)\n",
               atm ? " with air" : "", photon_map_count(map), st.fired_power_w_per_hz,
               st.emitted_power_w_per_hz);
        assert_int_equal(st.fired, s->photons.per_channel);
        assert_int_equal(photon_map_count(map), 0);
        assert_true(st.fired_power_w_per_hz == 0.0);
        assert_true(st.absorbed_power_w_per_hz == 0.0 && st.escaped_power_w_per_hz == 0.0);
        assert_true(st.emitted_power_w_per_hz > 0.0);
        assert_true(st.reference_temperature_k == 300.0);
        assert_true(photon_map_reference_temperature_k(map) == 300.0);
        photon_map_destroy(map);
        scene_destroy(s);
    }
}

/* A closed room of grey Kirchhoff solids: the room (inward, one-sided, R = 0.3, 295 K),
 * a two-sided plate (R = 0.2, 320 K), a one-sided plate (R = 0.1, 280 K) and a cold
 * two-sided plate (R = 0.5, 0 K). */
static thz_scene *grey_room(uint64_t photons)
{
    thz_scene *s = ps_scene(0.35, 0.1, photons, 11);
    size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t a = ps_material(s, 0.2, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t b = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t c = ps_material(s, 0.5, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, wall, 295, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
    size_t p1 = ps_object(s, OBJECT_SOLID, a, 320, 0, true);
    ps_face(s, p1, v3(0, 0, 1.0), v3(0.4, 0, 0), v3(0, 0.3, 0)); /* 0.48 m2 */
    size_t p2 = ps_object(s, OBJECT_SOLID, b, 280, 0, false);
    ps_face(s, p2, v3(0.5, 0.5, 2.0), v3(0.3, 0, 0), v3(0, 0.3, 0)); /* 0.36 m2 */
    size_t p3 = ps_object(s, OBJECT_SOLID, c, 0, 0, true);
    ps_face(s, p3, v3(-0.5, -0.5, 1.5), v3(0.2, 0, 0), v3(0, 0, 0.2)); /* 0.16 m2 */
    ps_finalize(s);
    return s;
}

/* Fired power = sum over objects of pi area sides (1 - R) (Bbar(T) - Bbar(T0)), plus
 * -pi area Bbar(T0) for the back of the one-sided plate (radiance 0: emission.h; the
 * room's backs face outwards and fire nothing), for T0 below, between and above the
 * temperatures (signs mixed or not), within 5 standard errors; the balance closes;
 * photons of both signs where expected. */
static void test_fired_power(void **state)
{
    (void)state;
    const double t0s[] = {250.0, 295.0, 300.0, 350.0};
    uint64_t k = ps_scaled(200000);
    for (size_t i = 0; i < sizeof t0s / sizeof t0s[0]; i++) {
        double t0 = t0s[i];
        thz_scene *s = grey_room(k);
        double expected = 0.0;
        const double r[4] = {0.3, 0.2, 0.1, 0.5}, sides[4] = {1, 2, 1, 2};
        for (size_t o = 0; o < 4; o++)
            expected += M_PI * s->objects[o].mesh.total_area_m2 * sides[o] * (1.0 - r[o]) *
                        (band_b(s, s->objects[o].temperature_k) - band_b(s, t0));
        expected -= M_PI * s->objects[2].mesh.total_area_m2 * band_b(s, t0);
        photon_map *map;
        photon_stats st;
        fire(s, t0, 2, &map, &st);
        power_moments m = first_hits(map);
        double tol = five_sigma(&m, k);
        printf("# T0 = %.0f K: fired %.6e W/Hz, expected %.6e (tolerance %.2e); %zu negative "
               "and %zu positive photons; P_A %.6e\n",
               t0, st.fired_power_w_per_hz, expected, tol, m.n_neg, m.n_pos,
               st.emitted_power_w_per_hz);
        assert_int_equal(m.n_neg + m.n_pos, k); /* a closed room: every photon hits */
        assert_true(fabs(m.sum - st.fired_power_w_per_hz) <= 1e-6 * m.sum_abs); /* floats */
        assert_true(fabs(st.fired_power_w_per_hz - expected) <= tol);
        assert_true(tol < 0.05 * fabs(expected)); /* a factor 2 or a sign would fail */
        assert_balance(&st, m.sum_abs);
        assert_true(m.n_neg > 0); /* the 0 K plate (and the rest when T0 = 350 K) */
        if (t0 < 280.0)
            assert_true(m.n_pos > m.n_neg);
        if (t0 > 320.0)
            assert_int_equal(m.n_pos, 0);
        if (t0 > 280.0 && t0 < 320.0)
            assert_true(m.n_pos > 0);
        photon_map_destroy(map);
        scene_destroy(s);
    }
}

/* 2 int_0^1 A(mu) mu dmu and 2 int_0^1 A(mu) mu^2 dmu of a shell (Simpson), A = 1 - R -
 * min(exp(-tau / mu), 1 - R). */
static void shell_absorption(double r, double tau, double *abar, double *mu_moment)
{
    const int n = 20000;
    double h = 1.0 / n, s1 = 0.0, s2 = 0.0;
    for (int i = 1; i <= n; i++) {
        double mu = i * h;
        double w = i == n ? 1 : (i % 2 ? 4 : 2);
        double a = 1.0 - r - fmin(exp(-tau / mu), 1.0 - r);
        s1 += w * a * mu;
        s2 += w * a * mu * mu;
    }
    *abar = 2.0 * s1 * h / 3.0;
    *mu_moment = 2.0 * s2 * h / 3.0;
}

/* An explicit-emissivity shell (eps 0.3, R 0.1, alpha_M t = 0.05) in a closed room at
 * T0 (Kirchhoff: no source): two sources, eps B(T) with cosine directions and -A(mu) B0
 * with mu ~ A(mu) mu. Their powers and angular laws, from the first-hit records. */
static void test_explicit_shell(void **state)
{
    (void)state;
    const double t0 = 300.0, r = 0.1, eps = 0.3, alpha = 50.0, t_m = 1e-3;
    const double temps[] = {300.0, 330.0};
    uint64_t k = ps_scaled(200000);
    double abar, mu2;
    shell_absorption(r, alpha * t_m, &abar, &mu2);
    for (size_t i = 0; i < 2; i++) {
        thz_scene *s = ps_scene(0.35, 0.1, k, 17);
        size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t veil = ps_material(s, r, alpha, eps, TRANSMISSION_DIFFUSE);
        size_t room = ps_object(s, OBJECT_SOLID, wall, t0, 0, false);
        ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
        size_t shell = ps_object(s, OBJECT_SHELL, veil, temps[i], t_m, true);
        ps_face(s, shell, v3(0, 0, 1.2), v3(0.4, 0, 0), v3(0, 0.4, 0)); /* normal +z */
        ps_finalize(s);
        double area = s->objects[shell].mesh.total_area_m2;
        double p_eps = M_PI * area * 2.0 * eps * band_b(s, temps[i]);
        double p_abs = -M_PI * area * 2.0 * abar * band_b(s, t0);
        photon_map *map;
        photon_stats st;
        fire(s, t0, 1, &map, &st);
        /* Each sign separately: sums and mean mu = |dir_z| of the first hits. */
        double sum[2] = {0, 0}, sum2[2] = {0, 0}, mu[2] = {0, 0}, mu_sq[2] = {0, 0};
        size_t n[2] = {0, 0};
        const photon_record *rec = photon_map_records(map);
        for (size_t j = 0; j < photon_map_count(map); j++) {
            if (!photon_first_hit(&rec[j]))
                continue;
            int neg = rec[j].power_w_per_hz < 0.0f;
            double p = rec[j].power_w_per_hz;
            double z = fabs(photon_decode_direction(rec[j].dir_oct).z);
            sum[neg] += p;
            sum2[neg] += p * p;
            mu[neg] += z;
            mu_sq[neg] += z * z;
            n[neg]++;
        }
        assert_int_equal(n[0] + n[1], k);
        const double expect_sum[2] = {p_eps, p_abs};
        const double expect_mu[2] = {2.0 / 3.0, mu2 / abar}; /* cosine; A(mu) mu */
        for (int g = 0; g < 2; g++) {
            double mean = sum[g] / (double)k;
            double tol = 5.0 * sqrt(fmax(sum2[g] / (double)k - mean * mean, 0.0) * (double)k);
            double m = mu[g] / (double)n[g];
            double tol_mu = 5.0 * sqrt((mu_sq[g] / (double)n[g] - m * m) / (double)n[g]);
            printf("# T = %.0f K, %s part: %zu photons, power %.6e W/Hz expected %.6e (tol "
                   "%.1e); mean mu %.4f expected %.4f (tol %.4f)\n",
                   temps[i], g ? "-A B0" : "eps B(T)", n[g], sum[g], expect_sum[g], tol, m,
                   expect_mu[g], tol_mu);
            assert_true(fabs(sum[g] - expect_sum[g]) <= tol);
            /* a sign or factor 2 still fails (the -A B0 part has 5 % of the photons) */
            assert_true(tol < 0.25 * fabs(expect_sum[g]));
            assert_true(fabs(m - expect_mu[g]) <= tol_mu);
        }
        /* The two laws differ by far more than the tolerance: the split is tested. */
        assert_true(fabs(expect_mu[0] - expect_mu[1]) > 0.05);
        assert_true(fabs(st.fired_power_w_per_hz - (p_eps + p_abs)) <=
                    5.0 * sqrt(sum2[0] + sum2[1]));
        assert_balance(&st, fabs(sum[0]) + fabs(sum[1]));
        photon_map_destroy(map);
        scene_destroy(s);
    }
}

/* Air in a closed room at T0 (Kirchhoff walls: no surface source), in an extent 1 cm
 * inside the walls (so that its boundary is hidden and every air photon is kept): a
 * non-emitting absorbing atmosphere is air at 0 K and fires 4 pi alpha (0 - Bbar(T0)) V;
 * an emitting one at 280 K fires 4 pi alpha (Bbar(280) - Bbar(T0)) V. The photons'
 * powers differ only by the frequency histogram's interpolation (below 1e-3). */
static void test_absorbing_air(void **state)
{
    (void)state;
    const double t0 = 300.0, alpha = 0.2;
    uint64_t k = ps_scaled(200000);
    thz_error err;
    for (int emitting = 0; emitting < 2; emitting++) {
        thz_scene *s = ps_scene(0.35, 0.1, k, 23);
        size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
        size_t room = ps_object(s, OBJECT_SOLID, wall, t0, 0, false);
        ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
        ps_finalize(s);
        s->atmosphere.model = ATM_CONSTANT;
        ps_check(spectrum_set_constant(&s->atmosphere.attenuation_per_m, alpha));
        if (emitting)
            ps_check(atmosphere_set_emitting(&s->atmosphere, 280.0, 0.0, &err) == THZ_OK);
        double lo[3] = {-0.99, -0.99, 0.01}, hi[3] = {0.99, 0.99, 2.49};
        ps_check(atmosphere_set_extent(&s->atmosphere, lo, hi, &err) == THZ_OK);
        double v = 1.98 * 1.98 * 2.48;
        double expected =
            4.0 * M_PI * alpha * v * ((emitting ? band_b(s, 280.0) : 0.0) - band_b(s, t0));
        photon_map *map;
        photon_stats st;
        fire(s, t0, 2, &map, &st);
        double tol = 1e-3 * fabs(expected);
        printf("# %s air: fired %.6e W/Hz, expected %.6e (tolerance %.2e); P_A %.3e\n",
               emitting ? "emitting" : "absorbing", st.fired_power_w_per_hz, expected, tol,
               st.emitted_power_w_per_hz);
        assert_true(fabs(st.fired_power_w_per_hz - expected) <= tol);
        assert_true(tol < 0.05 * fabs(expected));
        assert_true(st.atmosphere_power_w_per_hz < 0.0); /* negative photons, absorbed */
        assert_balance(&st, fabs(expected));
        /* Physical P_A: nothing for the non-emitting air, the air's own for the other;
         * what it is does not depend on T0: the same as a T0 = 0 map's, where the sources
         * are the physical ones (the air's deviation source counted instead of its own, a
         * mutant, passed every test: a deviation-map run's summary.json then reported
         * 4 pi alpha (Bbar(T_air) - Bbar(T0)) V for the air, 0.27 pW/Hz low here) */
        if (!emitting)
            assert_true(st.emitted_power_w_per_hz > 0.0); /* the walls */
        photon_map *map0;
        photon_stats st0;
        fire(s, 0.0, 2, &map0, &st0);
        printf("# %s air: P_A %.9e W/Hz at T0 = %g K, %.9e at T0 = 0\n",
               emitting ? "emitting" : "absorbing", st.emitted_power_w_per_hz, t0,
               st0.emitted_power_w_per_hz);
        assert_true(fabs(st.emitted_power_w_per_hz / st0.emitted_power_w_per_hz - 1.0) < 1e-9);
        photon_map_destroy(map0);
        photon_map_destroy(map);
        scene_destroy(s);
    }
}

/* An open scene without atmosphere: the boundary (the widened bounding box, all open)
 * fires -B0 inwards, pi A_box Bbar(T0) in all; the plate at T0 fires nothing. */
static void test_open_boundary(void **state)
{
    (void)state;
    const double t0 = 290.0;
    uint64_t k = ps_scaled(100000);
    thz_scene *s = ps_scene(0.35, 0.1, k, 29);
    size_t grey = ps_material(s, 0.2, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plate = ps_object(s, OBJECT_SOLID, grey, t0, 0, true);
    ps_face(s, plate, v3(0, 0, 0), v3(0.2, 0, 0), v3(0, 0.2, 0));
    ps_finalize(s);
    double d = sqrt(0.4 * 0.4 + 0.4 * 0.4), w = 0.02 * d;
    double ax = 0.4 + w, az = w;
    double area = 2.0 * (ax * ax + 2.0 * ax * az);
    double expected = -M_PI * area * band_b(s, t0);
    photon_map *map;
    photon_stats st;
    fire(s, t0, 2, &map, &st);
    double phi = expected / (double)k; /* every photon carries about this */
    printf("# open boundary: fired %.6e W/Hz, expected %.6e; %zu records\n",
           st.fired_power_w_per_hz, expected, photon_map_count(map));
    assert_true(fabs(st.fired_power_w_per_hz - expected) <= 1e-3 * fabs(expected));
    assert_true(photon_map_count(map) > 0);
    const photon_record *rec = photon_map_records(map);
    for (size_t j = 0; j < photon_map_count(map); j++)
        assert_true(rec[j].power_w_per_hz < 0.0f && rec[j].power_w_per_hz > 2.0 * phi);
    assert_balance(&st, fabs(expected));
    assert_true(st.escaped_power_w_per_hz < 0.0);
    photon_map_destroy(map);
    scene_destroy(s);
}

/* The unpolarised Fresnel reflectance of air -> n + ik at cos(theta) = mu, written out
 * independently of fresnel.c. */
static double fresnel_r(double n, double k, double mu)
{
    double complex m = n + I * k, sin2 = 1.0 - mu * mu;
    double complex cos_t = csqrt(1.0 - sin2 / (m * m));
    double complex rs = (mu - m * cos_t) / (mu + m * cos_t);
    double complex rp = (m * mu - cos_t) / (m * mu + cos_t);
    return 0.5 * (cabs(rs) * cabs(rs) + cabs(rp) * cabs(rp));
}

/* Fires ps_scaled(200000) photons of channel 0 of s, every one of which hits a room,
 * with reference T0 on 2 threads; checks that every photon hit, that the fired power is
 * `expected` within 5 standard errors of the mean photon power (from the first hits), that
 * those are below max_rel of it, and the energy balance. Returns the moments. */
static power_moments fired_in_room(thz_scene *s, const accel *acc, double t0, double expected,
                                   double max_rel, const char *what)
{
    uint64_t photons = ps_scaled(200000);
    s->photons.per_channel = photons;
    photon_phase_options opt = {.threads = 2, .reference_temperature_k = t0};
    photon_map *map;
    photon_stats st;
    thz_error err;
    assert_int_equal(photon_phase_run(s, acc, 0, &opt, &map, &st, &err), THZ_OK);
    power_moments m = first_hits(map);
    double tol = five_sigma(&m, photons);
    printf("# %s: fired %.6e W/Hz, expected %.6e (tolerance %.2e); %zu negative and %zu "
           "positive photons\n",
           what, st.fired_power_w_per_hz, expected, tol, m.n_neg, m.n_pos);
    assert_int_equal(m.n_neg + m.n_pos, photons); /* every photon hits the room */
    assert_true(fabs(st.fired_power_w_per_hz - expected) <= tol);
    assert_true(tol < max_rel * fabs(expected));
    assert_balance(&st, m.sum_abs);
    photon_map_destroy(map);
    return m;
}

/* A one-sided 0.5 m cube of index 2 + 0.1i with an explicit emissivity 0.5, at 300 K, with
 * T0 = 100 K: two sources, eps B(T) and -A(mu) B0 with A = 1 - R(mu) (its back side,
 * inside, reaches no front face). Alone, the table holds those two (the cube once wrote a
 * third slot, its back side's, past a table of two per object); in a black room at T0
 * (no source there) the fired power is pi S (eps B(T) - A-bar B0), from the first hits. */
static void test_index_explicit_solid(void **state)
{
    (void)state;
    const double n = 2.0, k = 0.1, eps = 0.5, t_k = 300.0, t0 = 100.0, side = 0.5;
    static const char *room = "{\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
                              " \"temperature_k\": 100, \"shape\": {\"type\": \"box\","
                              " \"size_m\": [4, 4, 4], \"inward\": true}}, ";
    for (int with_room = 0; with_room < 2; with_room++) {
        char json[2000];
        snprintf(json, sizeof json,
                 "{\"format\": \"thzmap-scene/1\", \"name\": \"index-eps\","
                 " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.05}],"
                 " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
                 "   \"glass\": {\"refractive_index\": [%g, %g], \"emissivity\": %g}},"
                 " \"objects\": [%s{\"name\": \"cube\", \"type\": \"solid\","
                 "   \"material\": \"glass\", \"temperature_k\": %g,"
                 "   \"shape\": {\"type\": \"box\", \"size_m\": [%g, %g, %g]}}],"
                 " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -1.5, 0],"
                 "   \"look_at_m\": [0, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}],"
                 " \"photons\": {\"per_channel\": 1000, \"seed\": 3}}",
                 n, k, eps, with_room ? room : "", t_k, side, side, side);
        thz_scene *s;
        accel *acc;
        thz_error err;
        if (scene_load_string(json, ".", "index-eps", &s, &err) != THZ_OK)
            fail_msg("%s", err.message);
        if (accel_create(s, &acc, &err) != THZ_OK)
            fail_msg("%s", err.message);
        if (!with_room) {
            emission_table t;
            if (emission_table_init(&t, s, acc, 0, 1000, t0, NULL, &err) != THZ_OK)
                fail_msg("%s", err.message);
            assert_int_equal(t.n_sources, 2);
            assert_int_equal(t.sources[0].kind, EMISSION_EPS);
            assert_int_equal(t.sources[1].kind, EMISSION_ABSORB);
            emission_table_fini(&t);
            accel_destroy(acc);
            scene_destroy(s);
            continue;
        }
        /* A-bar = 2 int_0^1 (1 - R(mu)) mu dmu (Simpson) */
        const int steps = 20000;
        double h = 1.0 / steps, sum = 0.0;
        for (int i = 1; i <= steps; i++) {
            double mu = i * h, w = i == steps ? 1 : (i % 2 ? 4 : 2);
            sum += w * (1.0 - fresnel_r(n, k, mu)) * mu;
        }
        double abar = 2.0 * sum * h / 3.0;
        double area = 6.0 * side * side;
        double expected = M_PI * area * (eps * band_b(s, t_k) - abar * band_b(s, t0));
        printf("# index solid, explicit eps: A-bar %.4f\n", abar);
        /* a factor 2, a sign or the -A B0 source left out (-127 %) would fail */
        power_moments m = fired_in_room(s, acc, t0, expected, 0.1, "index solid, explicit eps");
        assert_true(m.n_neg > 0 && m.n_pos > 0);
        accel_destroy(acc);
        scene_destroy(s);
    }
}

/* (1 - R(nu)) B_nu(T0) of a material, for a band mean. */
typedef struct absorb_ctx {
    const thz_spectrum *reflectivity;
    double t0_k;
} absorb_ctx;

static double absorb_b0_at(double freq_hz, void *ctx)
{
    const absorb_ctx *c = ctx;
    return (1.0 - spectrum_eval(c->reflectivity, freq_hz)) * planck_radiance(freq_hz, c->t0_k);
}

/* A one-sided 0.5 m cube with an explicit emissivity 0.3, at 300 K, in a black room at
 * T0 = 100 K (no source there): one source eps B(T) - (1 - R) B0 (EMISSION_EPS_ABSORB).
 * Its reflectivity varies over the band (0.1, 0.5, 0.2 at 0.30, 0.35, 0.40 THz), so the
 * two terms change their ratio across it (the source without constant optics), or is a
 * constant 0.2 (the source with constant optics: its powers are weights fixed at the
 * table's set-up, eps pi S and A pi S). Fired power, from the first hits: pi S (eps Bbar(T)
 * - the band mean of (1 - R) B0). */
static void test_explicit_solid(void **state)
{
    (void)state;
    const double eps = 0.3, t_k = 300.0, t0 = 100.0, side = 0.5;
    static const char *const reflectivity[2] = {"[[0.30, 0.1], [0.35, 0.5], [0.40, 0.2]]", "0.2"};
    for (int grey = 0; grey < 2; grey++) {
        char json[1400];
        snprintf(json, sizeof json,
                 "{\"format\": \"thzmap-scene/1\", \"name\": \"explicit-eps\","
                 " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.1}],"
                 " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
                 "   \"tile\": {\"reflectivity\": %s, \"emissivity\": %g}},"
                 " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
                 "   \"temperature_k\": %g, \"shape\": {\"type\": \"box\", \"size_m\": [4, 4, 4],"
                 "   \"inward\": true}},"
                 "  {\"name\": \"cube\", \"type\": \"solid\", \"material\": \"tile\","
                 "   \"temperature_k\": %g, \"shape\": {\"type\": \"box\","
                 "   \"size_m\": [%g, %g, %g]}}],"
                 " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -1.5, 0],"
                 "   \"look_at_m\": [0, 0, 0], \"fov_deg\": 40, \"resolution\": [4, 4]}],"
                 " \"photons\": {\"per_channel\": 1000, \"seed\": 3}}",
                 reflectivity[grey], eps, t0, t_k, side, side, side);
        thz_scene *s;
        accel *acc;
        thz_error err;
        if (scene_load_string(json, ".", "explicit-eps", &s, &err) != THZ_OK)
            fail_msg("%s", err.message);
        if (accel_create(s, &acc, &err) != THZ_OK)
            fail_msg("%s", err.message);
        emission_table t;
        if (emission_table_init(&t, s, acc, 0, 1000, t0, NULL, &err) != THZ_OK)
            fail_msg("%s", err.message);
        assert_int_equal(t.n_sources, 1);
        assert_int_equal(t.sources[0].kind, EMISSION_EPS_ABSORB);
        assert_int_equal(t.sources[0].constant_optics, grey);
        emission_table_fini(&t);

        const thz_material *tile = &s->materials[s->objects[1].material];
        absorb_ctx ac = {.reflectivity = &tile->reflectivity, .t0_k = t0};
        double absorbed = channel_band_mean(&s->channels[0], absorb_b0_at, &ac);
        double area = 6.0 * side * side;
        double expected = M_PI * area * (eps * band_b(s, t_k) - absorbed);
        printf("# %s solid, explicit eps: (1 - R) B0 band mean %.4e W/(m^2 sr Hz)\n",
               grey ? "grey" : "spectral", absorbed);
        /* a factor 2, a sign (the grey one's -A B0 added: 11 x the power), or R taken at
         * the centre for the whole band (1 - R = 0.5 there; the band's (1 - R) B0 is 0.54
         * of its B0) would fail: the last moves the power 10 % */
        fired_in_room(s, acc, t0, expected, 0.05,
                      grey ? "grey solid, explicit eps" : "spectral solid, explicit eps");
        accel_destroy(acc);
        scene_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_furnace),        cmocka_unit_test(test_fired_power),
        cmocka_unit_test(test_explicit_shell), cmocka_unit_test(test_absorbing_air),
        cmocka_unit_test(test_open_boundary),  cmocka_unit_test(test_index_explicit_solid),
        cmocka_unit_test(test_explicit_solid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
