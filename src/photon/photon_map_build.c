/* The photon map's build: the records grouped by (object, side), each group sorted by
 * Morton code and then bytes (photon_map.c says why that order), with a scratch of 3/8
 * of the records, in passes that each split the records over the threads:
 *
 *  1. scan: each part of the array (a contiguous range; one per thread) counts its records
 *     of each group and takes the groups' bounding boxes, which give the groups' cubes;
 *  2. key: each part writes each record's key into its tag's group bits (the tag's own
 *     bits kept; the group is known from the key) and counts the keys:
 *     a small group is one key, a large group one per first digit of its records' codes
 *     (PHOTON_MAP_FIRST_LEVELS levels: 4096), the keys in the map's order. The keys are
 *     dealt into buckets, runs of consecutive keys that fit in the scratch (3 in the
 *     paper's case);
 *  3. partition: each part orders its records by bucket, in place (a few fronts streaming
 *     through the part);
 *  then for each bucket in turn:
 *  4. scatter: each part moves its records of the bucket into the scratch, into its own
 *     slot of each key's range (after the earlier keys' and the earlier parts'); then the
 *     parts' records of the later buckets are moved up against the array's end
 *     (photon_build_compact), which frees the bucket's range of the map;
 *  5. sort: each key's range is sorted from the scratch into the map (photon_sort_range in
 *     photon_map_order.c), in cache but for the largest.
 *
 * Records already in the map's order (a map's own, as a photon-map file keeps them) are
 * found so by pass 1's check (photon_build_in_order) and not moved: no scratch.
 *
 * The order within a key's range before pass 5 does not matter: the map's order is total
 * (code, then bytes; records equal in both are the same bytes), so the map is the same
 * for any number of parts and any bucketing. The in-place build before these (a serial
 * permutation by group, then per group an American flag sort whose first pass over the
 * largest group was serial too) swapped the records along permutation cycles, a cache
 * miss per record in the passes over the whole array: 62 ns per record on 1 thread and
 * 35-46 on 2 (the paper's case, 5.06 M records, warm memory). A build with a second array
 * as large as the records (grouping and digit passes from one to the other) took 36 and
 * 20 but doubled the peak; this one takes as long (12.1 M records, 2 threads, three
 * alternating runs: 0.33-0.38 s against 0.33-0.38 s; 1 thread 0.60-0.67 s against
 * 0.60-0.65 s) and its peak is the map and 3/8 of it. The scratch is larger only where
 * more than 3/8 of the records share a key (a point holding most photons of a large
 * group): a key's records must fit in it. It is kept in the pool between builds.
 */
#include "photon/photon_map.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/threads.h"
#include "photon/photon_map_layout.h"
#include "photon/photon_map_order.h"

#ifdef _OPENMP
#include <omp.h>
#endif

/* Groups of this many records or more are keyed by their first digit (PHOTON_MAP_DIGITS
 * keys, sorted apart, over the threads); smaller ones are one key each. */
#define PHOTON_MAP_LARGE 65536
/* Below this many records, one part (not worth waking threads for). */
#define PHOTON_MAP_PARTS_MIN 65536

/* A record's group before pass 2, its key after (the tag's upper bits). */
static inline size_t photon_build_key_of(const photon_record *q)
{
    return q->tag >> PHOTON_TAG_GROUP_SHIFT;
}

/* A group's bounding box. */
typedef struct photon_bounds {
    double lo[3], hi[3];
} photon_bounds;

/* The group's cube: its records' bounding box, widened to a cube (cells stay cubes). */
static photon_cube photon_group_cube(const photon_bounds *b)
{
    photon_cube c;
    double side = 0.0;
    for (int a = 0; a < 3; a++) {
        /* an empty group: any; + 0.0 makes a minimum of -0 +0 (pass 1's parts may see -0
         * and +0 in either order) */
        c.origin[a] = b->lo[a] <= b->hi[a] ? b->lo[a] + 0.0 : 0.0;
        side = b->hi[a] - b->lo[a] > side ? b->hi[a] - b->lo[a] : side;
    }
    if (!(side > 0.0))
        side = 1.0;
    /* slightly larger, so the top corner quantises inside */
    c.side = side * (1.0 + 1e-9);
    c.scale = (double)(1u << PHOTON_MAP_LEVELS) / c.side;
    return c;
}

