/* photon/knn: the k-nearest search by radius queries gives photon_map_kth_distance2's
 * distance exactly, whatever its first guess, and its buffer holds exactly the photons
 * within that distance, seen side first; with the map's directory (photon_map.h) the
 * radius queries visit the same photons in the same order as without. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "core/rng.h"
#include "photon/knn.h"
#include "photon/photon_map.h"

/* n photons over n_objects objects, both sides, clustered in a 1 x 1 x 0.2 m slab, with
 * some exact duplicates of position (ties at the k-th distance). */
static photon_record *make_photons(size_t n, uint32_t n_objects)
{
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    rng_stream rng;
    rng_init(&rng, 5, 0, RNG_PURPOSE_TEST, 0);
    for (size_t i = 0; i < n; i++) {
        uint32_t obj = rng_next_u32(&rng) % n_objects, side = rng_next_u32(&rng) & 1u;
        float pos[3];
        for (int a = 0; a < 3; a++)
            pos[a] = (float)(rng_uniform(&rng) * (a == 2 ? 0.2 : 1.0));
        if (i % 9 == 4)
            for (int a = 0; a < 3; a++)
                pos[a] = p[i - 1].position_m[a];
        p[i] = (photon_record){.position_m = {pos[0], pos[1], pos[2]},
                               .power_w_per_hz = 1.0f,
                               .freq_hz = 1e12f,
                               .tag = photon_tag(obj, (int)side, 0, 0)};
    }
    return p;
}

/* The map of make_photons(n, n_objects) and its directory. */
static photon_map *make_map(size_t n, uint32_t n_objects, photon_map_directory **dir)
{
    photon_map *map = NULL;
    assert_int_equal(photon_map_create(make_photons(n, n_objects), n, n_objects, 0, &map, NULL),
                     THZ_OK);
    assert_int_equal(photon_map_directory_create(map, 2, dir, NULL), THZ_OK);
    return map;
}

static double dist2(const photon_record *r, vec3 q)
{
    double dx = (double)r->position_m[0] - q.x, dy = (double)r->position_m[1] - q.y,
           dz = (double)r->position_m[2] - q.z;
    return dx * dx + dy * dy + dz * dz;
}

static void test_knn_matches_kth_distance(void **state)
{
    (void)state;
    const size_t n = 20000;
    const uint32_t n_objects = 3;
    photon_map_directory *dir = NULL;
    photon_map *map = make_map(n, n_objects, &dir);
    const photon_record *r = photon_map_records(map);
    static knn_buffer b, b_dir; /* ~48 KiB each: not on the test's stack */
    static double scratch[KNN_CAP];
    static const size_t ks[] = {1, 2, 7, 64, 300, 1900, 5000, 20000};
    static const double areas[] = {1e-6, 1.0, 1e4}; /* bad first guesses too */
    rng_stream rng;
    rng_init(&rng, 6, 0, RNG_PURPOSE_TEST, 0);
    size_t settled = 0;
    for (int trial = 0; trial < 20; trial++) {
        vec3 q = v3(rng_uniform(&rng), rng_uniform(&rng), rng_uniform(&rng) * 0.2);
        uint32_t obj = (uint32_t)trial % n_objects;
        for (unsigned mask = 1; mask < 4; mask++) {
            int seen = mask == 2u ? 1 : 0;
            for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
                for (size_t ai = 0; ai < sizeof areas / sizeof areas[0]; ai++) {
                    size_t k = ks[ki];
                    double want = photon_map_kth_distance2(map, obj, mask, q, k);
                    double got =
                        knn_collect(map, NULL, obj, areas[ai], seen, mask, q, k, &b, scratch);
                    /* through the directory: the same distance, the same buffer */
                    double got_dir =
                        knn_collect(map, dir, obj, areas[ai], seen, mask, q, k, &b_dir, scratch);
                    assert_true(got_dir == got || (isnan(got) && isnan(got_dir)));
                    assert_int_equal(b_dir.n, b.n);
                    assert_int_equal(b_dir.total, b.total);
                    for (size_t i = 0; i < b.n; i++) {
                        assert_ptr_equal(b_dir.e[i].p, b.e[i].p);
                        assert_true(b_dir.e[i].d2 == b.e[i].d2);
                        assert_int_equal(b_dir.e[i].other_side, b.e[i].other_side);
                    }
                    if (isnan(got))
                        continue; /* did not settle: the caller falls back */
                    assert_true(got == want);
                    if (isinf(got))
                        continue;
                    settled++;
                    /* the buffer: every photon of those sides within got, once */
                    size_t inside = 0, expect = 0;
                    int other_seen = 0;
                    for (size_t i = 0; i < b.n; i++) {
                        assert_true(b.e[i].d2 == dist2(b.e[i].p, q));
                        inside += b.e[i].d2 <= got;
                        if (b.e[i].other_side)
                            other_seen = 1;
                        else
                            assert_false(other_seen); /* seen side first */
                    }
                    for (size_t i = 0; i < n; i++)
                        if (photon_object(&r[i]) == obj && (mask >> photon_side(&r[i]) & 1u) &&
                            dist2(&r[i], q) <= got)
                            expect++;
                    assert_int_equal(inside, expect);
                    assert_true(expect >= k);
                }
            }
        }
    }
    assert_true(settled > 300); /* the search settles for every k <= KNN_CAP */
    photon_map_directory_destroy(dir);
    photon_map_destroy(map);
}

