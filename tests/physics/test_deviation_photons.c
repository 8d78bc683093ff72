/* Deviation photon maps (phase.h, photon_map.h "Reference temperature"): with T0 > 0
 * the photon phase fires the map of L - B_nu(T0), whose sources are signed. This file
 * pins the map's bytes; test_deviation_power.c checks the power each source fires.
 *
 * - T0 = 0 reproduces the paper's map bit for bit: checksums of records and statistics
 *   of three scenes (closed with a non-emitting atmosphere, open with an emitting one
 *   with and without extent) stored from the code before deviation maps existed.
 * - Determinism across 1 and 2 threads with T0 > 0.
 * - The memory estimate's pilot predicts a deviation map's size as well as the paper's.
 */
#include "deviation_photons.h"
#include "physics/spectrum.h"

/* The box scene plus explicit-emissivity objects (a solid with eps 0.5 < 1 - R and a
 * shell with eps 0.3) and a solid whose reflectivity varies over the band. Without the
 * room (room = false) the scene is open. */
static thz_scene *mixed_scene(uint64_t photons, uint64_t seed, bool room, double atm_per_m)
{
    thz_scene *s = ps_box_scene(photons, seed, atm_per_m);
    if (!room) { /* object 0 is the room: shrink it to a 2 mm speck at the origin */
        thz_mesh *m = &s->objects[0].mesh;
        for (size_t i = 0; i < 3 * m->n_vertices; i++)
            m->positions[i] *= 1e-3f;
    }
    size_t grey = ps_material(s, 0.2, 0.0, 0.5, TRANSMISSION_DIFFUSE);
    size_t veil = ps_material(s, 0.1, 50.0, 0.3, TRANSMISSION_DIFFUSE);
    size_t tile = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    double f[3] = {0.30e12, 0.35e12, 0.40e12}, r[3] = {0.1, 0.4, 0.2};
    ps_check(spectrum_set_table(&s->materials[tile].reflectivity, 3, f, r));
    size_t a = ps_object(s, OBJECT_SOLID, grey, 305, 0, true);
    ps_face(s, a, v3(-0.6, -0.6, 1.5), v3(0.2, 0, 0), v3(0, 0.2, 0));
    size_t b = ps_object(s, OBJECT_SHELL, veil, 285, 1e-3, true);
    ps_face(s, b, v3(0.6, 0.6, 1.0), v3(0.2, 0, 0), v3(0, 0, 0.2));
    size_t c = ps_object(s, OBJECT_SOLID, tile, 315, 0, false);
    ps_face(s, c, v3(-0.6, 0.0, 1.0), v3(0, 0.2, 0), v3(0, 0, 0.2));
    ps_finalize(s);
    return s;
}

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++) {
        h ^= c[i];
        h *= 1099511628211ull;
    }
    return h;
}

/* Checksum of the records and of every reproducible statistic. */
static uint64_t map_checksum(const photon_map *map, const photon_stats *st)
{
    /* without the batch bits, which the records gained after these sums were taken */
    size_t n = photon_map_count(map);
    photon_record *r = malloc((n ? n : 1) * sizeof *r);
    assert_non_null(r);
    memcpy(r, photon_map_records(map), n * sizeof *r);
    for (size_t i = 0; i < n; i++) {
        assert_true(photon_batch(&r[i]) < PHOTON_MAP_BATCHES);
        r[i].tag &= ~(PHOTON_MAP_BATCHES - 1u);
    }
    uint64_t h = fnv(1469598103934665603ull, r, n * sizeof *r);
    free(r);
    uint64_t u[] = {st->fired,       st->stored,        st->hits,    st->reflected,
                    st->transmitted, st->absorbed,      st->escaped, st->back_face_hits,
                    st->terminated,  st->bounce_capped, st->rays};
    double d[] = {st->emitted_power_w_per_hz,
                  st->absorbed_power_w_per_hz,
                  st->escaped_power_w_per_hz,
                  st->atmosphere_power_w_per_hz,
                  st->mean_bounces,
                  st->fired_power_w_per_hz,
                  st->terminated_power_w_per_hz};
    h = fnv(h, u, sizeof u);
    return fnv(h, d, sizeof d);
}

/* The three scenes of the checksums. */
static thz_scene *checksum_scene(int which)
{
    thz_error err;
    if (which == 0)
        return mixed_scene(20000, 42, true, 0.3);
    thz_scene *s = mixed_scene(20000, 43 + (uint64_t)which, false, 0.1);
    ps_check(atmosphere_set_emitting(&s->atmosphere, 290, 50, &err) == THZ_OK);
    if (which == 1) {
        double lo[3] = {-1.5, -1.5, -0.5}, hi[3] = {1.5, 1.5, 3.0};
        ps_check(atmosphere_set_extent(&s->atmosphere, lo, hi, &err) == THZ_OK);
    }
    return s;
}

