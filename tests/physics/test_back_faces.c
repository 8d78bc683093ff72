/* Back faces of one-sided solids in a deviation map (emission.h, docs/integrators.md
 * "The deviation photon map"): a back face leaves radiance 0, the deviation -B0, so it is
 * a source of -pi A B0 (Lambertian) in the map of L - B0.
 *
 *   photons: in an open scene a one-sided plate's back faces a second plate's front;
 *     the second's back faces nothing. Only the first back side gets a source (its reach
 *     share r in (0, 1)), each of its photons carries exactly -pi A B_nu(T0) / K at its
 *     own frequency (drawn r times as often as its power says, carrying 1 / r), and the
 *     photons' summed power is the band mean -pi A B0-bar within 5 standard errors of
 *     the photon count;
 *   rendering: a closed room at T0 with a warm one-sided plate whose back faces the far
 *     wall that the camera sees: final-gather (over the deviation map) agrees with path
 *     (the reference, many paths) pixel by pixel within IDENT_Z combined standard errors
 *     plus a bias allowance, as in test_integrators.c. Without the back faces' source
 *     the walls that see the plate's back miss R B0 times their view factor to it in
 *     the map, and final-gather was 1.7 % high here on average (2.3-2.9 % on the far
 *     wall beside the plate, z up to 8).
 */
#include "identity.h"

#include "photon/emission.h"
#include "photon/emission_reach.h"

#define OPEN_JSON                                                                                  \
    "{\"format\": \"thzmap-scene/1\", \"name\": \"open-backs\","                                   \
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"                         \
    " \"materials\": {\"grey\": {\"reflectivity\": 0.3}},"                                         \
    " \"objects\": ["                                                                              \
    "   {\"name\": \"front\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": "    \
    "293, \"shape\": {\"type\": \"rectangle\", \"size_m\": [1, 1]}},"                              \
    "   {\"name\": \"behind\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": "   \
    "293, \"shape\": {\"type\": \"rectangle\", \"size_m\": [1, 1]},"                               \
    "    \"transform\": {\"translate_m\": [0.3, 0, -0.8]}}],"                                      \
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, 0, 2], \"direction\": [0, 0, -1],"     \
    "   \"up\": [0, 1, 0], \"fov_deg\": 40, \"resolution\": [4, 4], \"aperture_m2\": 0.01}],"      \
    " \"photons\": {\"per_channel\": 100000, \"seed\": 7}}"

static void test_back_source_power(void **state)
{
    (void)state;
    thz_error err;
    thz_scene *s = NULL;
    assert_int_equal(scene_load_string(OPEN_JSON, ".", "open-backs", &s, &err), THZ_OK);
    accel *acc = NULL;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    const double t0 = 293.0; /* the plates' temperature: only their backs emit */
    uint64_t n = ident_photons(200000);
    emission_table t;
    assert_int_equal(emission_table_init(&t, s, acc, 0, n, t0, NULL, &err), THZ_OK);
    assert_int_equal(t.n_sources, 1);
    const emission_source *src = &t.sources[0];
    double area = s->objects[0].mesh.total_area_m2;
    print_message("back source of object %u: reach share %.4f\n", src->object, src->reach_share);
    assert_int_equal(src->kind, EMISSION_BACK);
    assert_int_equal(src->object, 0);
    assert_true(src->reach_share > 0.05 && src->reach_share < 0.95);

    double sum = 0.0, sum2 = 0.0;
    for (uint64_t i = 0; i < n; i++) {
        rng_stream rng;
        rng_init(&rng, 7, 0, RNG_PURPOSE_TEST, i);
        emission_photon e;
        assert_true(emission_sample(&t, &rng, &e));
        assert_int_equal(e.object, 0);
        assert_int_equal(e.side, 1);
        assert_true(e.dir.z < 0.0); /* into the back side's hemisphere (normal +z) */
        double x = e.power_w_per_hz * (double)n;
        double v = -M_PI * area * planck_radiance(e.freq_hz, t0);
        assert_true(fabs(x - v) <= 1e-12 * fabs(v));
        sum += x;
        sum2 += x * x;
    }
    double mean = sum / (double)n;
    double se = sqrt(fmax(sum2 / (double)n - mean * mean, 0.0) / (double)n);
    double expected = -M_PI * area * ident_band_planck(&s->channels[0], t0);
    print_message("fired %.6e W/Hz, expected %.6e (%.2f se)\n", mean, expected,
                  (mean - expected) / se);
    assert_true(fabs(mean - expected) <= 5.0 * se + 1e-9 * fabs(expected));
    emission_table_fini(&t);

    /* The paper's map (T0 = 0) has no back sources (and needs no ray caster). */
    for (size_t i = 0; i < s->n_objects; i++)
        s->objects[i].temperature_k = 0.0;
    assert_int_equal(emission_table_init(&t, s, NULL, 0, n, 0.0, NULL, &err), THZ_OK);
    assert_int_equal(t.n_sources, 0);
    emission_table_fini(&t);
    accel_destroy(acc);
    scene_destroy(s);
}

