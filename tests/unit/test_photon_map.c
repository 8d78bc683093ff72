/* Photon map: octahedral directions, radius and k-nearest queries against brute
 * force, and byte-identical builds for any thread count and input order. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/rng.h"
#include "photon/photon_map.h"

static double test_scale(void)
{
    const char *s = getenv("THZ_TEST_SCALE");
    double v = s ? atof(s) : 1.0;
    return (v > 0.0 && v <= 1.0) ? v : 1.0;
}

static double angle_between(vec3 a, vec3 b)
{
    return atan2(v3_length(v3_cross(a, b)), v3_dot(a, b));
}

static double check_direction(vec3 d)
{
    d = v3_normalize(d);
    vec3 back = photon_decode_direction(photon_encode_direction(d));
    assert_true(fabs(v3_length(back) - 1.0) < 1e-12);
    return angle_between(d, back);
}

static void test_directions(void **state)
{
    (void)state;
    double worst = 0.0;
    /* poles, axes, the z = 0 seam, octant diagonals, signed zeros */
    static const double special[][3] = {
        {0, 0, 1},          {0, 0, -1},   {1, 0, 0},        {-1, 0, 0},        {0, 1, 0},
        {0, -1, 0},         {1, 1, 0},    {-1, 1, 0},       {1, -1, 0},        {-1, -1, 0},
        {1, 1, 1},          {-1, -1, -1}, {1, 1, -1},       {0, 1, -1},        {1, 0, -1},
        {-0.0, -0.0, -1},   {-0.0, 0, 1}, {1e-9, 1e-9, -1}, {-1e-9, 1e-9, -1}, {0.6, 0.8, -1e-12},
        {0.6, -0.8, 1e-12},
    };
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++) {
        double e = check_direction(v3(special[i][0], special[i][1], special[i][2]));
        worst = e > worst ? e : worst;
    }
    rng_stream rng;
    rng_init(&rng, 3, 0, RNG_PURPOSE_TEST, 0);
    const size_t n = (size_t)(400000 * test_scale());
    for (size_t i = 0; i < n; i++) {
        double z = 2.0 * rng_uniform(&rng) - 1.0, phi = 2.0 * M_PI * rng_uniform(&rng);
        if (i % 4 == 1)
            z = 1e-3 * (2.0 * rng_uniform(&rng) - 1.0); /* near the seam */
        else if (i % 4 == 2)
            z = copysign(1.0 - 1e-6 * rng_uniform(&rng), z); /* near the poles */
        double s = sqrt(fmax(0.0, 1.0 - z * z));
        double e = check_direction(v3(s * cos(phi), s * sin(phi), z));
        worst = e > worst ? e : worst;
    }
    print_message("octahedral round trip: worst angular error %.3g rad\n", worst);
    assert_true(worst < 1e-4);
    /* the zero vector does not crash and decodes to a unit vector */
    assert_true(fabs(v3_length(photon_decode_direction(photon_encode_direction(v3(0, 0, 0)))) -
                     1.0) < 1e-12);
}

/* Random photons over n_objects objects: clustered positions, exact coordinate
 * duplicates, fully identical records, a coplanar group and empty groups. */
static photon_record *make_photons(size_t n, size_t n_objects, uint64_t stream)
{
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    rng_stream rng;
    rng_init(&rng, 11, 0, RNG_PURPOSE_TEST, stream);
    for (size_t i = 0; i < n; i++) {
        uint32_t obj = rng_next_u32(&rng) % (uint32_t)n_objects;
        uint32_t side = rng_next_u32(&rng) & 1u;
        if (obj == 2)
            side = 0; /* object 2 has no back-side photons */
        if (obj == 3)
            obj = 1; /* object 3 has none at all */
        float pos[3];
        for (int a = 0; a < 3; a++)
            pos[a] = (float)(rng_uniform(&rng) * (a == 2 ? 0.2 : 1.0));
        if (obj == 1 && side == 0)
            pos[2] = 0.5f;         /* coplanar */
        if (i % 7 == 3 && i > 0) { /* same position as the previous photon */
            memcpy(pos, p[i - 1].position_m, sizeof pos);
        }
        p[i] = (photon_record){
            .position_m = {pos[0], pos[1], pos[2]},
            .power_w_per_hz = (float)i,
            .freq_hz = 1e12f,
            .dir_oct = rng_next_u32(&rng),
            .tag = photon_tag(obj, (int)side, i % 5 == 0, (unsigned)(i % 3)),
        };
        if (i % 11 == 5 && i > 0 && photon_object(&p[i - 1]) != 3)
            p[i] = p[i - 1]; /* fully identical record */
    }
    return p;
}