/* ---- The passes ------------------------------------------------------------------------ */

/* At most this many buckets: each holds at most the scratch's records, and two neighbours
 * more than it (else they would be one), so with the scratch at least 3/8 of the records
 * there are at most 2 x 8/3 + 1 < 7. */
#define PHOTON_MAP_BUCKETS_MAX 8

/* One build: the records, the scratch, and what the passes hand on. The per-part arrays
 * have a row per part, rows a cache line apart at least (strides n_groups + 8 and
 * n_keys + 8): each part writes its own row for every record. */
typedef struct photon_build {
    photon_record *r; /* the records: the input, then the map */
    photon_record *s; /* the scratch: one bucket's records at a time */
    size_t s_base;    /* the map position of s[0] while a bucket is there */
    size_t count, n_groups, stride;
    int parts;
    size_t *part_count;      /* [p][g]: part p's records of group g (pass 1) */
    photon_bounds *part_box; /* [p][g]: the bounding box of those records */
    size_t *first_bad;       /* [p]: the part's first record naming no group, or count */
    size_t *start;           /* n_groups + 1: the map's group offsets */
    photon_cube *cubes;      /* n_groups: the map's cubes */
    size_t *key_base;        /* n_groups + 1: group g's keys are key_base[g] .. [g + 1] - 1 */
    size_t n_keys, key_stride;
    size_t *key_next;  /* [p][key]: part p's records of the key (pass 2), then slots */
    size_t *key_start; /* n_keys + 1: the map position of each key's first record */
    int n_buckets;
    size_t bucket_key[PHOTON_MAP_BUCKETS_MAX + 1]; /* bucket k: keys [k], .. [k + 1] - 1 */
    size_t *part_at; /* [p][k]: where part p's records of bucket k are; [p][n_buckets]: end */
    size_t *part_in; /* [p][k]: how many */
} photon_build;

static void photon_part_range(const photon_build *b, int p, size_t *lo, size_t *hi)
{
    size_t step = b->count / (size_t)b->parts;
    *lo = step * (size_t)p;
    *hi = p == b->parts - 1 ? b->count : step * (size_t)(p + 1);
}

/* Part p's rows of part_at and part_in. */
static size_t *photon_part_at(const photon_build *b, int p)
{
    return b->part_at + (size_t)p * (PHOTON_MAP_BUCKETS_MAX + 1);
}
static size_t *photon_part_in(const photon_build *b, int p)
{
    return b->part_in + (size_t)p * (PHOTON_MAP_BUCKETS_MAX + 1);
}

/* Pass 1 for part p: counts and bounding boxes of its records' groups; stops at the
 * first record naming no group. Read only. */
static void photon_build_scan(photon_build *b, int p)
{
    size_t lo, hi;
    photon_part_range(b, p, &lo, &hi);
    size_t *cnt = b->part_count + (size_t)p * b->stride;
    photon_bounds *box = b->part_box + (size_t)p * b->stride;
    for (size_t g = 0; g < b->n_groups; g++) {
        cnt[g] = 0;
        for (int a = 0; a < 3; a++) {
            box[g].lo[a] = INFINITY;
            box[g].hi[a] = -INFINITY;
        }
    }
    b->first_bad[p] = b->count;
    for (size_t i = lo; i < hi; i++) {
        photon_prefetch(b->r, i + PHOTON_PREFETCH_AHEAD, hi);
        const photon_record *q = &b->r[i];
        size_t g = photon_group(q);
        if (g >= b->n_groups) {
            b->first_bad[p] = i;
            return;
        }
        cnt[g]++;
        photon_bounds *bb = &box[g];
        for (int a = 0; a < 3; a++) {
            double v = q->position_m[a];
            bb->lo[a] = v < bb->lo[a] ? v : bb->lo[a];
            bb->hi[a] = v > bb->hi[a] ? v : bb->hi[a];
        }
    }
}

/* After pass 1: the groups' offsets and cubes (the parts' boxes and counts combined
 * exactly: minima, maxima and integer sums, so the number of parts changes nothing) and
 * keys (a large group one per first digit, any other one). Returns count, or the first
 * record that names no group. */