/* A closed room at T0 = 295 K and a warm one-sided plate facing the camera, its back
 * 0.5 m from the far wall. */
#define ROOM_JSON                                                                                  \
    "{\"format\": \"thzmap-scene/1\", \"name\": \"back-faces\","                                   \
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"                         \
    " \"materials\": {\"wall\": {\"reflectivity\": 0.5}, \"grey\": {\"reflectivity\": 0.3}},"      \
    " \"objects\": ["                                                                              \
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 295," \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"                \
    "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": "    \
    "%g, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.9, 0.9]},"                            \
    "    \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [0.3, 0.5, 0.1]}}],"         \
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0], \"direction\": [0, 1, 0],"   \
    "   \"up\": [0, 0, 1], \"fov_deg\": 80, \"resolution\": [16, 16], \"oversampling\": 1,"        \
    "   \"aperture_m2\": 0.01, \"normalize_to_k\": 295}],"                                         \
    " \"photons\": {\"per_channel\": 300000, \"seed\": 11}}"

static void cross_validate(double plate_k)
{
    char json[4096];
    snprintf(json, sizeof json, ROOM_JSON, plate_k);
    ident_run ref, r;
    ident_run_scene_with(&ref, json, 0, INTEGRATOR_PATH, ident_estimates(1024));
    ident_run_scene_with(&r, json, ident_photons(300000), INTEGRATOR_FINAL_GATHER,
                         ident_estimates(64));
    /* the plate faces the camera: its back faces the far wall */
    const float *nf = r.scene->objects[1].mesh.normals;
    assert_true(nf[1] < -0.99f);
    const double allowance = 0.005; /* final-gather's disk bias, as in test_integrators.c */
    size_t px = (size_t)r.img.columns * r.img.rows, n = 0, failed = 0;
    double sum_rel = 0.0, worst_z = 0.0;
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            if (!ident_pixel_interior(&r, col, row))
                continue;
            size_t i = ident_at(&r, 0, col, row);
            double l = r.img.radiance[i], l_ref = ref.img.radiance[i];
            double se = hypot(r.img.radiance_stderr[i], ref.img.radiance_stderr[i]);
            double z = (l - l_ref) / se;
            n++;
            sum_rel += (l - l_ref) / l_ref;
            if (fabs(z) > fabs(worst_z))
                worst_z = z;
            if (!(fabs(l - l_ref) <= IDENT_Z * se + allowance * l_ref)) {
                if (failed < 8)
                    print_message("pixel (%u, %u): L = %.5e, path %.5e (%+.3f %%, z = %.1f)\n", col,
                                  row, l, l_ref, 100.0 * (l - l_ref) / l_ref, z);
                failed++;
            }
        }
    double mean_rel = sum_rel / (double)n;
    print_message("plate at %g K: final-gather vs path over %zu interior of %zu pixels: mean "
                  "deviation %+.3f %%, worst z %.2f\n",
                  plate_k, n, px, 100.0 * mean_rel, worst_z);
    assert_true(n > px / 3);
    assert_int_equal(failed, 0);
    assert_true(fabs(mean_rel) <= allowance);
    ident_run_fini(&r);
    ident_run_fini(&ref);
}

static void test_cross_validation(void **state)
{
    (void)state;
    cross_validate(320.0); /* warm */
    cross_validate(250.0); /* cold */
}

/* A sleeve (a one-sided open cylinder, r = 0.1 m, h = 0.4 m, 64 segments: its back side is
 * inside) in a closed room (an inward box: its back side is outside). */
