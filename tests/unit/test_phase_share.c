/* A photon phase shared by processes (photon/phase.h; over MPI in src/mpi/), with the
 * processes played in one: a team whose members fire their shares when the lead
 * gathers. The lead's map and statistics must equal, byte for byte, those of one
 * process, for 2, 3 and 5 members (5 > the batches: some shares are empty), 1 and 2
 * threads, and a later photon pass (first_photon > 0); the shares tile the phase in
 * whole batches; a member with another seed refuses the lead's request. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../physics/photon_scenes.h"
#include "accel/accel.h"
#include "core/alloc.h"
#include "photon/phase.h"
#include "scene/scene_hash.h"

typedef struct fake_team {
    const thz_scene *scene;
    const accel *acc;
    size_t members;
    int threads;
    photon_phase_request rq;
    int starts;
} fake_team;

static thz_status fake_start(void *impl, const photon_phase_request *rq, thz_error *err)
{
    (void)err;
    fake_team *t = impl;
    t->rq = *rq;
    t->starts++;
    return THZ_OK;
}

/* What the MPI team does, in this process: append members 1.. n-1's shares. */
static thz_status fake_gather(void *impl, photon_phase_share *share, thz_error *err)
{
    fake_team *t = impl;
    for (size_t m = 1; m < t->members; m++) {
        photon_phase_share part;
        thz_status st = photon_phase_fire_share(t->scene, t->acc, &t->rq, t->threads, NULL, m,
                                                t->members, &part, err);
        if (st != THZ_OK)
            return st;
        share->records =
            thz_realloc_array(share->records, share->count + part.count + 1, sizeof(photon_record));
        share->chunks = thz_realloc_array(share->chunks, share->n_chunks + part.n_chunks + 1,
                                          sizeof(trace_counters));
        assert_non_null(share->records);
        assert_non_null(share->chunks);
        if (part.count)
            memcpy(share->records + share->count, part.records, part.count * sizeof(photon_record));
        if (part.n_chunks)
            memcpy(share->chunks + share->n_chunks, part.chunks,
                   part.n_chunks * sizeof(trace_counters));
        share->count += part.count;
        share->n_chunks += part.n_chunks;
        photon_phase_share_fini(&part);
    }
    return THZ_OK;
}

static void run(const thz_scene *s, const accel *acc, int threads, uint64_t first, fake_team *team,
                photon_map **map, photon_stats *st)
{
    photon_phase_team pt = {.start = fake_start, .gather = fake_gather, .impl = team};
    if (team)
        pt.members = team->members;
    photon_phase_options opt = {
        .threads = threads, .first_photon = first, .team = team ? &pt : NULL};
    thz_error err;
    if (photon_phase_run(s, acc, 0, &opt, map, st, &err) != THZ_OK)
        fail_msg("%s", err.message);
}

static void assert_same(const photon_map *a, const photon_stats *sa, const photon_map *b,
                        const photon_stats *sb)
{
    assert_int_equal(photon_map_count(a), photon_map_count(b));
    assert_memory_equal(photon_map_records(a), photon_map_records(b),
                        photon_map_count(a) * sizeof(photon_record));
    photon_stats x = *sa, y = *sb;
    x.seconds = y.seconds = 0.0; /* wall times */
    x.seconds_emission_table = y.seconds_emission_table = 0.0;
    x.seconds_tracing = y.seconds_tracing = 0.0;
    x.seconds_index = y.seconds_index = 0.0;
    assert_memory_equal(&x, &y, sizeof x);
}

static void test_shares_identical(void **state)
{
    (void)state;
    /* 4 batches, the last short; not scaled by THZ_TEST_SCALE: fewer than 5 batches would
     * leave ranks without a share and test no joining */
    uint64_t k = 3 * PHASE_BATCH + 12345;
    thz_scene *s = ps_box_scene(k, 7, 0.3);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    for (uint64_t first = 0; first <= k; first += k) { /* pass 0, then pass 1 */
        photon_map *alone;
        photon_stats sa;
        run(s, acc, 1, first, NULL, &alone, &sa);
        assert_int_equal(sa.fired, k);
        size_t members[] = {2, 3, 5};
        for (size_t i = 0; i < 3; i++) {
            for (int threads = 1; threads <= 2; threads++) {
                fake_team team = {
                    .scene = s, .acc = acc, .members = members[i], .threads = threads};
                photon_map *shared;
                photon_stats ss;
                run(s, acc, threads, first, &team, &shared, &ss);
                assert_int_equal(team.starts, 1);
                assert_same(alone, &sa, shared, &ss);
                photon_map_destroy(shared);
            }
        }
        photon_map_destroy(alone);
    }
    accel_destroy(acc);
    scene_destroy(s);
}

