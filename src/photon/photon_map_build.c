/* The photon map's build: the records grouped by (object, side), each group sorted by
 * Morton code and then bytes (photon_map.c says why that order), in passes that each
 * split the records over the threads:
 *
 *  1. scan: each part of the array (a contiguous range; one per thread) counts its records
 *     of each group and takes the groups' bounding boxes, which give the groups' cubes;
 *  2. group: each part moves its records to a second array, into its own slot of each
 *     group (after the earlier parts'); a record of a large group carries there, in its
 *     object_side, the first digit of its code (PHOTON_MAP_FIRST_LEVELS levels), and the
 *     part counts those digits;
 *  3. split: each part moves its records of the large groups back, into its slot of
 *     their digit's range (after the earlier digits' and the earlier parts');
 *  4. sort: each digit's range of a large group, and each small group, is sorted alone
 *     (photon_build_sort_range), in cache but for the largest.
 *
 * Records already in the map's order (a map's own, as a photon-map file keeps them) are
 * found so by pass 1's check (photon_build_in_order) and not moved: no second array.
 *
 * Each pass streams the records, or a cached range of them, from one array to the other.
 * The in-place build it replaces (a serial permutation by group, then per group an
 * American flag sort whose first pass over the largest group was serial too) swapped
 * the records along permutation cycles, a cache miss per record in the passes over the
 * whole array; it took 62 ns per record on 1 thread and 35-46 on 2 (the paper's case,
 * 5.06 M records, warm memory, fastest of 6 builds on a loaded machine), this one 36 and
 * 20. The price is memory: the second array is as large as the records (the peak is
 * twice the map, as the run's estimate allows), kept in the pool between builds.
 */
#include "photon/photon_map.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "photon/photon_map_layout.h"

#ifdef _OPENMP
#include <omp.h>
#endif

/* Ranges up to this many records (2 MB) are sorted 64 buckets at a time. */
#define PHOTON_MAP_CACHED 65536
/* Ranges up to this many records are sorted by insertion. */
#define PHOTON_MAP_SORT_SMALL 16
/* Groups of this many records or more are split by their first digit over the threads
 * (pass 3); smaller ones are sorted by one thread each. */
#define PHOTON_MAP_LARGE PHOTON_MAP_CACHED
/* Levels of the first digit of a large group: 4096 ranges, a few thousand records each
 * in the paper's case (a plane's records fill a sixteenth of them). */
#define PHOTON_MAP_FIRST_LEVELS 4
#define PHOTON_MAP_DIGITS (1u << (3 * PHOTON_MAP_FIRST_LEVELS))
/* Below this many records, one part (not worth waking threads for). */
#define PHOTON_MAP_PARTS_MIN 65536

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

/* 7 bits spread to every third bit (bit i to bit 3i), for the table below. */
#define PHOTON_SPREAD7(i)                                                                          \
    (((i)&1u) | ((i)&2u) << 2 | ((i)&4u) << 4 | ((i)&8u) << 6 | ((i)&16u) << 8 | ((i)&32u) << 10 | \
     ((i)&64u) << 12)
#define PHOTON_SPREAD7_4(i)                                                                        \
    PHOTON_SPREAD7(i), PHOTON_SPREAD7(i + 1u), PHOTON_SPREAD7(i + 2u), PHOTON_SPREAD7(i + 3u)
#define PHOTON_SPREAD7_16(i)                                                                       \
    PHOTON_SPREAD7_4(i), PHOTON_SPREAD7_4(i + 4u), PHOTON_SPREAD7_4(i + 8u),                       \
        PHOTON_SPREAD7_4(i + 12u)

/* 7 bits spread to every third bit. */
static const uint32_t photon_spread7[128] = {PHOTON_SPREAD7_16(0u),  PHOTON_SPREAD7_16(16u),
                                             PHOTON_SPREAD7_16(32u), PHOTON_SPREAD7_16(48u),
                                             PHOTON_SPREAD7_16(64u), PHOTON_SPREAD7_16(80u),
                                             PHOTON_SPREAD7_16(96u), PHOTON_SPREAD7_16(112u)};