static size_t photon_build_layout(photon_build *b)
{
    size_t bad = b->count;
    for (int p = 0; p < b->parts; p++)
        bad = b->first_bad[p] < bad ? b->first_bad[p] : bad;
    if (bad < b->count)
        return bad;
    b->start[0] = 0;
    b->key_base[0] = 0;
    for (size_t g = 0; g < b->n_groups; g++) {
        photon_bounds box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        size_t n = 0;
        for (int p = 0; p < b->parts; p++) {
            size_t at = (size_t)p * b->stride + g;
            n += b->part_count[at];
            for (int a = 0; a < 3; a++) {
                box.lo[a] = b->part_box[at].lo[a] < box.lo[a] ? b->part_box[at].lo[a] : box.lo[a];
                box.hi[a] = b->part_box[at].hi[a] > box.hi[a] ? b->part_box[at].hi[a] : box.hi[a];
            }
        }
        b->start[g + 1] = b->start[g] + n;
        b->cubes[g] = photon_group_cube(&box);
        b->key_base[g + 1] = b->key_base[g] + (n >= PHOTON_MAP_LARGE ? PHOTON_MAP_DIGITS : 1);
    }
    b->n_keys = b->key_base[b->n_groups];
    return b->count;
}

/* After pass 1, for part p: whether its records, and the one before them, are in the map's
 * order already: groups ascending; within a group, Morton codes in the group's cube
 * ascending, ties by bytes. Read only. */
static bool photon_build_in_order(const photon_build *b, int p)
{
    size_t lo, hi;
    photon_part_range(b, p, &lo, &hi);
    size_t first = lo > 0 ? lo - 1 : 0;
    uint64_t prev_code = 0;
    for (size_t i = first; i < hi; i++) {
        photon_prefetch(b->r, i + PHOTON_PREFETCH_AHEAD, hi);
        const photon_record *q = &b->r[i];
        uint64_t code = photon_morton(&b->cubes[photon_group(q)], q);
        if (i > first) {
            const photon_record *before = q - 1;
            if (photon_group(before) > photon_group(q))
                return false;
            if (photon_group(before) == photon_group(q) &&
                (prev_code > code || (prev_code == code && memcmp(before, q, sizeof *q) > 0)))
                return false;
        }
        prev_code = code;
    }
    return true;
}

/* Pass 2 for part p: each record's key into its tag's group bits (the group is known from
 * the key), counted. */
static void photon_build_key(photon_build *b, int p)
{
    size_t lo, hi;
    photon_part_range(b, p, &lo, &hi);
    size_t *cnt = b->key_next + (size_t)p * b->key_stride;
    memset(cnt, 0, b->n_keys * sizeof *cnt);
    for (size_t i = lo; i < hi; i++) {
        photon_prefetch_write(b->r, i + PHOTON_PREFETCH_AHEAD, hi);
        photon_record *q = &b->r[i];
        size_t g = photon_group(q), key = b->key_base[g];
        if (b->key_base[g + 1] - key > 1)
            key += photon_first_digit(&b->cubes[g], q);
        q->tag = (uint32_t)key << PHOTON_TAG_GROUP_SHIFT |
                 (q->tag & ((1u << PHOTON_TAG_GROUP_SHIFT) - 1u));
        cnt[key]++;
    }
}

/* After pass 2: the keys' map positions (the parts' counts summed); returns the largest
 * key's records. */
static size_t photon_build_key_starts(photon_build *b)
{
    size_t largest = 0;
    b->key_start[0] = 0;
    for (size_t key = 0; key < b->n_keys; key++) {
        size_t n = 0;
        for (int p = 0; p < b->parts; p++)
            n += b->key_next[(size_t)p * b->key_stride + key];
        b->key_start[key + 1] = b->key_start[key] + n;
        largest = n > largest ? n : largest;
    }
    return largest;
}

/* Then the buckets (consecutive keys, as many as fit in the scratch of s_count records:
 * s_count is at least the largest key's) and each part's records of each bucket (where
 * pass 3 puts them). */