typedef struct visit_log {
    const photon_record *base;
    unsigned char *seen;
    size_t visits;
    int bad;
    vec3 q;
} visit_log;

static void log_visit(void *ctx, const photon_record *p, double d2)
{
    visit_log *v = ctx;
    size_t i = (size_t)(p - v->base);
    double dx = (double)p->position_m[0] - v->q.x, dy = (double)p->position_m[1] - v->q.y,
           dz = (double)p->position_m[2] - v->q.z;
    if (v->seen[i] || d2 != dx * dx + dy * dy + dz * dz)
        v->bad = 1;
    v->seen[i] = 1;
    v->visits++;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void test_queries_vs_brute_force(void **state)
{
    (void)state;
    const size_t n = 6000, n_objects = 5;
    photon_record *in = make_photons(n, n_objects, 1);
    photon_map *map = NULL;
    thz_error err;
    assert_int_equal(photon_map_create(in, n, n_objects, 0, &map, &err), THZ_OK);
    assert_int_equal(photon_map_count(map), n);
    const photon_record *r = photon_map_records(map);
    unsigned char *seen = calloc(n, 1);
    double *d2s = malloc(n * sizeof *d2s);
    assert_non_null(seen);
    assert_non_null(d2s);
    rng_stream rng;
    rng_init(&rng, 12, 0, RNG_PURPOSE_TEST, 0);
    static const double radii[] = {0.0, 0.01, 0.05, 0.2, 2.0};
    static const size_t ks[] = {1, 2, 7, 50, 256, 257, 400, 5000};
    for (int trial = 0; trial < 60; trial++) {
        vec3 q = v3(rng_uniform(&rng) * 1.2 - 0.1, rng_uniform(&rng) * 1.2 - 0.1,
                    rng_uniform(&rng) * 0.6 - 0.1);
        if (trial % 5 == 0) /* exactly on a stored photon */
            q = v3(r[trial * 37].position_m[0], r[trial * 37].position_m[1],
                   r[trial * 37].position_m[2]);
        for (uint32_t obj = 0; obj < n_objects + 1; obj++) {
            for (int side = 0; side < 2; side++) {
                for (size_t ri = 0; ri < sizeof radii / sizeof radii[0]; ri++) {
                    double r2 = radii[ri] * radii[ri];
                    memset(seen, 0, n);
                    visit_log v = {r, seen, 0, 0, q};
                    photon_map_radius(map, obj, side, q, r2, log_visit, &v);
                    assert_false(v.bad);
                    size_t expect = 0;
                    for (size_t i = 0; i < n; i++) {
                        if (photon_group(&r[i]) != (obj << 1 | (uint32_t)side))
                            continue;
                        double dx = (double)r[i].position_m[0] - q.x,
                               dy = (double)r[i].position_m[1] - q.y,
                               dz = (double)r[i].position_m[2] - q.z;
                        if (dx * dx + dy * dy + dz * dz <= r2) {
                            expect++;
                            assert_true(seen[i]);
                        }
                    }
                    assert_int_equal(v.visits, expect);
                }
            }
            for (unsigned mask = 0; mask < 4; mask++) {
                size_t m = 0;
                for (size_t i = 0; i < n; i++) {
                    if (photon_object(&r[i]) != obj || !(mask >> photon_side(&r[i]) & 1))
                        continue;
                    double dx = (double)r[i].position_m[0] - q.x,
                           dy = (double)r[i].position_m[1] - q.y,
                           dz = (double)r[i].position_m[2] - q.z;
                    d2s[m++] = dx * dx + dy * dy + dz * dz;
                }
                qsort(d2s, m, sizeof *d2s, cmp_double);
                for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
                    double got = photon_map_kth_distance2(map, obj, mask, q, ks[ki]);
                    if (ks[ki] > m)
                        assert_true(isinf(got) && got > 0);
                    else
                        assert_true(got == d2s[ks[ki] - 1]);
                }
            }
        }
    }
    /* a position that is not a number finds no photon: INFINITY, as too few photons
     * (the heap's top was read unwritten); k on the stack's heap and above it */
    for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++)
        assert_true(isinf(photon_map_kth_distance2(map, 0, 3u, v3(NAN, 0.5, 0.1), ks[ki])));
    free(seen);
    free(d2s);
    photon_map_destroy(map);
}

