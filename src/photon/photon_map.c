/* Photon map: records grouped by (object, side), each group sorted along a Morton
 * (z-order) curve, with an implicit octree over the sorted array as its spatial index.
 *
 * Layout. The records are reordered, with no per-photon side array, so the map costs
 * 32 bytes per photon plus, per (object, side), one offset and the cube its octree
 * spans. Group g = object << 1 | side occupies [start[g], start[g+1]). Within a
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
 * sort is a radix sort, a few passes over the array (photon_map_build.c).
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
#include "core/threads.h"
#include "photon/photon_map_layout.h"

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

/* ---- The map ------------------------------------------------------------------------ */

void photon_map_destroy(photon_map *map)
{
    if (!map)
        return;
    free(map->records);
    free(map->start);
    free(map->cubes);
    free(map);
}

/* ---- Memory kept between the maps of a run ------------------------------------------- */

void photon_map_pool_fini(photon_map_pool *pool)
{
    free(pool->records);
    free(pool->scratch);
    free(pool->index);
    memset(pool, 0, sizeof *pool);
}

photon_record *photon_map_pool_take(photon_map_pool *pool, size_t *capacity)
{
    if (!pool) {
        *capacity = 0;
        return NULL;
    }
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

photon_record *photon_map_pool_scratch(photon_map_pool *pool, size_t count)
{
    size_t n = count ? count : 1;
    if (pool && pool->scratch_capacity >= n)
        return pool->scratch;
    if (pool) { /* the old one first: the peak stays the map and its scratch */
        free(pool->scratch);
        pool->scratch = NULL;
        pool->scratch_capacity = 0;
    }
    /* No MADV_HUGEPAGE: where transparent huge pages are "madvise", the advice makes the
     * first write wait for the kernel to compact and clear 2 MB pages. On this project's
     * VM (2026-12-03) that took the first build's grouping pass from 0.19-0.26 s to
     * 0.50-0.63 s (10 M photons, 2 threads), and the six builds of the paper's case
     * 2.41 s against 2.85 on average; a kernel whose huge pages are "always" still
     * gives them where it has them free. */
    photon_record *s = thz_malloc_array(n, sizeof(photon_record));
    thz_populate(s, s ? n * sizeof(photon_record) : 0); /* written by every build */
    if (pool && s) {
        pool->scratch = s;
        pool->scratch_capacity = n;
    }
    return s;
}

void *photon_map_pool_index(photon_map_pool *pool, size_t bytes)
{
    if (!pool)
        return malloc(bytes ? bytes : 1);
    if (pool->index_bytes < bytes || !pool->index) {
        free(pool->index);
        pool->index = malloc(bytes ? bytes : 1);
        pool->index_bytes = pool->index ? bytes : 0;
    }
    return pool->index;
}

thz_status photon_map_merge(const photon_map *const *maps, size_t n, size_t n_objects, int threads,
                            photon_map_pool *pool, photon_map **out, thz_error *err)
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
    /* the pool's array (an earlier merge's), grown in place where it can be: a merge into
     * fresh memory spent most of its time faulting the pages in */
    size_t capacity = 0;
    photon_record *all = photon_map_pool_take(pool, &capacity);
    if (capacity < total || !all) {
        photon_record *grown = thz_realloc_array(all, total ? total : 1, sizeof *all);
        if (!grown) {
            free(all);
            return thz_error_set(err, THZ_ERR_NOMEM,
                                 "photon map merge: out of memory for %zu photons", total);
        }
        /* the new pages at once (the kernel's populate, not a fault per page) */
        thz_populate(grown + capacity, ((total ? total : 1) - capacity) * sizeof *grown);
        all = grown;
        capacity = total ? total : 1;
    }
    size_t *at = thz_malloc_array(n ? n : 1, sizeof *at);
    if (!at) {
        free(all);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon map merge: out of memory");
    }
    for (size_t i = 0, sum = 0; i < n; i++) {
        at[i] = sum;
        sum += photon_map_count(maps[i]);
    }
    double scale = 1.0 / (double)(n ? n : 1);
    /* each map to its own place: the same records whatever the thread count */
    int nt = thz_threads_or_all(threads);
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
    for (size_t i = 0; i < n; i++) {
        size_t count = photon_map_count(maps[i]);
        photon_record *to = all + at[i];
        memcpy(to, photon_map_records(maps[i]), count * sizeof *all);
        for (size_t j = 0; j < count; j++)
            to[j].power_w_per_hz = (float)((double)to[j].power_w_per_hz * scale);
    }
    free(at);
    thz_status st =
        photon_map_build(all, total, capacity, n_objects, threads, pool, NULL, out, err);
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

typedef struct photon_radius_query {
    const photon_cube *cube;
    const photon_record *r; /* the map's records */
    int dir_level;          /* the group's directory: starts of its cells of this level, */
    const uint32_t *dir_starts;
    size_t dir_base; /* ... as offsets from the group's first record */
    double q[3];
    double radius2, radius;
    float radius2_pre; /* a float bound that every record within the radius meets */
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
                          .m = cell->m << 3 | bits,
                          .lo = lo,
                          .hi = hi};
        if (photon_cell_distance2(qr->cube, &ch, qr->q) <= qr->radius2)
            photon_radius_rec(qr, &ch);
        return;
    }
    double size = photon_cell_size(qr->cube, cell->level), pad = 1e-6 * size;
    double mid_m = qr->cube->origin[axis] + ((double)cell->c[axis] + 0.5) * size;
    bool low = qr->q[axis] - qr->radius <= mid_m + pad;
    bool high = qr->q[axis] + qr->radius >= mid_m - pad;
    size_t m;
    if (cell->level < qr->dir_level) {
        /* the first record of the child whose digit has this axis's bit set and the
         * bits so far, the later axes' bits clear: its first descendant of the
         * directory's level */
        uint64_t child = cell->m << 3 | ((uint64_t)bits << (3 - axis) | 1u << (2 - axis));
        m = qr->dir_base + qr->dir_starts[child << 3 * (qr->dir_level - cell->level - 1)];
    } else {
        m = photon_bit_boundary(qr->cube, qr->r, lo, hi, axis,
                                PHOTON_MAP_LEVELS - (cell->level + 1));
    }
    if (low)
        photon_radius_axes(qr, cell, lo, m, axis + 1, bits << 1);
    if (high)
        photon_radius_axes(qr, cell, m, hi, axis + 1, bits << 1 | 1u);
}

