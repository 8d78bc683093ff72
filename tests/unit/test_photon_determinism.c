/* Photon phase determinism: the photon maps and statistics from 1 and 2 threads are
 * byte-identical (and equal to a repeated run, and to runs from a pool's memory); progress
 * reports batches on the calling thread and cancels. Also measures photons per second on
 * the box scene. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>
#include <omp.h>

#include "../physics/photon_scenes.h"
#include "accel/accel.h"
#include "photon/phase.h"

static void run_pooled(const thz_scene *s, const accel *acc, int threads, photon_map_pool *pool,
                       photon_map **map, photon_stats *st)
{
    photon_phase_options opt = {.threads = threads, .pool = pool};
    thz_error err;
    thz_status status = photon_phase_run(s, acc, 0, &opt, map, st, &err);
    if (status != THZ_OK)
        fail_msg("%s", err.message);
}

static void run(const thz_scene *s, const accel *acc, int threads, photon_map **map,
                photon_stats *st)
{
    run_pooled(s, acc, threads, NULL, map, st);
}

static void assert_same(const photon_map *a, const photon_stats *sa, const photon_map *b,
                        const photon_stats *sb)
{
    assert_int_equal(photon_map_count(a), photon_map_count(b));
    assert_memory_equal(photon_map_records(a), photon_map_records(b),
                        photon_map_count(a) * sizeof(photon_record));
    photon_stats x = *sa, y = *sb;
    x.seconds = y.seconds = 0.0;
    x.seconds_emission_table = y.seconds_emission_table = 0.0; /* wall times */
    x.seconds_tracing = y.seconds_tracing = 0.0;
    x.seconds_index = y.seconds_index = 0.0;
    assert_memory_equal(&x, &y, sizeof x);
}

static void test_threads_identical(void **state)
{
    (void)state;
    /* More than one batch, so the merge across batches is exercised too. */
    uint64_t k = ps_scaled(PHASE_BATCH + 30000);
    thz_scene *s = ps_box_scene(k, 42, 0.3);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    photon_map *m1, *m2, *m1b;
    photon_stats s1, s2, s1b;
    run(s, acc, 1, &m1, &s1);
    run(s, acc, 2, &m2, &s2);
    run(s, acc, 1, &m1b, &s1b);
    assert_int_equal(s1.fired, k);
    assert_int_equal(s1.stored, photon_map_count(m1));
    assert_true(s1.stored > k); /* the room reflects: more than one hit per photon */
    assert_true(s1.reflected > 0 && s1.transmitted > 0 && s1.back_face_hits > 0);
    assert_true(s1.atmosphere_power_w_per_hz > 0.0);
    assert_same(m1, &s1, m2, &s2);
    assert_same(m1, &s1, m1b, &s1b);
    printf("# box scene: %llu photons, %llu stored (%.2f per photon, %zu bytes each), "
           "%.0f photons/s on 1 thread, %.0f on 2\n",
           (unsigned long long)k, (unsigned long long)s1.stored, (double)s1.stored / (double)k,
           sizeof(photon_record), (double)k / s1.seconds, (double)k / s2.seconds);
    photon_map_destroy(m1);
    photon_map_destroy(m2);
    photon_map_destroy(m1b);
    accel_destroy(acc);
    scene_destroy(s);
}

/* A run's maps built in the memory of the maps before (photon_map_pool) are the maps
 * built without: the second run starts from the first's record array and codes (a
 * smaller scene's map, in fewer records), the third from the larger of the two. */