static void photon_build_buckets(photon_build *b, size_t s_count)
{
    b->n_buckets = 0;
    b->bucket_key[0] = 0;
    size_t in_bucket = 0;
    for (size_t key = 0; key < b->n_keys; key++) {
        size_t n = b->key_start[key + 1] - b->key_start[key];
        if (in_bucket + n > s_count) {
            b->bucket_key[++b->n_buckets] = key;
            in_bucket = 0;
        }
        in_bucket += n;
    }
    b->bucket_key[++b->n_buckets] = b->n_keys;
    for (int p = 0; p < b->parts; p++) {
        size_t lo, hi;
        photon_part_range(b, p, &lo, &hi);
        size_t *at = photon_part_at(b, p), *in = photon_part_in(b, p);
        const size_t *cnt = b->key_next + (size_t)p * b->key_stride;
        for (int k = 0; k < b->n_buckets; k++) {
            at[k] = lo;
            in[k] = 0;
            for (size_t key = b->bucket_key[k]; key < b->bucket_key[k + 1]; key++)
                in[k] += cnt[key];
            lo += in[k];
        }
        at[b->n_buckets] = hi;
    }
}

/* The bucket of a key. */
static int photon_bucket_of(const photon_build *b, size_t key)
{
    int k = 0;
    while (key >= b->bucket_key[k + 1])
        k++;
    return k;
}

/* Pass 3 for part p: its records in place, by bucket (American flag sort: each record out
 * of place swapped straight to the next free slot of its bucket, a few fronts streaming
 * through the part). */
static void photon_build_partition(photon_build *b, int p)
{
    if (b->n_buckets == 1)
        return;
    const size_t *at = photon_part_at(b, p);
    size_t next[PHOTON_MAP_BUCKETS_MAX];
    for (int k = 0; k < b->n_buckets; k++)
        next[k] = at[k];
    for (int k = 0; k < b->n_buckets; k++) {
        while (next[k] < at[k + 1]) {
            photon_prefetch_write(b->r, next[k] + PHOTON_PREFETCH_AHEAD, at[k + 1]);
            int d = photon_bucket_of(b, photon_build_key_of(&b->r[next[k]]));
            if (d == k) {
                next[k]++;
            } else { /* and the front it swaps with (16 ahead did as well as 32) */
                photon_prefetch_write(b->r, next[d] + PHOTON_PREFETCH_AHEAD, at[d + 1]);
                photon_record t = b->r[next[k]];
                b->r[next[k]] = b->r[next[d]];
                b->r[next[d]++] = t;
            }
        }
    }
}

/* Before bucket k's pass 4: each part's first slot in the scratch for each of the bucket's
 * keys (the keys in order, within a key the parts in order). */
static void photon_build_slots(photon_build *b, int k)
{
    b->s_base = b->key_start[b->bucket_key[k]];
    for (size_t key = b->bucket_key[k]; key < b->bucket_key[k + 1]; key++) {
        size_t at = b->key_start[key] - b->s_base;
        for (int p = 0; p < b->parts; p++) {
            size_t *slot = &b->key_next[(size_t)p * b->key_stride + key];
            size_t n = *slot;
            *slot = at;
            at += n;
        }
    }
}

/* Pass 4 for part p and bucket k: the part's records of the bucket into their keys' slots
 * of the scratch. */
static void photon_build_scatter(photon_build *b, int k, int p)
{
    size_t *slot = b->key_next + (size_t)p * b->key_stride;
    size_t at = photon_part_at(b, p)[k], in = photon_part_in(b, p)[k];
    for (size_t i = at; i < at + in; i++) {
        photon_prefetch(b->r, i + PHOTON_PREFETCH_AHEAD, at + in);
        b->s[slot[photon_build_key_of(&b->r[i])]++] = b->r[i];
    }
}

/* After bucket k's pass 4: the parts' records of the later buckets moved up against the
 * array's end (each part's after the later parts', which are there already), freeing the
 * bucket's range of the map just after the earlier buckets'. */
static void photon_build_compact(photon_build *b, int k)
{
    size_t shift = 0;
    for (int p = b->parts - 2; p >= 0; p--) {
        size_t *at = photon_part_at(b, p);
        shift += photon_part_in(b, p + 1)[k];
        size_t from = at[k] + photon_part_in(b, p)[k];
        size_t to = at[b->n_buckets];
        if (shift == 0)
            continue;
        memmove(b->r + from + shift, b->r + from, (to - from) * sizeof *b->r);
        for (int j = k + 1; j <= b->n_buckets; j++)
            at[j] += shift;
    }
}

