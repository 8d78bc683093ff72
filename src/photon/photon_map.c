/* Photon map: records grouped by (object, side), each group sorted along a Morton
 * (z-order) curve, with an implicit octree over the sorted array as its spatial index.
 *
 * Layout. The records are reordered in place, with no per-photon side array, so the
 * map costs 32 bytes per photon plus, per (object, side), one offset and the cube its
 * octree spans. Group g = object << 1 | side occupies [start[g], start[g+1]). Within a
 * group, positions are quantised to PHOTON_MAP_LEVELS bits per axis in the group's
 * bounding cube, and the records are sorted by the interleaved bits (x, y, z at each
 * level, coarsest first), then by their bytes. So the records of every octree cell form
 * one contiguous range, and a cell's eight children split it into eight sub-ranges,
 * found by binary search on the next level's digit: the octree needs no stored nodes.
 * Queries descend the cells that reach the query sphere and scan ranges of at most
 * PHOTON_MAP_LEAF records.
 *
 * Why not the balanced kd-tree it replaces: its build (a median selection per node and
 * level, O(n log n) passes over 32-byte records) took a third of the photon phase; the
 * sort is an in-place MSD radix sort with 64-way digits, a few passes over the array.
 *
 * Determinism. The order (Morton code, then the record's bytes) is total, so every
 * position of the final array is a function of the group's multiset of records alone:
 * neither the input order nor the thread count changes a byte of the result.
 */
#include "photon/photon_map.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

#ifdef _OPENMP
#include <omp.h>
#endif

/* k up to this uses a heap on the stack; larger k allocates one per query. */
#define PHOTON_MAP_STACK_K 256

/* ---- Octahedral direction encoding ------------------------------------------------ */

static double photon_sign(double v)
{
    return v >= 0.0 ? 1.0 : -1.0;
}

static uint32_t photon_quantize(double v)
{
    double q = floor((v * 0.5 + 0.5) * 65535.0 + 0.5);
    if (!(q >= 0.0))
        q = 0.0; /* also NaN */
    if (q > 65535.0)
        q = 65535.0;
    return (uint32_t)q;
}

static double photon_dequantize(uint32_t q)
{
    return (double)q * (2.0 / 65535.0) - 1.0;
}

static vec3 photon_decode_xy(double x, double y)
{
    double z = 1.0 - fabs(x) - fabs(y);
    if (z < 0.0) {
        double ox = x;
        x = (1.0 - fabs(y)) * photon_sign(ox);
        y = (1.0 - fabs(ox)) * photon_sign(y);
    }
    return v3_normalize(v3(x, y, z));
}

uint32_t photon_encode_direction(vec3 dir)
{
    double l1 = fabs(dir.x) + fabs(dir.y) + fabs(dir.z);
    if (!(l1 > 0.0))
        return photon_quantize(0.0) << 16 | photon_quantize(0.0); /* +z */
    double x = dir.x / l1, y = dir.y / l1;
    if (dir.z < 0.0) {
        double ox = x;
        x = (1.0 - fabs(y)) * photon_sign(ox);
        y = (1.0 - fabs(ox)) * photon_sign(y);
    }
    return photon_quantize(x) << 16 | photon_quantize(y);
}

vec3 photon_decode_direction(uint32_t code)
{
    return photon_decode_xy(photon_dequantize(code >> 16), photon_dequantize(code & 0xffffu));
}

/* ---- Build -------------------------------------------------------------------------- */

/* Bits per axis of the quantised positions: cells down to 2^-21 of the group's extent. */
#define PHOTON_MAP_LEVELS 21
/* Ranges up to this many records are scanned instead of split. */
#define PHOTON_MAP_LEAF 48
/* Ranges up to this many records (2 MB) are sorted 64 buckets at a time. */
#define PHOTON_MAP_CACHED 65536
/* Ranges up to this many records are sorted by insertion. */
#define PHOTON_MAP_SORT_SMALL 16

/* The cube a group's octree spans: origin (its bounding box's minimum) and side. */
typedef struct photon_cube {
    double origin[3];
    double side;  /* of the root cell, m; cells at level L have side / 2^L */
    double scale; /* 2^LEVELS / side: position offset -> quantised coordinate */
} photon_cube;