/* The low 21 bits of v spread to every third bit (bit i to bit 3i), 7 bits at a time from
 * the table: 2/3 of the instructions of the shift-and-mask version, whose codes took 43 %
 * of the build's instructions. */
static uint64_t photon_spread3(uint32_t v)
{
    return (uint64_t)photon_spread7[v & 127u] | (uint64_t)photon_spread7[v >> 7 & 127u] << 21 |
           (uint64_t)photon_spread7[v >> 14 & 127u] << 42;
}

/* The full Morton code (3 LEVELS bits; x the highest bit of each level). */
static uint64_t photon_morton(const photon_cube *c, const photon_record *p)
{
    return photon_spread3(photon_quantize_axis(c, p, 0)) << 2 |
           photon_spread3(photon_quantize_axis(c, p, 1)) << 1 |
           photon_spread3(photon_quantize_axis(c, p, 2));
}

/* The first PHOTON_MAP_FIRST_LEVELS levels' digits of the record's Morton code
 * (photon_code_digits(photon_morton(c, p), 1, PHOTON_MAP_FIRST_LEVELS)), from the
 * quantised coordinates' top bits alone. */
static unsigned photon_first_digit(const photon_cube *c, const photon_record *p)
{
    _Static_assert(PHOTON_MAP_FIRST_LEVELS <= 7, "the table spreads 7 bits");
    const int shift = PHOTON_MAP_LEVELS - PHOTON_MAP_FIRST_LEVELS;
    return photon_spread7[photon_quantize_axis(c, p, 0) >> shift] << 2 |
           photon_spread7[photon_quantize_axis(c, p, 1) >> shift] << 1 |
           photon_spread7[photon_quantize_axis(c, p, 2) >> shift];
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
 * levels 1..level-1, by code and then bytes: American flag sort, in place. The build
 * uses it for the records whose codes tie in the 32 bits its radix sort looked at.
 * Ranges larger than the caches go three levels (512 buckets) at a time, since every
 * pass over them costs a cache miss per record; cached ones two levels (64 buckets) at
 * a time. */
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

/* One build: the records, the second array, and what the passes hand on. The per-part
 * arrays have a row per part, rows a cache line apart at least (stride n_groups + 8):
 * each part writes its own row for every record. */
typedef struct photon_build {
    photon_record *r; /* the records: the input, then the map */
    photon_record *s; /* the second array, count records */
    size_t count, n_groups, stride;
    int parts;
    size_t *part_count;      /* [p][g]: part p's records of group g (pass 1) */
    size_t *part_next;       /* [p][g]: its next slot in the second array (pass 2) */
    photon_bounds *part_box; /* [p][g]: the bounding box of those records */
    size_t *first_bad;       /* [p]: the part's first record naming no group, or count */
    size_t *start;           /* n_groups + 1: the map's group offsets */
    photon_cube *cubes;      /* n_groups: the map's cubes */
    size_t *large_of;        /* [g]: g's index among the large groups, or SIZE_MAX */
    size_t *large_group;     /* the large groups */
    size_t n_large;
    size_t *digit_next; /* [p][large][digit]: counts (pass 2), then slots (pass 3) */
} photon_build;

static void photon_part_range(const photon_build *b, int p, size_t *lo, size_t *hi)
{
    size_t step = b->count / (size_t)b->parts;
    *lo = step * (size_t)p;
    *hi = p == b->parts - 1 ? b->count : step * (size_t)(p + 1);
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
        const photon_record *q = &b->r[i];
        if (q->object_side >= b->n_groups) {
            b->first_bad[p] = i;
            return;
        }
        cnt[q->object_side]++;
        photon_bounds *bb = &box[q->object_side];
        for (int a = 0; a < 3; a++) {
            double v = q->position_m[a];
            bb->lo[a] = v < bb->lo[a] ? v : bb->lo[a];
            bb->hi[a] = v > bb->hi[a] ? v : bb->hi[a];
        }
    }
}

/* After pass 1: the groups' offsets and cubes (the parts' boxes and counts combined
 * exactly: minima, maxima and integer sums, so the number of parts changes nothing), each
 * part's first slot in each group, and the large groups. Returns count, or the first
 * record that names no group. */
