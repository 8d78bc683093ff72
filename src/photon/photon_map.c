/* Photon map: records grouped by (object, side), each group an implicit balanced
 * kd-tree in a flat array (Jensen's balanced kd-tree, Radiance's pmapkdt).
 *
 * Layout. The records are reordered in place, with no per-photon side array, so the
 * map costs exactly 32 bytes per photon plus one offset per (object, side). Group g =
 * object << 1 | side occupies [start[g], start[g+1]). Within a group a subtree over
 * [lo, hi) has its node at mid = lo + (hi - lo) / 2: the median along the node's split
 * axis, with [lo, mid) before and [mid + 1, hi) after it in that axis' order. The split
 * axis (0, 1, 2 = x, y, z; the axis of largest extent of the subtree's points) is kept
 * in bits 16..17 of the node's `flags`; the low 16 bits keep the bounce count.
 *
 * Determinism. Records are ordered by a total order (the split coordinate's bits
 * mapped to a sortable integer, then the record's bytes), so every position of the
 * final array is a function of the group's multiset of records alone: neither the
 * input order nor the thread count changes a byte of the result.
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

#define PHOTON_MAP_AXIS_SHIFT 16u
#define PHOTON_MAP_AXIS_MASK (3u << PHOTON_MAP_AXIS_SHIFT)
/* Subtrees larger than this are built as separate OpenMP tasks. */
#define PHOTON_MAP_TASK_MIN 8192
/* k up to this uses a heap on the stack; larger k allocates one per query. */
#define PHOTON_MAP_STACK_K 256

struct photon_map {
    photon_record *records;
    size_t count;
    size_t n_groups; /* 2 n_objects */
    size_t *start;   /* n_groups + 1 offsets */
};

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
    /* Of the four codes around (x, y) (floor and ceiling in each axis), keep the one
     * that decodes closest to dir (the rounded one is not always best near the fold).
     * Compared by dot(d, dir)^2 / |d|^2 over candidates of positive dot, so no square
     * root or division is needed per candidate. */
    double fx = (x * 0.5 + 0.5) * 65535.0, fy = (y * 0.5 + 0.5) * 65535.0;
    int64_t qx0 = (int64_t)floor(fx), qy0 = (int64_t)floor(fy);
    uint32_t best = photon_quantize(x) << 16 | photon_quantize(y);
    double best_num = -1.0, best_den = 1.0;
    for (int64_t qx = qx0; qx <= qx0 + 1; qx++) {
        for (int64_t qy = qy0; qy <= qy0 + 1; qy++) {
            if (qx < 0 || qy < 0 || qx > 65535 || qy > 65535)
                continue;
            double cx = photon_dequantize((uint32_t)qx), cy = photon_dequantize((uint32_t)qy);
            double cz = 1.0 - fabs(cx) - fabs(cy);
            if (cz < 0.0) {
                double ox = cx;
                cx = (1.0 - fabs(cy)) * photon_sign(ox);
                cy = (1.0 - fabs(ox)) * photon_sign(cy);
            }
            double dot = cx * dir.x + cy * dir.y + cz * dir.z;
            if (!(dot > 0.0))
                continue;
            double num = dot * dot, den = cx * cx + cy * cy + cz * cz;
            if (num * best_den > best_num * den) {
                best_num = num;
                best_den = den;
                best = (uint32_t)qx << 16 | (uint32_t)qy;
            }
        }
    }
    return best;
}

vec3 photon_decode_direction(uint32_t code)
{
    return photon_decode_xy(photon_dequantize(code >> 16), photon_dequantize(code & 0xffffu));
}

/* ---- Build -------------------------------------------------------------------------- */

static unsigned photon_axis(const photon_record *p)
{
    return (p->flags & PHOTON_MAP_AXIS_MASK) >> PHOTON_MAP_AXIS_SHIFT;
}