/* Pass 5, item `key` of the bucket in the scratch: the key's records sorted into the map
 * (a small group's, or a large group's of one first digit). */
static void photon_build_sort_key(const photon_build *b, size_t key)
{
    size_t lo = b->key_start[key], hi = b->key_start[key + 1];
    if (hi == lo)
        return;
    size_t g = 0, top = b->n_groups; /* the group: key_base[g] <= key < key_base[g + 1] */
    while (top - g > 1) {
        size_t mid = g + (top - g) / 2;
        if (b->key_base[mid] <= key)
            g = mid;
        else
            top = mid;
    }
    bool large = b->key_base[g + 1] - b->key_base[g] > 1;
    photon_sort_range(&b->cubes[g], b->s + (lo - b->s_base), b->r + lo, hi - lo,
                      large ? 1 + PHOTON_MAP_FIRST_LEVELS : 1, (uint32_t)g);
}

/* ---- The build -------------------------------------------------------------------------- */

/* More parts than this gain nothing (and keep the per-part arrays' sizes far from
 * overflow: n_groups <= 2^32). */
#define PHOTON_MAP_PARTS_MAX 1024

thz_status photon_map_create(photon_record *photons, size_t count, size_t n_objects, int threads,
                             photon_map **out, thz_error *err)
{
    return photon_map_build(photons, count, count, n_objects, threads, NULL, NULL, out, err);
}

/* The most keys a build of count records in n_groups groups may have: a group is large
 * (a key per first digit) from PHOTON_MAP_LARGE records on. */
static size_t photon_build_max_keys(size_t count, size_t n_groups)
{
    size_t max_large = count / PHOTON_MAP_LARGE;
    max_large = max_large < n_groups ? max_large : n_groups;
    return n_groups + max_large * (PHOTON_MAP_DIGITS - 1);
}

/* Points b's per-part, per-group and per-key arrays into index
 * (photon_map_pool_index); returns the bytes they take, or 0 with index NULL (to size
 * it). */
static size_t photon_build_arrays(photon_build *b, void *index)
{
    const size_t parts = (size_t)b->parts, rows = parts * b->stride;
    const size_t max_keys = photon_build_max_keys(b->count, b->n_groups);
    b->key_stride = max_keys + 8;
    size_t boxes = rows * sizeof(photon_bounds);
    size_t sizes = rows + parts + (b->n_groups + 1) + parts * b->key_stride + (max_keys + 1) +
                   2 * parts * (PHOTON_MAP_BUCKETS_MAX + 1);
    if (!index)
        return boxes + sizes * sizeof(size_t);
    b->part_box = index;
    b->part_count = (size_t *)(void *)((char *)index + boxes);
    b->first_bad = b->part_count + rows;
    b->key_base = b->first_bad + parts;
    b->key_next = b->key_base + (b->n_groups + 1);
    b->key_start = b->key_next + parts * b->key_stride;
    b->part_at = b->key_start + (max_keys + 1);
    b->part_in = b->part_at + parts * (PHOTON_MAP_BUCKETS_MAX + 1);
    return boxes + sizes * sizeof(size_t);
}

thz_status photon_map_build(photon_record *photons, size_t count, size_t capacity, size_t n_objects,
                            int threads, photon_map_pool *pool, const cancel_check *cancel,
                            photon_map **out, thz_error *err)
{
    thz_status st = THZ_OK;
    photon_map *map = NULL;
    photon_record *scratch = NULL;
    void *index = NULL;
    *out = NULL;
    if (count > 0 && !photons) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "photon map: %zu photons but no array", count);
        goto cleanup;
    }
    if (n_objects > PHOTON_MAX_OBJECTS) {
        st = thz_error_set(err, THZ_ERR_LIMIT, "photon map: %zu objects is too many", n_objects);
        goto cleanup;
    }
    const size_t n_groups = 2 * n_objects;
    /* a key is a tag's group bits */
    if (photon_build_max_keys(count, n_groups) > UINT32_MAX >> PHOTON_TAG_GROUP_SHIFT) {
        st = thz_error_set(err, THZ_ERR_LIMIT, "photon map: %zu photons is too many", count);
        goto cleanup;
    }
    int nt = 1;