static size_t photon_build_layout(photon_build *b)
{
    size_t bad = b->count;
    for (int p = 0; p < b->parts; p++)
        bad = b->first_bad[p] < bad ? b->first_bad[p] : bad;
    if (bad < b->count)
        return bad;
    b->start[0] = 0;
    b->n_large = 0;
    for (size_t g = 0; g < b->n_groups; g++) {
        photon_bounds box = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        size_t n = 0;
        for (int p = 0; p < b->parts; p++) {
            size_t at = (size_t)p * b->stride + g;
            b->part_next[at] = b->start[g] + n;
            n += b->part_count[at];
            for (int a = 0; a < 3; a++) {
                box.lo[a] = b->part_box[at].lo[a] < box.lo[a] ? b->part_box[at].lo[a] : box.lo[a];
                box.hi[a] = b->part_box[at].hi[a] > box.hi[a] ? b->part_box[at].hi[a] : box.hi[a];
            }
        }
        b->start[g + 1] = b->start[g] + n;
        b->cubes[g] = photon_group_cube(&box);
        b->large_of[g] = SIZE_MAX;
        if (n >= PHOTON_MAP_LARGE) {
            b->large_of[g] = b->n_large;
            b->large_group[b->n_large++] = g;
        }
    }
    return b->count;
}

/* After pass 1, for part p: whether its records, and the one before them, are in the map's
 * order already: groups ascending; within a group, Morton codes in the group's cube
 * ascending, ties by bytes; flags bits 16..17 clear (what pass 2 clears). Read only. */
static bool photon_build_in_order(const photon_build *b, int p)
{
    size_t lo, hi;
    photon_part_range(b, p, &lo, &hi);
    size_t first = lo > 0 ? lo - 1 : 0;
    uint64_t prev_code = 0;
    for (size_t i = first; i < hi; i++) {
        const photon_record *q = &b->r[i];
        if (q->flags & 3u << 16)
            return false;
        uint64_t code = photon_morton(&b->cubes[q->object_side], q);
        if (i > first) {
            const photon_record *before = q - 1;
            if (before->object_side > q->object_side)
                return false;
            if (before->object_side == q->object_side &&
                (prev_code > code || (prev_code == code && memcmp(before, q, sizeof *q) > 0)))
                return false;
        }
        prev_code = code;
    }
    return true;
}

/* Pass 2 for part p: its records into their group's slots of the second array, a large
 * group's carrying their first digit in object_side (the group is known from the slot),
 * counted. Also clears bits 16..17 of flags (a kd-tree's split axis in maps before the
 * octree; kept zero). */
static void photon_build_group(photon_build *b, int p)
{
    size_t lo, hi;
    photon_part_range(b, p, &lo, &hi);
    size_t *next = b->part_next + (size_t)p * b->stride;
    size_t *digits = b->digit_next + (size_t)p * b->n_large * PHOTON_MAP_DIGITS;
    memset(digits, 0, b->n_large * PHOTON_MAP_DIGITS * sizeof *digits);
    for (size_t i = lo; i < hi; i++) {
        photon_record rec = b->r[i];
        size_t g = rec.object_side;
        rec.flags &= ~(3u << 16);
        size_t large = b->large_of[g];
        if (large != SIZE_MAX) {
            unsigned d = photon_first_digit(&b->cubes[g], &rec);
            digits[large * PHOTON_MAP_DIGITS + d]++;
            rec.object_side = d;
        }
        b->s[next[g]++] = rec;
    }
}

/* After pass 2: the parts' first slots in each digit's range of each large group (the
 * digits in order, within a digit the parts in order). */
static void photon_build_digit_slots(photon_build *b)
{
    for (size_t l = 0; l < b->n_large; l++) {
        size_t at = b->start[b->large_group[l]];
        for (unsigned d = 0; d < PHOTON_MAP_DIGITS; d++) {
            for (int p = 0; p < b->parts; p++) {
                size_t *slot = &b->digit_next[((size_t)p * b->n_large + l) * PHOTON_MAP_DIGITS + d];
                size_t n = *slot;
                *slot = at;
                at += n;
            }
        }
    }
}