/* Stored from the code before deviation maps (commit 04bc2fc), Release and Debug +
 * sanitizer builds alike (x86-64, glibc); stored again when the photon phase's random
 * streams changed to 32-bit uniforms (issue 19, docs/physics.md "Random streams"), and
 * when the directions' and Box-Muller's cos, sin and log stopped calling libm (issue 19:
 * the same streams, last-bit differences; scene 0 only), and when the record became 28
 * bytes (its tag holds a first-hit bit where the bounce count was; a checksum of the
 * records' 24 bytes, groups, first-hit bits and batches, taken by both codes, was the
 * same), and when a hit's point and distance came from thzmap's own double arithmetic
 * rather than Embree's (accel.c: Embree's differ in the last bits between instruction sets
 * and between processors: an AMD machine's SSE4.2 kernels gave other checksums than the
 * Intel machine's they were stored on), and when a ray's origin offset became the hit's
 * own (accel.c: it was one distance for the whole scene). They pin the streams and the
 * arithmetic as well as
 * the T0 = 0 path, and are checked with Embree's SSE4.2 kernels and with its widest
 * (AVX-512 where the machine has it), whose approximate reciprocals differ most. */
static const uint64_t t0_zero_checksums[3] = {0x0f2795a1a544b288ull, 0xf0c81d65fcc31a9bull,
                                              0x3aa36a7fa7077138ull};

static void test_t0_zero_checksums(void **state)
{
    (void)state;
    static const char *const isas[] = {"sse4.2", "avx512"};
    for (size_t i = 0; i < sizeof isas / sizeof isas[0]; i++) {
        assert_int_equal(setenv("THZMAP_EMBREE_MAX_ISA", isas[i], 1), 0);
        for (int w = 0; w < 3; w++) {
            thz_scene *s = checksum_scene(w);
            photon_map *map;
            photon_stats st;
            fire(s, 0.0, 2, &map, &st);
            uint64_t h = map_checksum(map, &st);
            printf("# %s, scene %d: %zu records, checksum 0x%016llx (expected 0x%016llx)\n",
                   isas[i], w, photon_map_count(map), (unsigned long long)h,
                   (unsigned long long)t0_zero_checksums[w]);
            assert_true(h == t0_zero_checksums[w]);
            assert_true(photon_map_reference_temperature_k(map) == 0.0);
            assert_true(st.reference_temperature_k == 0.0);
            photon_map_destroy(map);
            scene_destroy(s);
        }
    }
    unsetenv("THZMAP_EMBREE_MAX_ISA");
}

/* T0 > 0: the map and statistics are byte-identical for 1 and 2 threads (every source
 * class: surfaces of every kind, an emitting atmosphere and an open boundary). */
static void test_threads_identical(void **state)
{
    (void)state;
    thz_scene *s = checksum_scene(2);
    s->photons.per_channel = PHASE_BATCH + 5000;
    photon_map *m1, *m2;
    photon_stats s1, s2;
    fire(s, 300.0, 1, &m1, &s1);
    fire(s, 300.0, 2, &m2, &s2);
    assert_int_equal(photon_map_count(m1), photon_map_count(m2));
    assert_memory_equal(photon_map_records(m1), photon_map_records(m2),
                        photon_map_count(m1) * sizeof(photon_record));
    assert_true(map_checksum(m1, &s1) == map_checksum(m2, &s2));
    size_t neg = 0;
    const photon_record *r = photon_map_records(m1);
    for (size_t i = 0; i < photon_map_count(m1); i++)
        neg += r[i].power_w_per_hz < 0.0f;
    printf("# %zu records, %zu negative\n", photon_map_count(m1), neg);
    assert_true(neg > 0 && neg < photon_map_count(m1));
    photon_map_destroy(m1);
    photon_map_destroy(m2);
    scene_destroy(s);
}

/* The memory estimate's pilot fires the same kind of map: a deviation map stores a
 * different number of hits per photon than the paper's (its sources are other objects). */
static void test_estimate_bytes(void **state)
{
    (void)state;
    thz_scene *s = mixed_scene(200000, 5, true, 0.0);
    accel *acc;
    thz_error err;
    if (accel_create(s, &acc, &err) != THZ_OK)
        fail_msg("%s", err.message);
    for (int t = 0; t < 2; t++) {
        double t0_k = t == 0 ? 0.0 : 295.0;
        uint64_t bytes = 0;
        assert_int_equal(photon_phase_estimate_bytes(s, acc, 0, t0_k, NULL, &bytes, &err), THZ_OK);
        photon_phase_options opt = {.threads = 2, .reference_temperature_k = t0_k};
        photon_map *map = NULL;
        photon_stats st;
        assert_int_equal(photon_phase_run(s, acc, 0, &opt, &map, &st, &err), THZ_OK);
        double actual = (double)st.stored * sizeof(photon_record);
        printf("# T0 = %.0f K: estimated %.0f bytes, stored %.0f (%.3f hits per photon)\n", t0_k,
               (double)bytes, actual, (double)st.stored / (double)st.fired);
        /* the pilot's 4096 photons: a few % of statistical error, times 1.05 */
        assert_true(bytes > 0.95 * actual && bytes < 1.2 * actual);
        photon_map_destroy(map);
    }
    accel_destroy(acc);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_t0_zero_checksums),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_estimate_bytes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
