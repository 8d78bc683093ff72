/* Photon passes (photon_phase_options.first_photon, photon_map_merge): maps fired with
 * disjoint photon ranges merge into exactly the map of all their photons fired at once.
 * Pass p of K photons fires photons p K .. (p + 1) K - 1 with power P/K; merged, each
 * power is halved (a power of two: exact), so the merge of passes [0, K) and [K, 2K)
 * holds the same records, bit for bit, as one phase of 2 K photons; and the batches
 * follow the global photon index; the passes' statistics merged (photon_stats_merge, as
 * summary.json reports a run of passes) are the one phase's. Checked on the box scene (every kind
 * of surface, an attenuating atmosphere) with the paper's map and a deviation map. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon_scenes.h"

static int record_cmp(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(photon_record));
}

/* The map's records, sorted bytewise (the merge's order of equal spatial keys may
 * differ from a single phase's). */
static photon_record *sorted_records(const photon_map *map)
{
    size_t n = photon_map_count(map);
    photon_record *r = malloc((n ? n : 1) * sizeof *r);
    assert_non_null(r);
    memcpy(r, photon_map_records(map), n * sizeof *r);
    qsort(r, n, sizeof *r, record_cmp);
    return r;
}

static photon_map *fire_stats(thz_scene *s, const accel *acc, uint64_t k, uint64_t first,
                              double t0_k, photon_stats *st)
{
    thz_error err;
    s->photons.per_channel = k;
    photon_phase_options po = {
        .threads = 2, .reference_temperature_k = t0_k, .first_photon = first};
    photon_map *map = NULL;
    if (photon_phase_run(s, acc, 0, &po, &map, st, &err) != THZ_OK)
        fail_msg("%s", err.message);
    return map;
}

static photon_map *fire(thz_scene *s, const accel *acc, uint64_t k, uint64_t first, double t0_k)
{
    return fire_stats(s, acc, k, first, t0_k, NULL);
}

/* The merged statistics of two passes against those of one phase of all their photons:
 * counts equal, power sums equal to rounding (the passes' photons carry twice the power,
 * their merge the mean of the two). Powers summed rather than averaged (a mutant) passed
 * every test: summary.json's power balance of a run of n passes would read n times the
 * power fired. */
static void check_merged_stats(const photon_stats pass[2], const photon_stats *whole)
{
    photon_stats sum;
    photon_stats_merge(&sum, &pass[0], 1);
    photon_stats_merge(&sum, &pass[1], 2);
    assert_int_equal(sum.fired, whole->fired);
    assert_int_equal(sum.hits, whole->hits);
    assert_int_equal(sum.reflected, whole->reflected);
    assert_int_equal(sum.transmitted, whole->transmitted);
    assert_int_equal(sum.absorbed, whole->absorbed);
    assert_int_equal(sum.escaped, whole->escaped);
    assert_int_equal(sum.terminated, whole->terminated);
    assert_int_equal(sum.rays, whole->rays);
    assert_float_equal(sum.mean_bounces, whole->mean_bounces, 1e-12);
    const double scale = fabs(whole->absorbed_power_w_per_hz) +
                         fabs(whole->escaped_power_w_per_hz) +
                         fabs(whole->atmosphere_power_w_per_hz);
    assert_true(scale > 0.0);
    const double got[] = {sum.fired_power_w_per_hz, sum.absorbed_power_w_per_hz,
                          sum.escaped_power_w_per_hz, sum.atmosphere_power_w_per_hz,
                          sum.terminated_power_w_per_hz};
    const double want[] = {whole->fired_power_w_per_hz, whole->absorbed_power_w_per_hz,
                           whole->escaped_power_w_per_hz, whole->atmosphere_power_w_per_hz,
                           whole->terminated_power_w_per_hz};
    for (size_t i = 0; i < sizeof got / sizeof got[0]; i++) {
        printf("# power %zu: merged %.9e, one phase %.9e\n", i, got[i], want[i]);
        assert_true(fabs(got[i] - want[i]) <= 1e-9 * scale);
    }
}