#ifdef _OPENMP
    nt = thz_threads_or_all(threads);
#else
    (void)threads;
#endif
    nt = nt < 1 ? 1 : (nt > PHOTON_MAP_PARTS_MAX ? PHOTON_MAP_PARTS_MAX : nt);
    photon_build b = {.r = photons,
                      .count = count,
                      .n_groups = n_groups,
                      .stride = n_groups + 8,
                      .parts = count < PHOTON_MAP_PARTS_MIN ? 1 : nt};
    map = calloc(1, sizeof *map);
    if (map) {
        map->start = thz_calloc(n_groups + 1, sizeof *map->start);
        map->cubes = thz_calloc(n_groups ? n_groups : 1, sizeof *map->cubes);
    }
    index = photon_map_pool_index(pool, photon_build_arrays(&b, NULL));
    if (!map || !map->start || !map->cubes || !index) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu photons", count);
        goto cleanup;
    }
    photon_build_arrays(&b, index);
    b.start = map->start;
    b.cubes = map->cubes;

#pragma omp parallel for num_threads(b.parts) schedule(static, 1)
    for (int p = 0; p < b.parts; p++)
        photon_build_scan(&b, p);
    size_t bad = photon_build_layout(&b);
    if (bad < count) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "photon map: photon %zu names object %u of %zu",
                           bad, (unsigned)photon_object(&photons[bad]), n_objects);
        goto cleanup;
    }
    int ordered = 1;
#pragma omp parallel for num_threads(b.parts) schedule(static, 1) reduction(&& : ordered)
    for (int p = 0; p < b.parts; p++)
        ordered = photon_build_in_order(&b, p) && ordered;
    if (ordered)
        goto built;
    if (cancel_now(cancel))
        goto cancelled;
#pragma omp parallel for num_threads(b.parts) schedule(static, 1)
    for (int p = 0; p < b.parts; p++)
        photon_build_key(&b, p);
    /* The scratch: 3/8 of the records, or the largest key's if more. */
    size_t largest = photon_build_key_starts(&b);
    if (largest > UINT32_MAX) { /* the sort's pairs index a key's records in 32 bits */
        st = thz_error_set(err, THZ_ERR_LIMIT,
                           "photon map: %zu photons in one 4096th of an object's cube is too many",
                           largest);
        goto cleanup;
    }
    size_t s_count = photon_map_scratch_records(count);
    s_count = largest > s_count ? largest : s_count;
    scratch = photon_map_pool_scratch(pool, s_count);
    if (!scratch) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu photons", count);
        goto cleanup;
    }
    b.s = scratch;
    photon_build_buckets(&b, s_count);
    if (cancel_now(cancel))
        goto cancelled;
#pragma omp parallel for num_threads(b.parts) schedule(static, 1)
    for (int p = 0; p < b.parts; p++)
        photon_build_partition(&b, p);
    /* a region per bucket (at most PHOTON_MAP_BUCKETS_MAX), so that a stop is asked between
     * them on this thread */
    for (int k = 0; k < b.n_buckets; k++) {
        if (cancel_now(cancel))
            goto cancelled;
#pragma omp parallel num_threads(b.parts)
        {
#pragma omp single
            photon_build_slots(&b, k);
#pragma omp for schedule(static, 1)
            for (int p = 0; p < b.parts; p++)
                photon_build_scatter(&b, k, p);
#pragma omp single
            photon_build_compact(&b, k);
#pragma omp for schedule(dynamic, 1)
            for (size_t key = b.bucket_key[k]; key < b.bucket_key[k + 1]; key++)
                photon_build_sort_key(&b, key);
        }
    }

built:
    map->records = photons;
    map->count = count;
    map->capacity = capacity > count ? capacity : count;
    map->n_groups = n_groups;
    photons = NULL; /* owned by map now */
    *out = map;
    map = NULL;
    goto cleanup;
cancelled:
    st = thz_error_set(err, THZ_ERR_CANCELLED, "photon map: cancelled");
cleanup:
    if (!pool) {
        free(scratch);
        free(index);
    }
    free(photons);
    photon_map_destroy(map);
    return st;
}