struct photon_map {
    photon_record *records;
    size_t count;
    size_t capacity;    /* of records (photon_map_recycle) */
    size_t n_groups;    /* 2 n_objects */
    size_t *start;      /* n_groups + 1 offsets */
    photon_cube *cubes; /* n_groups */
    double t0_k;        /* reference temperature: 0 for the paper's map */
    unsigned batches;   /* PHOTON_MAP_BATCHES, or 1: records without their batch */
};

static uint32_t photon_quantize_axis(const photon_cube *c, const photon_record *p, int a)
{
    double q = ((double)p->position_m[a] - c->origin[a]) * c->scale;
    if (!(q > 0.0))
        return 0;
    if (q >= (double)(1u << PHOTON_MAP_LEVELS))
        return (1u << PHOTON_MAP_LEVELS) - 1;
    return (uint32_t)q;
}

/* `levels` levels' digits of a Morton code from `level` on (3 bits each, the first
 * level's highest; levels past the last count as digit 0). */
static unsigned photon_code_digits(uint64_t code, int level, int levels)
{
    int last = level + levels - 1; /* deepest level wanted */
    int shift = 3 * (PHOTON_MAP_LEVELS - last);
    uint64_t mask = ((uint64_t)1 << (3 * levels)) - 1;
    if (shift >= 0)
        return (unsigned)(code >> shift & mask);
    return (unsigned)(code << -shift & mask);
}

/* The low 21 bits of v spread to every third bit (bit i to bit 3i). */
static uint64_t photon_spread3(uint32_t v)
{
    uint64_t x = v & 0x1fffffu;
    x = (x | x << 32) & 0x1f00000000ffffu;
    x = (x | x << 16) & 0x1f0000ff0000ffu;
    x = (x | x << 8) & 0x100f00f00f00f00fu;
    x = (x | x << 4) & 0x10c30c30c30c30c3u;
    x = (x | x << 2) & 0x1249249249249249u;
    return x;
}

/* The full Morton code (3 LEVELS bits; x the highest bit of each level). */
static uint64_t photon_morton(const photon_cube *c, const photon_record *p)
{
    return photon_spread3(photon_quantize_axis(c, p, 0)) << 2 |
           photon_spread3(photon_quantize_axis(c, p, 1)) << 1 |
           photon_spread3(photon_quantize_axis(c, p, 2));
}

/* Swaps records i and j and their codes. */
static void photon_swap2(photon_record *r, uint64_t *code, size_t i, size_t j)
{
    photon_record t = r[i];
    r[i] = r[j];
    r[j] = t;
    uint64_t k = code[i];
    code[i] = code[j];
    code[j] = k;
}

static int photon_compare_bytes(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(photon_record));
}

/* Insertion sort of a small range by (Morton code, bytes). */
static void photon_sort_small(photon_record *r, uint64_t *code, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        photon_record x = r[i];
        uint64_t k = code[i];
        size_t j = i;
        while (j > 0 &&
               (code[j - 1] > k || (code[j - 1] == k && memcmp(&r[j - 1], &x, sizeof x) > 0))) {
            r[j] = r[j - 1];
            code[j] = code[j - 1];
            j--;
        }
        r[j] = x;
        code[j] = k;
    }
}

/* Sorts r[0..n) (with their Morton codes alongside), whose codes share the digits of
 * levels 1..level-1, by code and then bytes: American flag sort. Ranges larger than the
 * caches go three levels (512 buckets) at a time, since every pass over them costs a
 * cache miss per record; cached ones two levels (64 buckets) at a time. */