/* Pass 3 for part p: its records of the large groups (where pass 2 put them: after the
 * earlier parts', up to its own next slot) back into their digit's slots, their
 * object_side restored. */
static void photon_build_split(photon_build *b, int p)
{
    for (size_t l = 0; l < b->n_large; l++) {
        size_t g = b->large_group[l];
        size_t lo = p > 0 ? b->part_next[(size_t)(p - 1) * b->stride + g] : b->start[g];
        size_t hi = b->part_next[(size_t)p * b->stride + g];
        size_t *slot = b->digit_next + ((size_t)p * b->n_large + l) * PHOTON_MAP_DIGITS;
        for (size_t i = lo; i < hi; i++) {
            photon_record rec = b->s[i];
            size_t j = slot[rec.object_side]++;
            rec.object_side = (uint32_t)g;
            b->r[j] = rec;
        }
    }
}

/* Sorts records [lo, hi) of group g, whose codes share levels 1..level-1 (level 1 or
 * 1 + PHOTON_MAP_FIRST_LEVELS), into the map's range; they start there, or in the second
 * array's range (in_scratch). An LSD radix sort, 8 bits a pass, by the next 32 bits of
 * their codes (10 levels and 2 bits), carried in object_side (the group's, restored
 * after), the records going back and forth between the two ranges; then each run of
 * records whose 32 bits tie sorted by full code and bytes (photon_sort; their codes in
 * the second array's range, free by then). In place, the American flag sort swapped
 * every record along a cycle at every second level, 37 of the build's 66 ns per record
 * (paper's case, 1 thread); this moves it once a pass, at 4 passes. */
static void photon_build_sort_range(const photon_build *b, size_t g, size_t lo, size_t hi,
                                    int level, bool in_scratch)
{
    _Static_assert(1 + PHOTON_MAP_FIRST_LEVELS <= 11, "the 32 bits must lie in the code");
    const size_t n = hi - lo;
    const int shift = 31 - 3 * (level - 1); /* the code's next 32 bits: [shift, shift + 32) */
    const photon_cube *cube = &b->cubes[g];
    photon_record *src = (in_scratch ? b->s : b->r) + lo, *dst = (in_scratch ? b->r : b->s) + lo;
    size_t count[4][256] = {{0}};
    for (size_t i = 0; i < n; i++) {
        uint32_t key = (uint32_t)(photon_morton(cube, &src[i]) >> shift);
        src[i].object_side = key;
        for (int d = 0; d < 4; d++)
            count[d][key >> 8 * d & 255u]++;
    }
    for (int d = 0; d < 4; d++) {
        size_t at = 0, *next = count[d];
        bool one = false; /* all in one bucket: nothing to move */
        for (int k = 0; k < 256; k++) {
            size_t c = next[k];
            one = one || c == n;
            next[k] = at;
            at += c;
        }
        if (one)
            continue;
        for (size_t i = 0; i < n; i++)
            dst[next[src[i].object_side >> 8 * d & 255u]++] = src[i];
        photon_record *t = src;
        src = dst;
        dst = t;
    }
    photon_record *r = b->r + lo;
    if (src != r)
        memcpy(r, src, n * sizeof *r);
    for (size_t i = 0; i < n;) {
        uint32_t key = r[i].object_side;
        size_t j = i;
        while (j < n && r[j].object_side == key)
            r[j++].object_side = (uint32_t)g;
        if (j - i > 1) {
            uint64_t *code = (uint64_t *)(void *)(b->s + lo + i);
            for (size_t k = i; k < j; k++)
                code[k - i] = photon_morton(cube, &r[k]);
            photon_sort(r + i, code, j - i, level + 10);
        }
        i = j;
    }
}

/* Pass 4, item k: small group k (k < n_groups; copied back from the second array
 * first), or a digit's range of a large group. */
