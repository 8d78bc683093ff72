/* The sort of a range of a group's records by Morton code and then bytes
 * (photon_map_order.h).
 */
#include "photon/photon_map_order.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* Ranges up to this many records (2 MB) are sorted 64 buckets at a time. */
#define PHOTON_MAP_CACHED 65536
/* Ranges up to this many records are sorted by insertion. */
#define PHOTON_MAP_SORT_SMALL 16

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

/* The pairs of photon_sort_range live in the destination's bytes, where a record's start
 * need not be 8-byte aligned: loaded and stored through memcpy (a plain move). */
static inline uint64_t photon_pair_get(const unsigned char *pairs, size_t i)
{
    uint64_t v;
    memcpy(&v, pairs + 8 * i, sizeof v);
    return v;
}
static inline void photon_pair_set(unsigned char *pairs, size_t i, uint64_t v)
{
    memcpy(pairs + 8 * i, &v, sizeof v);
}

/* An LSD radix sort, 8 bits a pass, of 64-bit pairs: the next 32 bits of a record's code
 * (10 levels and 2 bits) above its index. The pairs live in the last 16 bytes per record
 * of r (two arrays of 8 bytes per record), the sorted ones last, so that moving the
 * records into their places, first to last, overwrites only pairs already read (record i
 * ends at byte R i + R, R = sizeof(photon_record); pair j > i starts at byte
 * (R - 8) n + 8 j >= R i + R). The move marks the first record of each run of records
 * whose 32 bits tie (the tag's group bits, all g's in this range, free until then); each
 * run is then sorted by full code and bytes (photon_sort; their codes in the scratch, free
 * by then). Sorting the records themselves moved 32 bytes a pass instead of 8: 9 % more
 * build time (12.1 M records, 2 threads, six alternating runs each: 0.408 against
 * 0.375 s). In place, the American flag sort swapped every record along a cycle at every
 * second level: 37 of the build's 66 ns per record (paper's case, 1 thread). */
void photon_sort_range(const photon_cube *cube, photon_record *scratch, photon_record *r, size_t n,
                       int level, uint32_t g)
{
    _Static_assert(1 + PHOTON_MAP_FIRST_LEVELS <= 11, "the 32 bits must lie in the code");
    _Static_assert(sizeof(photon_record) >= 16, "pairs: 2 per record");
    const int shift = 31 - 3 * (level - 1); /* the code's next 32 bits: [shift, shift + 32) */
    const uint32_t low = (1u << PHOTON_TAG_GROUP_SHIFT) - 1u; /* the tag's own bits */
    unsigned char *half = (unsigned char *)r + (sizeof(photon_record) - 16) * n,
                  *last = half + 8 * n;
    size_t count[4][256] = {{0}};
    for (size_t i = 0; i < n; i++) {
        photon_prefetch(scratch, i + PHOTON_PREFETCH_AHEAD, n);
        uint32_t key = (uint32_t)(photon_morton(cube, &scratch[i]) >> shift);
        photon_pair_set(half, i, (uint64_t)key << 32 | i);
        for (int d = 0; d < 4; d++)
            count[d][key >> 8 * d & 255u]++;
    }
    bool moves[4]; /* not all in one bucket */
    int passes = 0;
    for (int d = 0; d < 4; d++) {
        moves[d] = true;
        for (int k = 0; k < 256 && moves[d]; k++)
            moves[d] = count[d][k] != n;
        passes += moves[d];
    }
    unsigned char *src = half, *dst = last;
    if (passes % 2 == 0) { /* an even number of passes ends where it starts: start in last */
        memcpy(last, half, 8 * n);
        src = last;
        dst = half;
    }
    for (int d = 0; d < 4; d++) {
        if (!moves[d])
            continue;
        size_t at = 0, *next = count[d];
        for (int k = 0; k < 256; k++) {
            size_t c = next[k];
            next[k] = at;
            at += c;
        }
        for (size_t i = 0; i < n; i++) {
            uint64_t pair = photon_pair_get(src, i);
            photon_pair_set(dst, next[pair >> (32 + 8 * d) & 255u]++, pair);
        }
        unsigned char *t = src;
        src = dst;
        dst = t;
    }
    uint32_t prev = 0;
    for (size_t i = 0; i < n; i++) { /* src == last: record i overwrites pairs up to i only */
        uint64_t pair = photon_pair_get(last, i);
        uint32_t key = (uint32_t)(pair >> 32);
        photon_record q = scratch[pair & 0xffffffffu];
        q.tag = (q.tag & low) | (uint32_t)(i == 0 || key != prev) << PHOTON_TAG_GROUP_SHIFT;
        prev = key;
        r[i] = q;
    }
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && (r[j].tag & ~low) == 0)
            j++;
        for (size_t k = i; k < j; k++)
            r[k].tag = g << PHOTON_TAG_GROUP_SHIFT | (r[k].tag & low);
        if (j - i > 1) { /* the codes 8-byte aligned in the run's 28 or more bytes a record */
            uintptr_t at = ((uintptr_t)(void *)(scratch + i) + 7u) & ~(uintptr_t)7u;
            uint64_t *code = (uint64_t *)(void *)at;
            for (size_t k = i; k < j; k++)
                code[k - i] = photon_morton(cube, &r[k]);
            photon_sort(r + i, code, j - i, level + 10);
        }
        i = j;
    }
}