static int cmp_record(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(photon_record));
}

static void test_same_records_grouped(void **state)
{
    (void)state;
    const size_t n = 3000, n_objects = 5;
    photon_record *in = make_photons(n, n_objects, 2);
    photon_record *copy = malloc(n * sizeof *copy);
    assert_non_null(copy);
    for (size_t i = 0; i < n; i++)
        copy[i] = in[i];
    photon_map *map = NULL;
    assert_int_equal(photon_map_create(in, n, n_objects, 1, &map, NULL), THZ_OK);
    const photon_record *r = photon_map_records(map);
    photon_record *out = malloc(n * sizeof *out);
    assert_non_null(out);
    for (size_t i = 0; i < n; i++) {
        out[i] = r[i];
        /* grouped; first-hit bits and batches kept */
        if (i > 0)
            assert_true(photon_group(&r[i - 1]) <= photon_group(&r[i]));
    }
    qsort(out, n, sizeof *out, cmp_record);
    qsort(copy, n, sizeof *copy, cmp_record);
    assert_memory_equal(out, copy, n * sizeof *out);
    free(out);
    free(copy);
    photon_map_destroy(map);
}

static photon_map *build(const photon_record *src, size_t n, size_t n_objects, int threads,
                         int reverse)
{
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    for (size_t i = 0; i < n; i++)
        p[i] = src[reverse ? n - 1 - i : i];
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    photon_map *map = NULL;
    assert_int_equal(photon_map_create(p, n, n_objects, threads, &map, NULL), THZ_OK);
    return map;
}

static void test_deterministic(void **state)
{
    (void)state;
    /* big enough for the subtree tasks (8192) to run in parallel */
    const size_t n = (size_t)(120000 * test_scale()), n_objects = 5;
    photon_record *src = make_photons(n, n_objects, 3);
    photon_map *a = build(src, n, n_objects, 1, 0);
    photon_map *b = build(src, n, n_objects, 2, 0);
    photon_map *c = build(src, n, n_objects, 2, 1);
    assert_memory_equal(photon_map_records(a), photon_map_records(b), n * sizeof(photon_record));
    assert_memory_equal(photon_map_records(a), photon_map_records(c), n * sizeof(photon_record));
    photon_map_destroy(a);
    photon_map_destroy(b);
    photon_map_destroy(c);
    free(src);
}

static void noop_visit(void *ctx, const photon_record *p, double d2)
{
    (void)p;
    (void)d2;
    (*(int *)ctx)++;
}

/* Many groups, one of them larger than the build's split threshold (65536 records, so
 * its records go through the first-digit pass), positions on a coarse lattice or all on
 * one point (long runs of equal codes, told apart by their bytes), exact duplicates and
 * empty groups. */