static void photon_build_sort_item(const photon_build *b, size_t k)
{
    if (k < b->n_groups) {
        size_t lo = b->start[k], hi = b->start[k + 1];
        if (b->large_of[k] != SIZE_MAX || hi == lo)
            return;
        photon_build_sort_range(b, k, lo, hi, 1, true);
        return;
    }
    size_t l = (k - b->n_groups) / PHOTON_MAP_DIGITS;
    unsigned d = (unsigned)((k - b->n_groups) % PHOTON_MAP_DIGITS);
    size_t g = b->large_group[l];
    /* after pass 3, the last part's slot of each digit is where the digit's range ends */
    const size_t *end =
        b->digit_next + ((size_t)(b->parts - 1) * b->n_large + l) * PHOTON_MAP_DIGITS;
    photon_build_sort_range(b, g, d > 0 ? end[d - 1] : b->start[g], end[d],
                            1 + PHOTON_MAP_FIRST_LEVELS, false);
}

/* ---- The build -------------------------------------------------------------------------- */

/* More parts than this gain nothing (and keep the per-part arrays' sizes far from
 * overflow: n_groups <= 2^32). */
#define PHOTON_MAP_PARTS_MAX 1024

thz_status photon_map_create(photon_record *photons, size_t count, size_t n_objects, int threads,
                             photon_map **out, thz_error *err)
{
    return photon_map_build(photons, count, count, n_objects, threads, NULL, out, err);
}

/* Points b's per-part and per-group arrays into index (photon_map_index_scratch); returns
 * the bytes they take, or 0 with index NULL (to size it). */
static size_t photon_build_arrays(photon_build *b, void *index)
{
    const size_t parts = (size_t)b->parts, rows = parts * b->stride;
    size_t max_large = b->count / PHOTON_MAP_LARGE;
    max_large = max_large < b->n_groups ? max_large : b->n_groups;
    size_t boxes = rows * sizeof(photon_bounds);
    size_t sizes = 2 * rows + parts + 2 * b->n_groups + parts * max_large * PHOTON_MAP_DIGITS;
    if (!index)
        return boxes + sizes * sizeof(size_t);
    b->part_box = index;
    size_t *at = (size_t *)(void *)((char *)index + boxes);
    b->part_count = at;
    b->part_next = at + rows;
    b->first_bad = at + 2 * rows;
    b->large_of = b->first_bad + parts;
    b->large_group = b->large_of + b->n_groups;
    b->digit_next = b->large_group + b->n_groups;
    return boxes + sizes * sizeof(size_t);
}

thz_status photon_map_build(photon_record *photons, size_t count, size_t capacity, size_t n_objects,
                            int threads, photon_map_pool *pool, photon_map **out, thz_error *err)
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
    if (n_objects > (SIZE_MAX - 1) / 2 || n_objects > UINT32_MAX / 2) {
        st = thz_error_set(err, THZ_ERR_LIMIT, "photon map: %zu objects is too many", n_objects);
        goto cleanup;
    }
    const size_t n_groups = 2 * n_objects;
    int nt = 1;
#ifdef _OPENMP
    nt = threads > 0 ? threads : omp_get_max_threads();
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
    /* The second array (32 bytes per record: the peak is twice the map), kept in the pool
     * for the next build. */
    scratch = photon_map_pool_scratch(pool, count);
    if (!scratch) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for %zu photons", count);
        goto cleanup;
    }
    b.s = scratch;
    const size_t n_items = n_groups + b.n_large * PHOTON_MAP_DIGITS;
#pragma omp parallel num_threads(b.parts)
    {
#pragma omp for schedule(static, 1)
        for (int p = 0; p < b.parts; p++)
            photon_build_group(&b, p);
#pragma omp single
        photon_build_digit_slots(&b);
#pragma omp for schedule(static, 1)
        for (int p = 0; p < b.parts; p++)
            photon_build_split(&b, p);
#pragma omp for schedule(dynamic, 1)
        for (size_t k = 0; k < n_items; k++)
            photon_build_sort_item(&b, k);
    }

built:
    map->records = photons;
    map->count = count;
    map->capacity = capacity > count ? capacity : count;
    map->n_groups = n_groups;
    photons = NULL; /* owned by map now */
    *out = map;
    map = NULL;
cleanup:
    if (!pool) {
        free(scratch);
        free(index);
    }
    free(photons);
    photon_map_destroy(map);
    return st;
}