/* A map of n photons of object 0, side 0, photon i at place(i): one object's layout. */
static photon_map *map_of_places(size_t n, uint64_t seed,
                                 void (*place)(size_t i, rng_stream *rng, float pos[3]))
{
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    rng_stream rng;
    rng_init(&rng, seed, 0, RNG_PURPOSE_TEST, 0);
    for (size_t i = 0; i < n; i++) {
        float pos[3];
        place(i, &rng, pos);
        p[i] = (photon_record){.position_m = {pos[0], pos[1], pos[2]},
                               .power_w_per_hz = 1.0f,
                               .freq_hz = 1e12f,
                               .tag = 0};
    }
    photon_map *map = NULL;
    assert_int_equal(photon_map_create(p, n, 1, 0, &map, NULL), THZ_OK);
    return map;
}

/* 1 000 photons at one point, 50 farther away along x. */
static void place_tie(size_t i, rng_stream *rng, float pos[3])
{
    pos[0] = i < 1000 ? 0.25f : (float)(0.5 + 0.5 * rng_uniform(rng));
    pos[1] = 0.5f;
    pos[2] = 0.1f;
}

/* Most distances equal (1 000 photons at one point, 50 farther away): the k-th
 * distance is still photon_map_kth_distance2's, for k inside the tie and just past it. */
static void test_knn_equal_distances(void **state)
{
    (void)state;
    photon_map *map = map_of_places(1050, 8, place_tie);
    static knn_buffer b;
    static double scratch[KNN_CAP];
    static const size_t ks[] = {1, 2, 500, 999, 1000, 1001, 1002, 1050};
    vec3 q = v3(0.2, 0.5, 0.1);
    const photon_record at = {.position_m = {0.25f, 0.5f, 0.1f}};
    const double tie = dist2(&at, q);
    for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
        double want = photon_map_kth_distance2(map, 0, 1u, q, ks[ki]);
        double got = knn_collect(map, NULL, 0, 1.0, 0, 1u, q, ks[ki], &b, scratch);
        assert_true(got == want);
        assert_true(ks[ki] > 1000 ? want > tie : want == tie);
    }
    photon_map_destroy(map);
}

/* Every visit of a radius query, in order. */
typedef struct visits {
    const photon_record **p;
    size_t n, cap;
} visits;

static void record_visit(void *ctx, const photon_record *p, double d2)
{
    (void)d2;
    visits *v = ctx;
    if (v->n < v->cap)
        v->p[v->n] = p;
    v->n++;
}

/* A map large enough for directories of several levels (50 000 records per group):
 * radius queries of every size, through the directory and without, visit the same
 * records in the same order; and the directory's bytes are a small part of the map's. */