/* Float bits mapped so that unsigned order is the numeric order (total, -0 < +0). */
static uint32_t photon_sortable(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

/* Total order along axis: coordinate, then the record's bytes. */
static int photon_compare(const photon_record *a, const photon_record *b, unsigned axis)
{
    uint32_t ka = photon_sortable(a->position_m[axis]);
    uint32_t kb = photon_sortable(b->position_m[axis]);
    if (ka != kb)
        return ka < kb ? -1 : 1;
    return memcmp(a, b, sizeof *a);
}

/* a before (key, record) t in the total order; the key compare settles almost all. */
static bool photon_before(const photon_record *a, uint32_t key_t, const photon_record *t,
                          unsigned axis)
{
    uint32_t ka = photon_sortable(a->position_m[axis]);
    if (ka != key_t)
        return ka < key_t;
    return memcmp(a, t, sizeof *a) < 0;
}

static void photon_swap(photon_record *a, photon_record *b)
{
    photon_record t = *a;
    *a = *b;
    *b = t;
}

/* Rearranges r[left..right] so that r[k] is the element of rank k - left, smaller ones
 * before it and larger ones after: Floyd and Rivest's SELECT (1975). Large ranges first
 * select within a sample-sized window around k, recursively, which leaves a pivot at k
 * whose rank is close to k, so one partition pass brings the range down to a window of
 * o(n): about 1.5 n comparisons for a median instead of quickselect's 3.4 n. */
static void photon_select_range(photon_record *r, int64_t left, int64_t right, int64_t k,
                                unsigned axis)
{
    while (right > left) {
        if (right - left > 600) {
            double n = (double)(right - left + 1);
            double i = (double)(k - left + 1);
            double z = log(n);
            double sz = 0.5 * exp(2.0 * z / 3.0);
            double sd = 0.5 * sqrt(z * sz * (n - sz) / n) * (i - n / 2.0 < 0.0 ? -1.0 : 1.0);
            int64_t nl = (int64_t)((double)k - i * sz / n + sd);
            int64_t nr = (int64_t)((double)k + (n - i) * sz / n + sd);
            photon_select_range(r, nl > left ? nl : left, nr < right ? nr : right, k, axis);
        }
        const photon_record t = r[k];
        const uint32_t tk = photon_sortable(t.position_m[axis]);
        int64_t i = left, j = right;
        photon_swap(&r[left], &r[k]);
        if (photon_compare(&r[right], &t, axis) > 0)
            photon_swap(&r[right], &r[left]);
        while (i < j) {
            photon_swap(&r[i], &r[j]);
            i++;
            j--;
            while (photon_before(&r[i], tk, &t, axis))
                i++;
            while (photon_compare(&r[j], &t, axis) > 0)
                j--;
        }
        if (photon_compare(&r[left], &t, axis) == 0) {
            photon_swap(&r[left], &r[j]);
        } else {
            j++;
            photon_swap(&r[j], &r[right]);
        }
        if (j <= k)
            left = j + 1;
        if (k <= j)
            right = j - 1;
    }
}

static void photon_select(photon_record *r, size_t n, size_t k, unsigned axis)
{
    if (n > 1)
        photon_select_range(r, 0, (int64_t)n - 1, (int64_t)k, axis);
}

/* The box a subtree's points lie in: the group's bounding box cut by the split planes of
 * the subtree's ancestors. Its widest side is the subtree's split axis, which saves a
 * pass over the points per level (the points' own bounding box would need one). */
typedef struct photon_cell {
    float lo[3], hi[3];
} photon_cell;

static photon_cell photon_bounds(const photon_record *r, size_t n)
{
    photon_cell c;
    for (int a = 0; a < 3; a++)
        c.lo[a] = c.hi[a] = r[0].position_m[a];
    for (size_t i = 1; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            float v = r[i].position_m[a];
            if (v < c.lo[a])
                c.lo[a] = v;
            if (v > c.hi[a])
                c.hi[a] = v;
        }
    }
    return c;
}

static unsigned photon_widest_axis(const photon_cell *c)
{
    double ex = (double)c->hi[0] - c->lo[0], ey = (double)c->hi[1] - c->lo[1],
           ez = (double)c->hi[2] - c->lo[2];
    if (ex >= ey && ex >= ez)
        return 0;
    return ey >= ez ? 1 : 2;
}

static void photon_build(photon_record *r, size_t n, photon_cell cell)
{
    while (n > 0) {
        size_t mid = n / 2;
        unsigned axis = n > 1 ? photon_widest_axis(&cell) : 0;
        if (n > 1)
            photon_select(r, n, mid, axis);
        r[mid].flags = (r[mid].flags & ~PHOTON_MAP_AXIS_MASK) | axis << PHOTON_MAP_AXIS_SHIFT;
        photon_cell left_cell = cell;
        left_cell.hi[axis] = r[mid].position_m[axis];
        cell.lo[axis] = r[mid].position_m[axis];
        if (mid >= PHOTON_MAP_TASK_MIN) {
            photon_record *left = r;
#pragma omp task firstprivate(left, mid, left_cell)
            photon_build(left, mid, left_cell);
        } else {
            photon_build(r, mid, left_cell);
        }
        /* the right subtree in this task (loop instead of recursion) */
        r += mid + 1;
        n -= mid + 1;
    }
}

/* Groups records by object_side in place (American flag sort: counts, then cycles);
 * the order within a group is irrelevant since the kd-tree build fixes it. */