static void photon_radius_rec(const photon_radius_query *qr, const photon_cell *cell)
{
    if (cell->hi - cell->lo <= PHOTON_MAP_LEAF || cell->level == PHOTON_MAP_LEVELS) {
        /* 64 records at a time: which of them may lie within the radius, as a mask of
         * compares without branches (most do not: a branch per record mispredicts), in
         * floats against a bound that every record within the radius meets (twice the
         * lanes of doubles), then each candidate's distance in double and the visits in
         * record order: the same visits as a test in double alone. */
        const float qf[3] = {(float)qr->q[0], (float)qr->q[1], (float)qr->q[2]};
        const float r2f = qr->radius2_pre;
        for (size_t i0 = cell->lo; i0 < cell->hi; i0 += 64) {
            size_t n = cell->hi - i0 < 64 ? cell->hi - i0 : 64;
            uint64_t inside = 0;
            for (size_t j = 0; j < n; j++) {
                const float *pp = qr->r[i0 + j].position_m;
                float dx = pp[0] - qf[0], dy = pp[1] - qf[1], dz = pp[2] - qf[2];
                inside |= (uint64_t)(dx * dx + dy * dy + dz * dz <= r2f) << j;
            }
            while (inside) {
                size_t i = i0 + (size_t)__builtin_ctzll(inside);
                inside &= inside - 1;
                double d2 = photon_distance2(&qr->r[i], qr->q);
                if (d2 <= qr->radius2)
                    qr->visit(qr->ctx, &qr->r[i], d2);
            }
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
    photon_map_radius_in(map, NULL, object, side, position_m, radius2_m2, visit, ctx);
}

void photon_map_radius_in(const photon_map *map, const photon_map_directory *dir, uint32_t object,
                          int side, vec3 position_m, double radius2_m2, photon_visit_fn visit,
                          void *ctx)
{
    size_t lo, n;
    if (!(radius2_m2 >= 0.0) || !photon_group_range(map, object, side, &lo, &n))
        return;
    size_t g = (size_t)object * 2 + (size_t)side;
    bool indexed = dir && g < dir->n_groups && dir->level[g] > 0;
    photon_radius_query qr = {.cube = &map->cubes[g],
                              .r = map->records,
                              .dir_level = indexed ? dir->level[g] : 0,
                              .dir_starts = indexed ? dir->starts[g] : NULL,
                              .dir_base = lo,
                              .q = {position_m.x, position_m.y, position_m.z},
                              .radius2 = radius2_m2,
                              .radius = sqrt(radius2_m2),
                              .visit = visit,
                              .ctx = ctx};
    /* The float test's bound: q rounded to float moves it by at most u |q| a coordinate
     * (u = 2^-24), each difference rounds by (1 + u) and the sum of squares by at most
     * (1 + u)^3, so a record within the radius has a float distance^2 below
     * (1 + 3.01 u) ((1 + u) r + 3 u max|q|)^2; the margin 8 u covers that and the
     * bound's own rounding to float. */
    double qmax = fmax(fabs(qr.q[0]), fmax(fabs(qr.q[1]), fabs(qr.q[2])));
    double u = 0x1p-24, bound = (1.0 + u) * qr.radius + 3.0 * u * qmax;
    qr.radius2_pre = (float)(bound * bound * (1.0 + 8.0 * u));
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
    /* fewer than k found only from a position that is not a number (every comparison
     * false): as with fewer than k photons */
    double result = h.size == k ? h.heap[0] : INFINITY;
    if (h.heap != stack_heap)
        free(h.heap);
    return result;
}