static void test_directory_same_visits(void **state)
{
    (void)state;
    const size_t n = 300000;
    const uint32_t n_objects = 3;
    photon_map_directory *dir = NULL;
    photon_map *map = make_map(n, n_objects, &dir);
    size_t dir_bytes = photon_map_directory_bytes(dir), map_bytes = photon_map_bytes(map);
    print_message("directory %zu bytes for a map of %zu (%.2f %%)\n", dir_bytes, map_bytes,
                  100.0 * (double)dir_bytes / (double)map_bytes);
    /* each of the 6 groups (~50 000 records) indexed at level 4: 8^4 cells of about 12 */
    assert_true(dir_bytes >= 6 * (4096 + 1) * sizeof(uint32_t));
    assert_true(dir_bytes < n);              /* under a byte a record (photon_map_layout.h) */
    assert_true(dir_bytes * 20 < map_bytes); /* a small part of the map */
    const photon_record *a[4096], *b[4096];
    visits va = {a, 0, 4096}, vb = {b, 0, 4096};
    rng_stream rng;
    rng_init(&rng, 7, 0, RNG_PURPOSE_TEST, 0);
    size_t visited = 0;
    for (int trial = 0; trial < 400; trial++) {
        vec3 q = v3(rng_uniform(&rng) * 1.2 - 0.1, rng_uniform(&rng) * 1.2 - 0.1,
                    rng_uniform(&rng) * 0.3 - 0.05);
        double r = 1e-4 * pow(2.0, 10.0 * rng_uniform(&rng)); /* 0.1 mm to 10 cm */
        uint32_t obj = (uint32_t)trial % n_objects;
        int side = trial / n_objects % 2;
        va.n = vb.n = 0;
        photon_map_radius(map, obj, side, q, r * r, record_visit, &va);
        photon_map_radius_in(map, dir, obj, side, q, r * r, record_visit, &vb);
        assert_int_equal(va.n, vb.n);
        for (size_t i = 0; i < va.n && i < va.cap; i++)
            assert_ptr_equal(a[i], b[i]);
        visited += va.n;
    }
    assert_true(visited > 10000);
    photon_map_directory_destroy(dir);
    photon_map_destroy(map);
}

/* 1 km from the origin, spread over 0.1 m. */
static void place_far(size_t i, rng_stream *rng, float pos[3])
{
    (void)i;
    for (int a = 0; a < 3; a++)
        pos[a] = (float)(1000.0 + 0.1 * rng_uniform(rng));
}

/* Radii through a photon exactly, far from the origin (where float positions are coarse):
 * a radius query visits exactly the records whose distance in double is within it, the
 * one on the boundary included (its leaf scan tests floats first, with a bound). */
static void test_radius_boundary(void **state)
{
    (void)state;
    const size_t n = 4000;
    photon_map *map = map_of_places(n, 9, place_far);
    rng_stream rng;
    rng_init(&rng, 10, 0, RNG_PURPOSE_TEST, 0);
    const photon_record *r = photon_map_records(map);
    static const photon_record *seen[4000];
    visits v = {seen, 0, 4000};
    size_t on_boundary = 0;
    for (int trial = 0; trial < 200; trial++) {
        vec3 q = v3(1000.0 + 0.1 * rng_uniform(&rng), 1000.0 + 0.1 * rng_uniform(&rng),
                    1000.0 + 0.1 * rng_uniform(&rng));
        const photon_record *through = &r[rng_next_u32(&rng) % n];
        double r2 = dist2(through, q);
        size_t expect = 0;
        for (size_t i = 0; i < n; i++)
            expect += dist2(&r[i], q) <= r2;
        v.n = 0;
        photon_map_radius(map, 0, 0, q, r2, record_visit, &v);
        assert_int_equal(v.n, expect);
        for (size_t i = 0; i < v.n; i++) {
            assert_true(dist2(v.p[i], q) <= r2);
            on_boundary += v.p[i] == through;
        }
    }
    assert_int_equal(on_boundary, 200);
    photon_map_destroy(map);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_knn_matches_kth_distance), cmocka_unit_test(test_knn_equal_distances),
        cmocka_unit_test(test_directory_same_visits), cmocka_unit_test(test_radius_boundary)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