static photon_record *make_crowded(size_t n, size_t n_objects)
{
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    rng_stream rng;
    rng_init(&rng, 13, 0, RNG_PURPOSE_TEST, 0);
    for (size_t i = 0; i < n; i++) {
        uint32_t u = rng_next_u32(&rng);
        uint32_t obj = u % 2 ? 0 : 1 + (u >> 1) % (uint32_t)(n_objects - 1);
        uint32_t side = obj == 0 ? 0 : (u >> 20) & 1u;
        if (obj == 7)
            obj = 8; /* object 7 has no photons */
        float pos[3];
        for (int a = 0; a < 3; a++) {
            double v = rng_uniform(&rng);
            if (obj % 3 == 1 || (obj == 0 && i % 4 == 0))
                v = floor(v * 8.0) / 8.0; /* a lattice: many records share a code */
            pos[a] = (float)(v * (a == 2 && obj == 0 ? 1e-3 : 2.0));
        }
        if (obj == 5) /* all on one point */
            pos[0] = pos[1] = pos[2] = 0.25f;
        p[i] = (photon_record){
            .position_m = {pos[0], pos[1], pos[2]},
            .power_w_per_hz = (float)(i % 1000),
            .freq_hz = 1e12f,
            .dir_oct = rng_next_u32(&rng) % 4u,
            .tag = photon_tag(obj, (int)side, i % 5 == 0, (unsigned)(i % 3)),
        };
        if (i % 13 == 6 && photon_object(&p[i - 1]) != 7)
            p[i] = p[i - 1]; /* fully identical record */
    }
    return p;
}

/* k-th nearest and radius counts of the big group against brute force. */
static void check_queries(const photon_map *map, size_t n, uint32_t obj)
{
    const photon_record *r = photon_map_records(map);
    double *d2s = malloc(n * sizeof *d2s);
    assert_non_null(d2s);
    rng_stream rng;
    rng_init(&rng, 14, 0, RNG_PURPOSE_TEST, 0);
    for (int trial = 0; trial < 12; trial++) {
        size_t at = (size_t)(rng_uniform(&rng) * (double)n);
        vec3 q = v3(r[at].position_m[0], r[at].position_m[1], r[at].position_m[2] + 1e-4 * trial);
        size_t m = 0;
        for (size_t i = 0; i < n; i++) {
            if (photon_group(&r[i]) != obj << 1)
                continue;
            double dx = (double)r[i].position_m[0] - q.x, dy = (double)r[i].position_m[1] - q.y,
                   dz = (double)r[i].position_m[2] - q.z;
            d2s[m++] = dx * dx + dy * dy + dz * dz;
        }
        qsort(d2s, m, sizeof *d2s, cmp_double);
        static const size_t ks[] = {1, 9, 100, 1000};
        for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
            if (ks[ki] > m)
                continue;
            assert_true(photon_map_kth_distance2(map, obj, 1u, q, ks[ki]) == d2s[ks[ki] - 1]);
            int visits = 0;
            photon_map_radius(map, obj, 0, q, d2s[ks[ki] - 1], noop_visit, &visits);
            size_t expect = ks[ki];
            while (expect < m && d2s[expect] <= d2s[ks[ki] - 1])
                expect++;
            assert_int_equal((size_t)visits, expect);
        }
    }
    free(d2s);
}

/* Byte-identical maps for 1, 2 and 3 threads, input reversed, and from a pool's reused
 * memory, on the crowded records; queries right on the largest group. */