static void photon_sort(photon_record *r, uint64_t *code, size_t n, int level)
{
    if (n <= PHOTON_MAP_SORT_SMALL) {
        photon_sort_small(r, code, n);
        return;
    }
    if (level > PHOTON_MAP_LEVELS) { /* one position: by bytes (the codes are equal) */
        qsort(r, n, sizeof *r, photon_compare_bytes);
        return;
    }
    const int levels = n <= PHOTON_MAP_CACHED ? 2 : 3;
    const int nb = 1 << (3 * levels);
    size_t count[512] = {0}, start[513], next[512];
    for (size_t i = 0; i < n; i++)
        count[photon_code_digits(code[i], level, levels)]++;
    start[0] = 0;
    for (int b = 0; b < nb; b++)
        start[b + 1] = start[b] + count[b];
    for (int b = 0; b < nb; b++)
        next[b] = start[b];
    for (int b = 0; b < nb; b++) {
        while (next[b] < start[b + 1]) {
            unsigned d = photon_code_digits(code[next[b]], level, levels);
            if (d == (unsigned)b)
                next[b]++;
            else
                photon_swap2(r, code, next[b], next[d]++);
        }
    }
    for (int b = 0; b < nb; b++) {
        photon_record *sub = r + start[b];
        uint64_t *sub_code = code + start[b];
        size_t m = count[b];
        if (m == 0)
            continue;
        int sub_level = level + levels;
        if (m >= 8192) {
#pragma omp task firstprivate(sub, sub_code, m, sub_level)
            photon_sort(sub, sub_code, m, sub_level);
        } else {
            photon_sort(sub, sub_code, m, sub_level);
        }
    }
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
        /* an empty group: any; + 0.0 makes a minimum of -0 +0 (photon_map_scan's threads
         * may see -0 and +0 in either order) */
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

static void photon_swap(photon_record *a, photon_record *b)
{
    photon_record t = *a;
    *a = *b;
    *b = t;
}

/* Groups records by object_side in place (American flag sort: the counts come from
 * photon_map_create's checking pass, then cycles); the order within a group is
 * irrelevant since the sort fixes it. */
static void photon_group(photon_record *r, size_t n_groups, size_t *start, size_t *next)
{
    for (size_t g = 0; g < n_groups; g++)
        start[g + 1] += start[g];
    for (size_t g = 0; g < n_groups; g++)
        next[g] = start[g];
    for (size_t g = 0; g < n_groups; g++) {
        while (next[g] < start[g + 1]) {
            size_t dst = r[next[g]].object_side;
            if (dst == g)
                next[g]++;
            else
                photon_swap(&r[next[g]], &r[next[dst]++]);
        }
    }
}

/* One pass over the records, split over threads: checks their groups, clears the bits
 * 16..17 of flags (a kd-tree's split axis in maps before the octree; kept zero), counts
 * the records of each group into count[g] and takes the groups' bounding boxes. Each
 * thread has counts and boxes of its own, summed after (integer sums, minima and maxima:
 * exact, so the thread count changes nothing). Returns count when every record names a
 * group, else the first that does not; SIZE_MAX when out of memory. */
static size_t photon_map_scan(photon_record *r, size_t count, size_t n_groups, int threads,
                              size_t *group_count, photon_bounds *bounds)
{
    int nt = 1;
#ifdef _OPENMP
    nt = threads > 0 ? threads : omp_get_max_threads();
    if (nt < 1)
        nt = 1;
    if (count < 65536) /* not worth waking threads for */
        nt = 1;
#else
    (void)threads;
#endif
    /* Each thread's counts and boxes, written for every record, apart from the next
     * thread's by a cache line at least (stride: n_groups + 8). */
    const size_t stride = n_groups + 8;
    size_t *counts = thz_calloc((size_t)nt * stride, sizeof *counts);
    photon_bounds *boxes = thz_malloc_array((size_t)nt * stride, sizeof *boxes);
    size_t *first_bad = thz_malloc_array((size_t)nt, sizeof *first_bad);
    if (!counts || !boxes || !first_bad) {
        free(counts);
        free(boxes);
        free(first_bad);
        return SIZE_MAX;
    }
    for (size_t g = 0; g < (size_t)nt * stride; g++)
        for (int a = 0; a < 3; a++) {
            boxes[g].lo[a] = INFINITY;
            boxes[g].hi[a] = -INFINITY;
        }
#pragma omp parallel num_threads(nt)
    {
        int t = 0, n_threads = 1;
#ifdef _OPENMP
        t = omp_get_thread_num();
        n_threads = omp_get_num_threads();
#endif
        size_t lo = count / (size_t)n_threads * (size_t)t,
               hi = count / (size_t)n_threads * (size_t)(t + 1);
        if (t == n_threads - 1)
            hi = count;
        size_t *cnt = counts + (size_t)t * stride;
        photon_bounds *box = boxes + (size_t)t * stride;
        first_bad[t] = count;
        for (size_t i = lo; i < hi; i++) {
            photon_record *p = &r[i];
            if (p->object_side >= n_groups) {
                first_bad[t] = i;
                break;
            }
            p->flags &= ~(3u << 16);
            cnt[p->object_side]++;
            photon_bounds *bb = &box[p->object_side];
            for (int a = 0; a < 3; a++) {
                double v = p->position_m[a];
                bb->lo[a] = v < bb->lo[a] ? v : bb->lo[a];
                bb->hi[a] = v > bb->hi[a] ? v : bb->hi[a];
            }
        }
        if (n_threads < nt && t == 0) /* fewer threads than asked: the rest scanned nothing */
            for (int u = n_threads; u < nt; u++)
                first_bad[u] = count;
    }
    size_t bad = count;
    for (size_t g = 0; g < n_groups; g++) {
        bounds[g] = boxes[g];
        group_count[g] = counts[g];
    }
    for (int t = 0; t < nt; t++) {
        bad = first_bad[t] < bad ? first_bad[t] : bad;
        if (t == 0)
            continue;
        for (size_t g = 0; g < n_groups; g++) {
            const photon_bounds *b = &boxes[(size_t)t * stride + g];
            group_count[g] += counts[(size_t)t * stride + g];
            for (int a = 0; a < 3; a++) {
                bounds[g].lo[a] = b->lo[a] < bounds[g].lo[a] ? b->lo[a] : bounds[g].lo[a];
                bounds[g].hi[a] = b->hi[a] > bounds[g].hi[a] ? b->hi[a] : bounds[g].hi[a];
            }
        }
    }
    free(counts);
    free(boxes);
    free(first_bad);
    return bad;
}

void photon_map_pool_fini(photon_map_pool *pool)
{
    free(pool->records);
    free(pool->codes);
    memset(pool, 0, sizeof *pool);
}

photon_record *photon_map_pool_take(photon_map_pool *pool, size_t *capacity)
{
    photon_record *r = pool->records;
    *capacity = r ? pool->records_capacity : 0;
    pool->records = NULL;
    pool->records_capacity = 0;
    return r;
}

void photon_map_recycle(photon_map *map, photon_map_pool *pool)
{
    if (map && pool && map->capacity > pool->records_capacity) {
        free(pool->records);
        pool->records = map->records;
        pool->records_capacity = map->capacity;
        map->records = NULL;
    }
    photon_map_destroy(map);
}

/* The codes' scratch: the pool's (grown if need be, kept there) or, without a pool, a
 * new array the caller frees. NULL when out of memory. */
static uint64_t *photon_map_codes(photon_map_pool *pool, size_t count)
{
    size_t n = count ? count : 1;
    if (!pool)
        return thz_malloc_array(n, sizeof(uint64_t));
    if (pool->codes_capacity < n) {
        free(pool->codes);
        pool->codes = thz_malloc_array(n, sizeof(uint64_t));
        pool->codes_capacity = pool->codes ? n : 0;
    }
    return pool->codes;
}

thz_status photon_map_create(photon_record *photons, size_t count, size_t n_objects, int threads,
                             photon_map **out, thz_error *err)
{
    return photon_map_build(photons, count, count, n_objects, threads, NULL, out, err);
}

thz_status photon_map_build(photon_record *photons, size_t count, size_t capacity, size_t n_objects,
                            int threads, photon_map_pool *pool, photon_map **out, thz_error *err)
{
    thz_status st = THZ_OK;
    photon_map *map = NULL;
    size_t *next = NULL;
    uint64_t *codes = NULL;
    photon_bounds *bounds = NULL;
    *out = NULL;
    if (count > 0 && !photons) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "photon map: %zu photons but no array", count);
        goto cleanup;
    }
    if (n_objects > (SIZE_MAX - 1) / 2 || n_objects > UINT32_MAX / 2) {
        st = thz_error_set(err, THZ_ERR_LIMIT, "photon map: %zu objects is too many", n_objects);
        goto cleanup;
    }
    const size_t n_groups = 2 * n_objects;
    map = calloc(1, sizeof *map);
    if (map) {
        map->start = thz_calloc(n_groups + 1, sizeof *map->start);
        map->cubes = thz_calloc(n_groups ? n_groups : 1, sizeof *map->cubes);
    }
    next = thz_calloc(n_groups + 1, sizeof *next);
    bounds = thz_malloc_array(n_groups ? n_groups : 1, sizeof *bounds);
    if (!map || !map->start || !map->cubes || !next || !bounds) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu objects",
                           n_objects);
        goto cleanup;
    }
    size_t bad = photon_map_scan(photons, count, n_groups, threads, map->start + 1, bounds);
    if (bad == SIZE_MAX) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu objects",
                           n_objects);
        goto cleanup;
    }
    if (bad < count) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "photon map: photon %zu names object %u of %zu",
                           bad, (unsigned)photon_object(&photons[bad]), n_objects);
        goto cleanup;
    }
    for (size_t g = 0; g < n_groups; g++)
        map->cubes[g] = photon_group_cube(&bounds[g]);
    photon_group(photons, n_groups, map->start, next);
    /* The records' Morton codes, sorted alongside them (8 bytes per record, freed when
     * the map is built, or kept in the pool for the next: the peak is 1.25 times the
     * map). */
    codes = photon_map_codes(pool, count);
    if (!codes) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu photons", count);
        goto cleanup;
    }
    map->records = photons;
    map->count = count;
    map->capacity = capacity > count ? capacity : count;
    map->n_groups = n_groups;
    photons = NULL; /* owned by map now */