static void merge_case(double t0_k)
{
    uint64_t k = 3 * PHASE_BATCH / 2 + 77; /* passes that end mid-batch */
    thz_scene *s = ps_box_scene(k, 11, 0.1);
    accel *acc;
    thz_error err;
    if (accel_create(s, &acc, &err) != THZ_OK)
        fail_msg("%s", err.message);
    photon_stats pass_stats[2], whole_stats;
    photon_map *passes[2] = {fire_stats(s, acc, k, 0, t0_k, &pass_stats[0]),
                             fire_stats(s, acc, k, k, t0_k, &pass_stats[1])};
    photon_map *whole = fire_stats(s, acc, 2 * k, 0, t0_k, &whole_stats);
    check_merged_stats(pass_stats, &whole_stats);
    photon_map *merged = NULL;
    assert_int_equal(photon_map_merge((const photon_map *const *)passes, 2, s->n_objects, 2, NULL,
                                      &merged, &err),
                     THZ_OK);
    size_t n = photon_map_count(whole);
    printf("# T0 = %.0f K: %zu + %zu records merged, %zu fired at once\n", t0_k,
           photon_map_count(passes[0]), photon_map_count(passes[1]), n);
    assert_true(n > k);
    assert_int_equal(photon_map_count(merged), n);
    assert_true(photon_map_reference_temperature_k(merged) == t0_k);
    assert_int_equal(photon_map_batches(merged), PHOTON_MAP_BATCHES);
    photon_record *a = sorted_records(merged), *b = sorted_records(whole);
    assert_memory_equal(a, b, n * sizeof *a);
    /* every batch is there, in about equal numbers */
    size_t per[PHOTON_MAP_BATCHES] = {0};
    for (size_t i = 0; i < n; i++)
        per[photon_batch(&a[i])]++;
    for (unsigned i = 0; i < PHOTON_MAP_BATCHES; i++)
        assert_true(fabs((double)per[i] - (double)n / PHOTON_MAP_BATCHES) <
                    6.0 * sqrt((double)n / PHOTON_MAP_BATCHES) +
                        0.02 * (double)n / PHOTON_MAP_BATCHES);
    free(a);
    free(b);
    photon_map_destroy(merged);
    photon_map_destroy(whole);
    photon_map_destroy(passes[0]);
    photon_map_destroy(passes[1]);
    accel_destroy(acc);
    scene_destroy(s);
}

static void test_merge_equals_one_phase(void **state)
{
    (void)state;
    merge_case(0.0);
    merge_case(295.0);
}

/* A merge through a pool (run_photon_passes' checks: the last merge recycled into it,
 * its array grown in place) is the merge without one, record for record in the same
 * order, for 1 and 2 threads; the pool's array is reused. */
static void test_merge_through_pool(void **state)
{
    (void)state;
    uint64_t k = PHASE_BATCH + 501;
    thz_scene *s = ps_box_scene(k, 7, 0.1);
    accel *acc;
    thz_error err;
    if (accel_create(s, &acc, &err) != THZ_OK)
        fail_msg("%s", err.message);
    photon_map *maps[3] = {fire(s, acc, k, 0, 0.0), fire(s, acc, k, k, 0.0),
                           fire(s, acc, k, 2 * k, 0.0)};
    const photon_map *const *m = (const photon_map *const *)maps;
    photon_map *plain = NULL;
    assert_int_equal(photon_map_merge(m, 3, s->n_objects, 2, NULL, &plain, &err), THZ_OK);
    size_t n = photon_map_count(plain);
    for (int threads = 1; threads <= 2; threads++) {
        photon_map_pool pool = {0};
        photon_map *first = NULL, *pooled = NULL;
        assert_int_equal(photon_map_merge(m, 2, s->n_objects, threads, &pool, &first, &err),
                         THZ_OK);
        const photon_record *kept = photon_map_records(first);
        photon_map_recycle(first, &pool); /* a smaller merge's array, to be grown */
        assert_ptr_equal(pool.records, kept);
        assert_int_equal(photon_map_merge(m, 3, s->n_objects, threads, &pool, &pooled, &err),
                         THZ_OK);
        assert_null(pool.records); /* taken */
        assert_int_equal(photon_map_count(pooled), n);
        assert_memory_equal(photon_map_records(pooled), photon_map_records(plain),
                            n * sizeof(photon_record));
        photon_map_destroy(pooled);
        photon_map_pool_fini(&pool);
    }
    photon_map_destroy(plain);
    for (int i = 0; i < 3; i++)
        photon_map_destroy(maps[i]);
    accel_destroy(acc);
    scene_destroy(s);
}

/* Maps of different reference temperatures do not merge. */
static void test_merge_refuses_mixed_t0(void **state)
{
    (void)state;
    thz_scene *s = ps_box_scene(2000, 3, 0.0);
    accel *acc;
    thz_error err;
    if (accel_create(s, &acc, &err) != THZ_OK)
        fail_msg("%s", err.message);
    photon_map *maps[2] = {fire(s, acc, 2000, 0, 0.0), fire(s, acc, 2000, 2000, 295.0)};
    photon_map *merged = NULL;
    assert_int_not_equal(
        photon_map_merge((const photon_map *const *)maps, 2, s->n_objects, 1, NULL, &merged, &err),
        THZ_OK);
    assert_null(merged);
    photon_map_destroy(maps[0]);
    photon_map_destroy(maps[1]);
    accel_destroy(acc);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merge_equals_one_phase),
        cmocka_unit_test(test_merge_through_pool),
        cmocka_unit_test(test_merge_refuses_mixed_t0),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