static void test_deterministic_crowded(void **state)
{
    (void)state;
    /* at least 140000 at any scale: object 0's half must pass the split threshold */
    const size_t n = (size_t)(140000 + 160000 * test_scale()), n_objects = 40;
    photon_record *src = make_crowded(n, n_objects);
    photon_map *a = build(src, n, n_objects, 1, 0);
    size_t total = 0;
    for (uint32_t obj = 0; obj < n_objects; obj++)
        total += photon_map_object_count(a, obj, 3u);
    assert_int_equal(total, n);
    assert_int_equal(photon_map_object_count(a, 7, 3u), 0);
    assert_true(photon_map_object_count(a, 0, 1u) >= 65536); /* the build's split threshold */
    const photon_record *ra = photon_map_records(a);
    for (size_t i = 1; i < n; i++)
        assert_true(photon_group(&ra[i - 1]) <= photon_group(&ra[i]));
    check_queries(a, n, 0);
    for (int t = 2; t <= 3; t++) {
        photon_map *b = build(src, n, n_objects, t, t == 3);
        assert_memory_equal(ra, photon_map_records(b), n * sizeof(photon_record));
        photon_map_destroy(b);
    }
    photon_map_pool pool = {0};
    for (int round = 0; round < 2; round++) { /* the second reuses the first's scratch */
        photon_record *p = malloc(n * sizeof *p);
        assert_non_null(p);
        memcpy(p, src, n * sizeof *p);
        photon_map *c = NULL;
        assert_int_equal(photon_map_build(p, n, n, n_objects, 2, &pool, NULL, &c, NULL), THZ_OK);
        assert_memory_equal(ra, photon_map_records(c), n * sizeof(photon_record));
        /* 3/8 of the records: no key holds more here (three buckets) */
        assert_int_equal(pool.scratch_capacity, photon_map_scratch_records(n));
        photon_map_recycle(c, &pool);
    }
    photon_map_pool_fini(&pool);
    photon_map_destroy(a);
    free(src);
}

/* A build asks its cancel between passes: stopped at each of its questions in turn, it
 * returns THZ_ERR_CANCELLED (nothing leaked: the sanitizer build), and never stopped it
 * builds the same map as without one. */
static int stop_at;
static int asked;
static int stop_at_question(void *user)
{
    (void)user;
    return ++asked == stop_at;
}

static void test_cancel(void **state)
{
    (void)state;
    const size_t n = 140000, n_objects = 40; /* three buckets: five questions */
    photon_record *src = make_crowded(n, n_objects);
    photon_map *a = build(src, n, n_objects, 1, 0);
    cancel_check cancel = {stop_at_question, NULL};
    int questions = 0;
    for (stop_at = 1;; stop_at++) {
        asked = 0;
        photon_record *p = malloc(n * sizeof *p);
        assert_non_null(p);
        memcpy(p, src, n * sizeof *p);
        photon_map *c = NULL;
        thz_error err = {0};
        thz_status st = photon_map_build(p, n, n, n_objects, 2, NULL, &cancel, &c, &err);
        if (st == THZ_OK) {
            assert_memory_equal(photon_map_records(a), photon_map_records(c),
                                n * sizeof(photon_record));
            photon_map_destroy(c);
            break;
        }
        assert_int_equal(st, THZ_ERR_CANCELLED);
        assert_null(c);
        questions++;
    }
    assert_true(questions >= 3); /* before the keys, before the partition, each bucket */
    photon_map_destroy(a);
    free(src);
}

/* Records already in the map's order (a map's own, as a photon-map file keeps them) give
 * the same map without the second array; one pair out of order where the two threads'
 * parts meet, and the full build runs and gives it too. */
static void test_in_order(void **state)
{
    (void)state;
    const size_t n = (size_t)(140000 + 60000 * test_scale()), n_objects = 40;
    photon_record *src = make_crowded(n, n_objects);
    photon_map *a = build(src, n, n_objects, 2, 0);
    const photon_record *ra = photon_map_records(a);
    for (int variant = 0; variant < 2; variant++) {
        photon_record *p = malloc(n * sizeof *p);
        assert_non_null(p);
        memcpy(p, ra, n * sizeof *p);
        size_t at = n / 2; /* the second part's first record */
        if (variant == 1) {
            while (photon_group(&ra[at - 1]) != photon_group(&ra[at]) ||
                   memcmp(&ra[at - 1], &ra[at], sizeof *ra) == 0)
                at++;
            photon_record t = p[at - 1];
            p[at - 1] = p[at];
            p[at] = t;
        }
        photon_map_pool pool = {0};
        photon_map *c = NULL;
        assert_int_equal(photon_map_build(p, n, n, n_objects, 2, &pool, NULL, &c, NULL), THZ_OK);
        assert_memory_equal(ra, photon_map_records(c), n * sizeof(photon_record));
        /* the second array is taken only when something is out of order */
        assert_true((pool.scratch == NULL) == (variant == 0));
        photon_map_destroy(c);
        photon_map_pool_fini(&pool);
    }
    photon_map_destroy(a);
    free(src);
}