#ifdef _OPENMP
    int nt = threads > 0 ? threads : omp_get_max_threads();
#else
    (void)threads;
#endif
    photon_record *rec = map->records;
    const photon_cube *cubes = map->cubes;
    const size_t *start = map->start;
#pragma omp parallel num_threads(nt)
    {
#pragma omp for schedule(static)
        for (size_t i = 0; i < count; i++)
            codes[i] = photon_morton(&cubes[rec[i].object_side], &rec[i]);
#pragma omp single
        for (size_t g = 0; g < n_groups; g++) {
            size_t lo = start[g], n = start[g + 1] - lo;
            if (n == 0)
                continue;
            photon_record *r = rec + lo;
            uint64_t *code = codes + lo;
#pragma omp task firstprivate(r, code, n)
            photon_sort(r, code, n, 1);
        }
    }

    *out = map;
    map = NULL;
cleanup:
    free(next);
    if (!pool)
        free(codes);
    free(bounds);
    free(photons);
    photon_map_destroy(map);
    return st;
}

void photon_map_destroy(photon_map *map)
{
    if (!map)
        return;
    free(map->records);
    free(map->start);
    free(map->cubes);
    free(map);
}

thz_status photon_map_merge(const photon_map *const *maps, size_t n, size_t n_objects, int threads,
                            photon_map **out, thz_error *err)
{
    *out = NULL;
    size_t total = 0;
    unsigned batches = PHOTON_MAP_BATCHES;
    for (size_t i = 0; i < n; i++) {
        if (photon_map_reference_temperature_k(maps[i]) !=
            photon_map_reference_temperature_k(maps[0]))
            return thz_error_set(err, THZ_ERR_INTERNAL,
                                 "photon map merge: maps of different reference temperatures");
        if (photon_map_batches(maps[i]) != PHOTON_MAP_BATCHES)
            batches = 1;
        total += photon_map_count(maps[i]);
    }
    photon_record *all = thz_malloc_array(total ? total : 1, sizeof *all);
    if (!all)
        return thz_error_set(err, THZ_ERR_NOMEM, "photon map merge: out of memory for %zu photons",
                             total);
    size_t at = 0;
    double scale = 1.0 / (double)(n ? n : 1);
    for (size_t i = 0; i < n; i++) {
        size_t count = photon_map_count(maps[i]);
        memcpy(all + at, photon_map_records(maps[i]), count * sizeof *all);
        for (size_t j = at; j < at + count; j++)
            all[j].power_w_per_hz = (float)((double)all[j].power_w_per_hz * scale);
        at += count;
    }
    thz_status st = photon_map_create(all, total, n_objects, threads, out, err);
    if (st != THZ_OK)
        return st;
    photon_map_set_reference_temperature_k(*out,
                                           n ? photon_map_reference_temperature_k(maps[0]) : 0.0);
    photon_map_set_batches(*out, batches);
    return THZ_OK;
}