static void test_share_ranges(void **state)
{
    (void)state;
    uint64_t ks[] = {0, 1, PHASE_BATCH, PHASE_BATCH + 1, 7 * PHASE_BATCH + 5, 100 * PHASE_BATCH};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
        for (size_t n = 1; n <= 9; n++) {
            uint64_t next = 0, most = 0, least = UINT64_MAX;
            for (size_t m = 0; m < n; m++) {
                uint64_t lo, hi;
                photon_phase_share_range(ks[i], m, n, &lo, &hi);
                assert_int_equal(lo, next); /* contiguous, in member order */
                assert_true(hi >= lo && hi <= ks[i]);
                assert_true(lo % PHASE_BATCH == 0 || lo == hi); /* whole batches */
                uint64_t batches = (hi - lo + PHASE_BATCH - 1) / PHASE_BATCH;
                most = batches > most ? batches : most;
                least = batches < least ? batches : least;
                next = hi;
            }
            assert_int_equal(next, ks[i]); /* the whole phase */
            assert_true(most - least <= 1);
        }
    }
}

static void test_member_refuses_other_seed(void **state)
{
    (void)state;
    thz_scene *s = ps_box_scene(1000, 7, 0.0);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    photon_phase_request rq = {
        .channel = 0, .photons = 1000, .seed = 8, .scene_print = scene_hash_run(s, false)};
    photon_phase_share part;
    assert_int_equal(photon_phase_fire_share(s, acc, &rq, 1, NULL, 1, 2, &part, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "seed 7"));
    rq.seed = 7;
    rq.scene_print ^= 1; /* the lead's scene differs in anything else */
    assert_int_equal(photon_phase_fire_share(s, acc, &rq, 1, NULL, 1, 2, &part, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "scene differs from the lead's"));
    rq.scene_print ^= 1;
    assert_int_equal(photon_phase_fire_share(s, acc, &rq, 1, NULL, 1, 2, &part, &err), THZ_OK);
    assert_int_equal(part.n_chunks, 0); /* one batch: member 0's */
    photon_phase_share_fini(&part);
    accel_destroy(acc);
    scene_destroy(s);
}

/* The geometry's hash is kept in the scene's memo after its first computation: the kept
 * value, the value computed afresh (a shallow copy without the memo) and the values the
 * code before the memo gave this scene (photon-map files store them) are all the same; a
 * scene with other geometry gets its own. */
static void test_scene_hash_memo(void **state)
{
    (void)state;
    thz_scene *s = ps_box_scene(1000, 7, 0.0);
    scene_hash first, kept, fresh;
    scene_hash_compute(s, &first);
    scene_hash_compute(s, &kept);
    thz_scene copy = *s;
    copy.hash_memo = NULL;
    scene_hash_compute(&copy, &fresh);
    assert_int_equal(first.geometry, 0x866dd1ce38cbf0dbull);
    assert_int_equal(first.optics, 0xfedc6833368f995cull);
    assert_int_equal(first.channels, 0x52918b00c5097224ull);
    assert_int_equal(scene_hash_run(s, true), 0x4f72153e85a8e58aull);
    assert_int_equal(kept.geometry, first.geometry);
    assert_int_equal(fresh.geometry, first.geometry);
    thz_scene *other = ps_box_scene(1000, 7, 0.0);
    other->objects[0].mesh.positions[0] += 0.5f; /* before its first hash */
    scene_hash moved;
    scene_hash_compute(other, &moved);
    assert_true(moved.geometry != first.geometry);
    assert_int_equal(moved.optics, first.optics);
    scene_destroy(other);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shares_identical),
        cmocka_unit_test(test_share_ranges),
        cmocka_unit_test(test_member_refuses_other_seed),
        cmocka_unit_test(test_scene_hash_memo),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