#define SLEEVE_JSON                                                                                \
    "{\"format\": \"thzmap-scene/1\", \"name\": \"sleeve\","                                       \
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"                         \
    " \"materials\": {\"grey\": {\"reflectivity\": 0.3}},"                                         \
    " \"objects\": ["                                                                              \
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 295," \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"                \
    "   {\"name\": \"sleeve\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": "   \
    "300, \"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.1, \"height_m\": 0.4,"               \
    "    \"caps\": false}, \"transform\": {\"translate_m\": [0, 0, -0.2]}}],"                      \
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0], \"direction\": [0, 1, 0],"   \
    "   \"up\": [0, 0, 1], \"fov_deg\": 40, \"resolution\": [4, 4], \"aperture_m2\": 0.01}],"      \
    " \"photons\": {\"per_channel\": 1000, \"seed\": 11}}"

typedef struct reach_calls {
    int calls, stop_at;
    uint64_t first_done, last_done, total;
} reach_calls;

static int reach_progress(void *user, const thz_progress *p)
{
    reach_calls *c = user;
    assert_string_equal(p->stage, "prepare");
    if (c->calls == 0)
        c->first_done = p->done;
    assert_true(p->done >= c->last_done); /* never backwards */
    c->last_done = p->done;
    c->total = p->total;
    return ++c->calls == c->stop_at;
}

/* The reach shares (emission_reach.h): the sleeve's inside reaches the room through its
 * ends alone. By reciprocity its share is 2 A_end (1 - F_ee) / A_wall, A_end the ends'
 * (64-gon) area, A_wall the inside's, F_ee the view factor between the two ends (coaxial
 * disks of radius r at distance h: (X - sqrt(X^2 - 4)) / 2, X = 2 + (h / r)^2); the room's
 * back side (outside) reaches nothing: exactly 0. The same shares on 1 and 2 threads, and
 * a stop asked between rounds. */
static void test_reach_shares(void **state)
{
    (void)state;
    thz_error err;
    thz_scene *s = NULL;
    assert_int_equal(scene_load_string(SLEEVE_JSON, ".", "sleeve", &s, &err), THZ_OK);
    accel *acc = NULL;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    assert_true(emission_reach_needed(s, 0) && emission_reach_needed(s, 1));
    emission_reach one = {0}, two = {0};
    reach_calls calls = {0};
    assert_int_equal(emission_reach_compute(&one, s, acc, 1, reach_progress, &calls, &err), THZ_OK);
    assert_true(one.done);
    assert_int_equal(calls.first_done, 0);
    assert_int_equal(calls.last_done, 2);
    assert_int_equal(calls.total, 2);
    assert_int_equal(emission_reach_compute(&two, s, acc, 2, NULL, NULL, &err), THZ_OK);
    assert_memory_equal(one.share, two.share, 2 * sizeof *one.share);

    const double r = 0.1, h = 0.4, n = 64.0;
    double a_end = 0.5 * n * r * r * sin(2.0 * M_PI / n);
    double a_wall = n * 2.0 * r * sin(M_PI / n) * h;
    double x = 2.0 + (h / r) * (h / r), f_ee = 0.5 * (x - sqrt(x * x - 4.0));
    double expected = 2.0 * a_end * (1.0 - f_ee) / a_wall;
    double se = sqrt(expected * (1.0 - expected) / EMISSION_REACH_RAYS);
    print_message("sleeve's reach share %.5f, expected %.5f (%.2f se)\n", one.share[1], expected,
                  (one.share[1] - expected) / se);
    assert_true(fabs(one.share[1] - expected) <= 4.0 * se + 0.002); /* + the 64-gon's F_ee */
    assert_true(one.share[0] == 0.0);

    /* computed once: a second call on a done set casts nothing and reports nothing */
    calls = (reach_calls){0};
    assert_int_equal(emission_reach_compute(&one, s, acc, 1, reach_progress, &calls, &err), THZ_OK);
    assert_int_equal(calls.calls, 0);

    /* a stop at the first report: cancelled, nothing kept */
    emission_reach stopped = {0};
    calls = (reach_calls){.stop_at = 1};
    assert_int_equal(emission_reach_compute(&stopped, s, acc, 2, reach_progress, &calls, &err),
                     THZ_ERR_CANCELLED);
    assert_false(stopped.done);
    assert_null(stopped.share);

    emission_reach_fini(&one);
    emission_reach_fini(&two);
    accel_destroy(acc);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_back_source_power),
        cmocka_unit_test(test_reach_shares),
        cmocka_unit_test(test_cross_validation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