size_t photon_map_count(const photon_map *map)
{
    return map ? map->count : 0;
}

double photon_map_reference_temperature_k(const photon_map *map)
{
    return map ? map->t0_k : 0.0;
}

void photon_map_set_reference_temperature_k(photon_map *map, double t0_k)
{
    map->t0_k = t0_k;
}

unsigned photon_map_batches(const photon_map *map)
{
    return map && map->batches ? map->batches : 1u;
}

void photon_map_set_batches(photon_map *map, unsigned batches)
{
    map->batches = batches;
}

size_t photon_map_bytes(const photon_map *map)
{
    if (!map)
        return 0;
    return sizeof *map + map->count * sizeof *map->records +
           (map->n_groups + 1) * sizeof *map->start + map->n_groups * sizeof *map->cubes;
}

const photon_record *photon_map_records(const photon_map *map)
{
    return map ? map->records : NULL;
}

/* ---- Queries ------------------------------------------------------------------------ */

static double photon_distance2(const photon_record *p, const double q[3])
{
    double dx = (double)p->position_m[0] - q[0];
    double dy = (double)p->position_m[1] - q[1];
    double dz = (double)p->position_m[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

/* A cell of a group's octree: its level, integer coordinates and record range. */
typedef struct photon_cell {
    int level;
    uint32_t c[3];
    size_t lo, hi;
} photon_cell;

/* Squared distance from q to the cell's box, the box widened by a millionth of its
 * side: quantisation rounds in double, so a point on a cell's face may sit in the
 * neighbouring cell; the widening keeps pruning conservative. */
static double photon_cell_distance2(const photon_cube *cube, const photon_cell *cell,
                                    const double q[3])
{
    double size = ldexp(cube->side, -cell->level);
    double pad = 1e-6 * size;
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        double lo = cube->origin[a] + (double)cell->c[a] * size - pad;
        double hi = lo + size + 2.0 * pad;
        double d = q[a] < lo ? lo - q[a] : (q[a] > hi ? q[a] - hi : 0.0);
        d2 += d * d;
    }
    return d2;
}

/* First index in [lo, hi) whose quantised coordinate on axis a has bit `bit` set: the
 * range is sorted by that bit (a cell's records by x bit, then, within each half, by y
 * bit, then by z bit of the next level). */
static size_t photon_bit_boundary(const photon_cube *cube, const photon_record *r, size_t lo,
                                  size_t hi, int a, int bit)
{
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (photon_quantize_axis(cube, &r[mid], a) >> bit & 1u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Splits a cell's range into its 8 children's: b[d]..b[d+1] is child d. */
static void photon_cell_split(const photon_cube *cube, const photon_record *r,
                              const photon_cell *cell, size_t b[9])
{
    int bit = PHOTON_MAP_LEVELS - (cell->level + 1);
    b[0] = cell->lo;
    b[8] = cell->hi;
    b[4] = photon_bit_boundary(cube, r, b[0], b[8], 0, bit);
    b[2] = photon_bit_boundary(cube, r, b[0], b[4], 1, bit);
    b[6] = photon_bit_boundary(cube, r, b[4], b[8], 1, bit);
    for (int k = 1; k < 8; k += 2)
        b[k] = photon_bit_boundary(cube, r, b[k - 1], b[k + 1], 2, bit);
}

static photon_cell photon_child(const photon_cell *cell, unsigned d, const size_t b[9])
{
    photon_cell ch = {.level = cell->level + 1,
                      .c = {cell->c[0] << 1 | (d >> 2 & 1u), cell->c[1] << 1 | (d >> 1 & 1u),
                            cell->c[2] << 1 | (d & 1u)},
                      .lo = b[d],
                      .hi = b[d + 1]};
    return ch;
}

typedef struct photon_radius_query {
    const photon_cube *cube;
    const photon_record *r; /* the map's records */
    double q[3];
    double radius2, radius;
    photon_visit_fn visit;
    void *ctx;
} photon_radius_query;

static void photon_radius_rec(const photon_radius_query *qr, const photon_cell *cell);

/* Splits [lo, hi) of `cell` by the next level's bit on axes `axis`..2, descending only
 * into the halves the query sphere reaches on each axis (so a small sphere costs one
 * binary search per axis, not seven per cell); `bits` collects the child's digit. */
static void photon_radius_axes(const photon_radius_query *qr, const photon_cell *cell, size_t lo,
                               size_t hi, int axis, unsigned bits)
{
    if (lo == hi)
        return;
    if (axis == 3) {
        photon_cell ch = {.level = cell->level + 1,
                          .c = {cell->c[0] << 1 | (bits >> 2 & 1u),
                                cell->c[1] << 1 | (bits >> 1 & 1u), cell->c[2] << 1 | (bits & 1u)},
                          .lo = lo,
                          .hi = hi};
        if (photon_cell_distance2(qr->cube, &ch, qr->q) <= qr->radius2)
            photon_radius_rec(qr, &ch);
        return;
    }
    double size = ldexp(qr->cube->side, -cell->level), pad = 1e-6 * size;
    double mid_m = qr->cube->origin[axis] + ((double)cell->c[axis] + 0.5) * size;
    bool low = qr->q[axis] - qr->radius <= mid_m + pad;
    bool high = qr->q[axis] + qr->radius >= mid_m - pad;
    size_t m =
        photon_bit_boundary(qr->cube, qr->r, lo, hi, axis, PHOTON_MAP_LEVELS - (cell->level + 1));
    if (low)
        photon_radius_axes(qr, cell, lo, m, axis + 1, bits << 1);
    if (high)
        photon_radius_axes(qr, cell, m, hi, axis + 1, bits << 1 | 1u);
}

static void photon_radius_rec(const photon_radius_query *qr, const photon_cell *cell)
{
    if (cell->hi - cell->lo <= PHOTON_MAP_LEAF || cell->level == PHOTON_MAP_LEVELS) {
        for (size_t i = cell->lo; i < cell->hi; i++) {
            double d2 = photon_distance2(&qr->r[i], qr->q);
            if (d2 <= qr->radius2)
                qr->visit(qr->ctx, &qr->r[i], d2);
        }
        return;
    }
    photon_radius_axes(qr, cell, cell->lo, cell->hi, 0, 0);
}

static bool photon_group_range(const photon_map *map, uint32_t object, int side, size_t *lo,
                               size_t *n)
{
    if (!map || (size_t)object >= map->n_groups / 2 || side < 0 || side > 1)
        return false;
    size_t g = (size_t)object * 2 + (size_t)side;
    *lo = map->start[g];
    *n = map->start[g + 1] - *lo;
    return *n > 0;
}

size_t photon_map_object_count(const photon_map *map, uint32_t object, unsigned side_mask)
{
    size_t total = 0, lo, n;
    for (int s = 0; s < 2; s++)
        if ((side_mask >> s & 1u) && photon_group_range(map, object, s, &lo, &n))
            total += n;
    return total;
}

static photon_cell photon_root(size_t lo, size_t n)
{
    photon_cell root = {.level = 0, .c = {0, 0, 0}, .lo = lo, .hi = lo + n};
    return root;
}

void photon_map_radius(const photon_map *map, uint32_t object, int side, vec3 position_m,
                       double radius2_m2, photon_visit_fn visit, void *ctx)
{
    size_t lo, n;
    if (!(radius2_m2 >= 0.0) || !photon_group_range(map, object, side, &lo, &n))
        return;
    size_t g = (size_t)object * 2 + (size_t)side;
    photon_radius_query qr = {&map->cubes[g],
                              map->records,
                              {position_m.x, position_m.y, position_m.z},
                              radius2_m2,
                              sqrt(radius2_m2),
                              visit,
                              ctx};
    photon_cell root = photon_root(lo, n);
    if (photon_cell_distance2(qr.cube, &root, qr.q) <= radius2_m2)
        photon_radius_rec(&qr, &root);
}

/* A bounded max-heap of the k smallest squared distances seen. */
typedef struct photon_knn {
    const photon_cube *cube;
    const photon_record *r;
    double q[3];
    double *heap;
    size_t size, k;
} photon_knn;

static void photon_knn_push(photon_knn *h, double d2)
{
    if (h->size < h->k) {
        size_t i = h->size++;
        while (i > 0) {
            size_t parent = (i - 1) / 2;
            if (h->heap[parent] >= d2)
                break;
            h->heap[i] = h->heap[parent];
            i = parent;
        }
        h->heap[i] = d2;
        return;
    }
    if (d2 >= h->heap[0])
        return;
    /* replace the root and sift down */
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->size)
            break;
        if (c + 1 < h->size && h->heap[c + 1] > h->heap[c])
            c++;
        if (h->heap[c] <= d2)
            break;
        h->heap[i] = h->heap[c];
        i = c;
    }
    h->heap[i] = d2;
}
static double photon_knn_bound(const photon_knn *h)
{
    return h->size < h->k ? INFINITY : h->heap[0];
}

/* Visits the children nearest first, each only while it may hold a closer photon. */
static void photon_knn_rec(photon_knn *h, const photon_cell *cell)
{
    if (cell->hi - cell->lo <= PHOTON_MAP_LEAF || cell->level == PHOTON_MAP_LEVELS) {
        for (size_t i = cell->lo; i < cell->hi; i++) {
            double d2 = photon_distance2(&h->r[i], h->q);
            if (d2 < photon_knn_bound(h))
                photon_knn_push(h, d2);
        }
        return;
    }
    size_t b[9];
    photon_cell_split(h->cube, h->r, cell, b);
    photon_cell ch[8];
    double dist[8];
    int n = 0;
    for (unsigned d = 0; d < 8; d++) {
        if (b[d] == b[d + 1])
            continue;
        photon_cell c = photon_child(cell, d, b);
        double d2 = photon_cell_distance2(h->cube, &c, h->q);
        int j = n++;
        while (j > 0 && dist[j - 1] > d2) { /* insertion by distance (stable) */
            ch[j] = ch[j - 1];
            dist[j] = dist[j - 1];
            j--;
        }
        ch[j] = c;
        dist[j] = d2;
    }
    for (int i = 0; i < n; i++)
        if (dist[i] < photon_knn_bound(h))
            photon_knn_rec(h, &ch[i]);
}

double photon_map_kth_distance2(const photon_map *map, uint32_t object, unsigned side_mask,
                                vec3 position_m, size_t k)
{
    if (k == 0)
        return 0.0;
    size_t total = 0, lo[2], n[2];
    bool has[2];
    for (int s = 0; s < 2; s++) {
        has[s] = (side_mask >> s & 1u) && photon_group_range(map, object, s, &lo[s], &n[s]);
        if (has[s])
            total += n[s];
    }
    if (total < k)
        return INFINITY;
    double stack_heap[PHOTON_MAP_STACK_K];
    photon_knn h = {NULL, map->records, {position_m.x, position_m.y, position_m.z}, stack_heap, 0,
                    k};
    if (k > PHOTON_MAP_STACK_K) {
        /* Documented exception to "queries allocate nothing": k above 256. */
        h.heap = thz_malloc_array(k, sizeof *h.heap);
        if (!h.heap)
            return NAN;
    }
    for (int s = 0; s < 2; s++) {
        if (!has[s])
            continue;
        h.cube = &map->cubes[(size_t)object * 2 + (size_t)s];
        photon_cell root = photon_root(lo[s], n[s]);
        photon_knn_rec(&h, &root);
    }
    double result = h.heap[0];
    if (h.heap != stack_heap)
        free(h.heap);
    return result;
}