/* A key (a 4096th of a large group's cube) holding 60 % of the records: the scratch grows
 * to hold it, and the map is the same for 1 and 2 threads, in order (a rebuild from it
 * takes no scratch) and right for the queries. */
static void test_crowded_key(void **state)
{
    (void)state;
    const size_t n = 100000, n_objects = 2;
    photon_record *src = make_photons(n, n_objects, 11);
    for (size_t i = 0; i < n; i++) {
        src[i].tag = photon_tag(i % 10 == 9, 0, 0, 0); /* 90 % in group 0: large */
        if (i < 90000 && i % 3 != 2)                   /* 60 % on one point */
            src[i].position_m[0] = src[i].position_m[1] = src[i].position_m[2] = 0.5f;
    }
    size_t at_point = 0;
    for (size_t i = 0; i < n; i++)
        at_point += photon_group(&src[i]) == 0 && src[i].position_m[0] == 0.5f &&
                    src[i].position_m[1] == 0.5f && src[i].position_m[2] == 0.5f;
    assert_true(at_point > photon_map_scratch_records(n));
    photon_map *a = build(src, n, n_objects, 1, 0);
    photon_map_pool pool = {0};
    photon_record *p = malloc(n * sizeof *p);
    assert_non_null(p);
    memcpy(p, src, n * sizeof *p);
    photon_map *c = NULL;
    assert_int_equal(photon_map_build(p, n, n, n_objects, 2, &pool, NULL, &c, NULL), THZ_OK);
    assert_memory_equal(photon_map_records(a), photon_map_records(c), n * sizeof(photon_record));
    /* the point's key and the few others in its cell, far less than all */
    assert_in_range(pool.scratch_capacity, at_point, at_point + n / 100);
    photon_map_destroy(c);
    photon_map_pool_fini(&pool);
    pool = (photon_map_pool){0};
    p = malloc(n * sizeof *p);
    assert_non_null(p);
    memcpy(p, photon_map_records(a), n * sizeof *p);
    assert_int_equal(photon_map_build(p, n, n, n_objects, 2, &pool, NULL, &c, NULL), THZ_OK);
    assert_null(pool.scratch); /* in the map's order already */
    photon_map_destroy(c);
    photon_map_pool_fini(&pool);
    check_queries(a, n, 0);
    photon_map_destroy(a);
    free(src);
}

/* A dense cluster: 1500 of 3000 records of one group within 0.8 mm of a 1 m cube, all
 * inside one cell of the octree's 10th level (1/1024 of the cube), so that queries there
 * descend below it, where the records are told apart by the digits after the build's
 * first 32 bits of code (photon_sort_range sorts those ties from the next level on). Radius
 * and k-nearest queries in the cluster against brute force. Those ties sorted from one
 * level deeper (a mutant: the 11th level's z bit left unsorted) passed every test, and
 * radius queries there missed photons. */