static void test_pool_reuses_memory(void **state)
{
    (void)state;
    uint64_t k = ps_scaled(PHASE_BATCH + 30000);
    thz_scene *s = ps_box_scene(k, 42, 0.3), *small = ps_box_scene(k / 3, 7, 0.3);
    accel *acc, *acc_small;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    assert_int_equal(accel_create(small, &acc_small, &err), THZ_OK);
    photon_map_pool pool = {0};
    photon_map *plain, *plain_small, *m;
    photon_stats sp, sp_small, sm;
    run(s, acc, 2, &plain, &sp);
    run(small, acc_small, 1, &plain_small, &sp_small);

    run_pooled(s, acc, 2, &pool, &m, &sm);
    assert_same(plain, &sp, m, &sm);
    assert_null(pool.records); /* the run took the spare (none yet) */
    assert_non_null(pool.scratch);
    assert_true(pool.scratch_capacity >= photon_map_scratch_records(photon_map_count(m)));
    const photon_record *first = photon_map_records(m);
    photon_map_recycle(m, &pool);
    assert_ptr_equal(pool.records, first);
    assert_true(pool.records_capacity >= sp.stored);

    run_pooled(small, acc_small, 1, &pool, &m, &sm); /* took the first run's array */
    assert_null(pool.records);
    assert_same(plain_small, &sp_small, m, &sm);
    photon_map_recycle(m, &pool);
    run_pooled(s, acc, 1, &pool, &m, &sm);
    assert_same(plain, &sp, m, &sm);
    photon_map_recycle(m, &pool);
    photon_map_recycle(NULL, &pool);
    photon_map_pool_fini(&pool);
    assert_null(pool.records);
    assert_null(pool.scratch);

    photon_map_destroy(plain);
    photon_map_destroy(plain_small);
    accel_destroy(acc);
    accel_destroy(acc_small);
    scene_destroy(s);
    scene_destroy(small);
}

typedef struct progress_log {
    int calls;
    int cancel_after;
    uint64_t last_done;
    int main_thread_ok;
    int bad;
    int build_questions; /* reports of done = K - 1: the index build asking for a stop */
} progress_log;

static int on_progress(void *user, const thz_progress *p)
{
    progress_log *log = user;
    log->calls++;
    /* the first report, done = 0, when the phase starts; then more each time, but for the
     * index build's questions, which repeat K - 1 (the stage's last unit still to come) */
    bool first_ok = log->calls == 1 && p->done == 0;
    bool build = p->done + 1 == p->total && log->last_done + 1 >= p->total;
    log->build_questions += p->done + 1 == p->total;
    if (strcmp(p->stage, "photons") != 0 || (p->done <= log->last_done && !first_ok && !build) ||
        p->done > p->total || p->channel != 0 || p->n_channels != 1)
        log->bad++;
    if (omp_in_parallel())
        log->main_thread_ok = 0;
    log->last_done = p->done;
    return log->cancel_after > 0 && log->calls >= log->cancel_after;
}

static void test_progress_and_cancel(void **state)
{
    (void)state;
    uint64_t k = 2 * PHASE_BATCH + 1000;
    thz_scene *s = ps_box_scene(k, 1, 0.0);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);

    /* Estimate before: stored records per photon times K times the record's bytes. */
    uint64_t bytes = 0;
    assert_int_equal(photon_phase_estimate_bytes(s, acc, 0, 0.0, NULL, &bytes, &err), THZ_OK);

    progress_log log = {.main_thread_ok = 1};
    photon_phase_options opt = {.threads = 2, .progress = on_progress, .progress_user = &log};
    photon_map *map = NULL;
    photon_stats st;
    assert_int_equal(photon_phase_run(s, acc, 0, &opt, &map, &st, &err), THZ_OK);
    /* the start, two batches, the index build's questions, the end */
    assert_true(log.build_questions >= 2);
    assert_int_equal(log.calls, 4 + log.build_questions);
    assert_int_equal(log.last_done, k);
    assert_int_equal(log.bad, 0);
    assert_true(log.main_thread_ok);
    double actual = (double)st.stored * sizeof(photon_record);
    assert_true(bytes > 0.9 * actual && bytes < 1.25 * actual);
    photon_map_destroy(map);

    log = (progress_log){.main_thread_ok = 1, .cancel_after = 1};
    map = NULL;
    assert_int_equal(photon_phase_run(s, acc, 0, &opt, &map, &st, &err), THZ_ERR_CANCELLED);
    assert_null(map);
    assert_int_equal(log.calls, 1);
    /* stopped by the index build's first question: cancelled, no map */
    log = (progress_log){.main_thread_ok = 1, .cancel_after = 4};
    assert_int_equal(photon_phase_run(s, acc, 0, &opt, &map, &st, &err), THZ_ERR_CANCELLED);
    assert_null(map);
    assert_int_equal(log.calls, 4);
    assert_int_equal(log.build_questions, 1);
    accel_destroy(acc);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_pool_reuses_memory),
        cmocka_unit_test(test_progress_and_cancel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