static void photon_group(photon_record *r, size_t count, size_t n_groups, size_t *start,
                         size_t *next)
{
    for (size_t g = 0; g <= n_groups; g++)
        start[g] = 0;
    for (size_t i = 0; i < count; i++)
        start[r[i].object_side + 1]++;
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

thz_status photon_map_create(photon_record *photons, size_t count, size_t n_objects, int threads,
                             photon_map **out, thz_error *err)
{
    thz_status st = THZ_OK;
    photon_map *map = NULL;
    size_t *next = NULL;
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
    for (size_t i = 0; i < count; i++) {
        if (photons[i].object_side >= n_groups) {
            st = thz_error_set(err, THZ_ERR_INTERNAL,
                               "photon map: photon %zu names object %u of %zu", i,
                               (unsigned)photon_object(&photons[i]), n_objects);
            goto cleanup;
        }
        photons[i].flags &= ~PHOTON_MAP_AXIS_MASK;
    }
    map = calloc(1, sizeof *map);
    if (map)
        map->start = thz_calloc(n_groups + 1, sizeof *map->start);
    next = thz_calloc(n_groups + 1, sizeof *next);
    if (!map || !map->start || !next) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu objects",
                           n_objects);
        goto cleanup;
    }
    photon_group(photons, count, n_groups, map->start, next);
    map->records = photons;
    map->count = count;
    map->n_groups = n_groups;
    photons = NULL; /* owned by map now */

#ifdef _OPENMP
    int nt = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel num_threads(nt)
#pragma omp single
#else
    (void)threads;
#endif
    for (size_t g = 0; g < n_groups; g++) {
        size_t lo = map->start[g], n = map->start[g + 1] - lo;
        if (n == 0)
            continue;
        photon_record *r = map->records + lo;
#pragma omp task firstprivate(r, n)
        photon_build(r, n, photon_bounds(r, n));
    }

    *out = map;
    map = NULL;
cleanup:
    free(next);
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
    free(map);
}

size_t photon_map_count(const photon_map *map)
{
    return map ? map->count : 0;
}

size_t photon_map_bytes(const photon_map *map)
{
    if (!map)
        return 0;
    return sizeof *map + map->count * sizeof *map->records + (map->n_groups + 1) * sizeof *map->start;
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
    double q[3];
    double radius2;
    photon_visit_fn visit;
    void *ctx;
} photon_radius_query;

static void photon_radius_rec(const photon_radius_query *qr, const photon_record *r, size_t n)
{
    while (n > 0) {
        size_t mid = n / 2;
        const photon_record *node = &r[mid];
        double d2 = photon_distance2(node, qr->q);
        if (d2 <= qr->radius2)
            qr->visit(qr->ctx, node, d2);
        unsigned axis = photon_axis(node);
        double d = qr->q[axis] - (double)node->position_m[axis];
        /* Near side first (recursively), far side only if the plane is within reach;
         * points on the plane may be on either side. */
        if (d < 0.0) {
            if (d * d <= qr->radius2)
                photon_radius_rec(qr, r + mid + 1, n - mid - 1);
            n = mid;
        } else {
            if (d * d <= qr->radius2)
                photon_radius_rec(qr, r, mid);
            r += mid + 1;
            n -= mid + 1;
        }
    }
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

void photon_map_radius(const photon_map *map, uint32_t object, int side, vec3 position_m,
                       double radius2_m2, photon_visit_fn visit, void *ctx)
{
    size_t lo, n;
    if (!(radius2_m2 >= 0.0) || !photon_group_range(map, object, side, &lo, &n))
        return;
    photon_radius_query qr = {{position_m.x, position_m.y, position_m.z}, radius2_m2, visit,
                              ctx};
    photon_radius_rec(&qr, map->records + lo, n);
}

/* A bounded max-heap of the k smallest squared distances seen. */
typedef struct photon_knn {
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

/* Current pruning bound: the k-th distance once k are known, else infinity. */
static double photon_knn_bound(const photon_knn *h)
{
    return h->size < h->k ? INFINITY : h->heap[0];
}

static void photon_knn_rec(photon_knn *h, const photon_record *r, size_t n)
{
    while (n > 0) {
        size_t mid = n / 2;
        const photon_record *node = &r[mid];
        unsigned axis = photon_axis(node);
        double d = h->q[axis] - (double)node->position_m[axis];
        double d2 = photon_distance2(node, h->q);
        if (d2 < photon_knn_bound(h))
            photon_knn_push(h, d2);
        const photon_record *near_r, *far_r;
        size_t near_n, far_n;
        if (d < 0.0) {
            near_r = r;
            near_n = mid;
            far_r = r + mid + 1;
            far_n = n - mid - 1;
        } else {
            near_r = r + mid + 1;
            near_n = n - mid - 1;
            far_r = r;
            far_n = mid;
        }
        photon_knn_rec(h, near_r, near_n);
        if (!(d * d < photon_knn_bound(h)))
            return;
        r = far_r;
        n = far_n;
    }
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
    photon_knn h = {{position_m.x, position_m.y, position_m.z}, stack_heap, 0, k};
    if (k > PHOTON_MAP_STACK_K) {
        /* Documented exception to "queries allocate nothing": k above 256. */
        h.heap = thz_malloc_array(k, sizeof *h.heap);
        if (!h.heap)
            return NAN;
    }
    for (int s = 0; s < 2; s++)
        if (has[s])
            photon_knn_rec(&h, map->records + lo[s], n[s]);
    double result = h.heap[0];
    if (h.heap != stack_heap)
        free(h.heap);
    return result;
}