static void test_dense_cluster(void **state)
{
    (void)state;
    const size_t n = 3000;
    photon_record *src = malloc(n * sizeof *src);
    assert_non_null(src);
    rng_stream rng;
    rng_init(&rng, 15, 0, RNG_PURPOSE_TEST, 0);
    for (size_t i = 0; i < n; i++) {
        float pos[3];
        for (int a = 0; a < 3; a++) {
            double u = rng_uniform(&rng);
            pos[a] = (float)(i % 2 ? 0.5001 + 0.0008 * u : u);
        }
        src[i] = (photon_record){.position_m = {pos[0], pos[1], pos[2]},
                                 .power_w_per_hz = (float)i,
                                 .freq_hz = 1e12f,
                                 .dir_oct = 0,
                                 .tag = photon_tag(0, 0, 0, 0)};
    }
    for (int a = 0; a < 3; a++) { /* the cube from 0 to 1 m: the cluster in cell 512 */
        src[0].position_m[a] = 0.0f;
        src[2].position_m[a] = 1.0f;
    }
    photon_map *map = build(src, n, 1, 1, 0);
    const photon_record *r = photon_map_records(map);
    double *d2s = malloc(n * sizeof *d2s);
    assert_non_null(d2s);
    for (int trial = 0; trial < 20; trial++) {
        vec3 q = v3(0.5001 + 0.0008 * rng_uniform(&rng), 0.5001 + 0.0008 * rng_uniform(&rng),
                    0.5001 + 0.0008 * rng_uniform(&rng));
        for (size_t i = 0; i < n; i++) {
            double dx = (double)r[i].position_m[0] - q.x, dy = (double)r[i].position_m[1] - q.y,
                   dz = (double)r[i].position_m[2] - q.z;
            d2s[i] = dx * dx + dy * dy + dz * dz;
        }
        qsort(d2s, n, sizeof *d2s, cmp_double);
        static const size_t ks[] = {1, 20, 300};
        for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
            assert_true(photon_map_kth_distance2(map, 0, 1u, q, ks[ki]) == d2s[ks[ki] - 1]);
            int visits = 0;
            photon_map_radius(map, 0, 0, q, d2s[ks[ki] - 1], noop_visit, &visits);
            size_t expect = ks[ki];
            while (expect < n && d2s[expect] <= d2s[ks[ki] - 1])
                expect++;
            assert_int_equal((size_t)visits, expect);
        }
    }
    free(d2s);
    photon_map_destroy(map);
    free(src);
}

static void test_empty_and_errors(void **state)
{
    (void)state;
    photon_map *map = NULL;
    thz_error err;
    assert_int_equal(photon_map_create(NULL, 0, 3, 0, &map, &err), THZ_OK);
    assert_non_null(map);
    assert_int_equal(photon_map_count(map), 0);
    int visits = 0;
    photon_map_radius(map, 0, 0, v3(0, 0, 0), 1e9, noop_visit, &visits);
    photon_map_radius(map, 7, 1, v3(0, 0, 0), 1e9, noop_visit, &visits);
    assert_int_equal(visits, 0);
    assert_true(isinf(photon_map_kth_distance2(map, 0, 3, v3(0, 0, 0), 1)));
    photon_map_destroy(map);
    photon_map_destroy(NULL);

    /* an object index beyond n_objects is refused (and the array freed) */
    photon_record *p = make_photons(10, 5, 4);
    p[4].tag = photon_tag(10, 0, 0, 0);
    map = NULL;
    assert_int_equal(photon_map_create(p, 10, 5, 0, &map, &err), THZ_ERR_INTERNAL);
    assert_null(map);
    assert_true(strstr(err.message, "object 10") != NULL);

    /* more objects than a tag's group bits hold: refused, not wrapped into other groups */
    map = NULL;
    assert_int_equal(photon_map_create(NULL, 0, PHOTON_MAX_OBJECTS + 1, 0, &map, &err),
                     THZ_ERR_LIMIT);
    assert_null(map);
    assert_true(strstr(err.message, "objects") != NULL);
    /* the most a map holds: its last object's back side is the tag's last group */
    assert_int_equal(photon_group(&(photon_record){
                         .tag = photon_tag((uint32_t)PHOTON_MAX_OBJECTS - 1, 1, 1, 7)}),
                     2 * PHOTON_MAX_OBJECTS - 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_directions),    cmocka_unit_test(test_queries_vs_brute_force),
        cmocka_unit_test(test_dense_cluster), cmocka_unit_test(test_same_records_grouped),
        cmocka_unit_test(test_deterministic), cmocka_unit_test(test_deterministic_crowded),
        cmocka_unit_test(test_cancel),        cmocka_unit_test(test_in_order),
        cmocka_unit_test(test_crowded_key),   cmocka_unit_test(test_empty_and_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
