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

/* An LSD radix sort, 8 bits a pass, of 64-bit pairs: the next 32 bits of a record's code
 * (10 levels and 2 bits) above its index. The pairs live in r's last half (two arrays of
 * 8 bytes per record), the sorted ones in its last quarter, so that moving the records
 * into their places, first to last, overwrites only pairs already read (record i ends at
 * byte 32 i + 32; pair j > i starts at byte 24 n + 8 j >= 32 i + 32). Then each run of
 * records whose 32 bits tie is sorted by full code and bytes (photon_sort; their codes in
 * the scratch, free by then). Sorting the records themselves moved 32 bytes a pass instead
 * of 8: 9 % more build time (12.1 M records, 2 threads, six alternating runs each: 0.408
 * against 0.375 s). In place, the American flag sort swapped every record along a cycle at
 * every second level: 37 of the build's 66 ns per record (paper's case, 1 thread). */
void photon_sort_range(const photon_cube *cube, photon_record *scratch, photon_record *r, size_t n,
                       int level, uint32_t g)
{
    _Static_assert(1 + PHOTON_MAP_FIRST_LEVELS <= 11, "the 32 bits must lie in the code");
    _Static_assert(sizeof(photon_record) == 4 * sizeof(uint64_t), "pairs: 4 per record");
    const int shift = 31 - 3 * (level - 1); /* the code's next 32 bits: [shift, shift + 32) */
    uint64_t *half = (uint64_t *)(void *)r + 2 * n, *last = half + n;
    size_t count[4][256] = {{0}};
    for (size_t i = 0; i < n; i++) {
        photon_prefetch(scratch, i + PHOTON_PREFETCH_AHEAD, n);
        uint32_t key = (uint32_t)(photon_morton(cube, &scratch[i]) >> shift);
        scratch[i].object_side = key; /* until the record is in its place */
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
    uint64_t *src = passes % 2 ? half : last, *dst = passes % 2 ? last : half;
    for (size_t i = 0; i < n; i++)
        src[i] = (uint64_t)scratch[i].object_side << 32 | i;
    for (int d = 0; d < 4; d++) {
        if (!moves[d])
            continue;
        size_t at = 0, *next = count[d];
        for (int k = 0; k < 256; k++) {
            size_t c = next[k];
            next[k] = at;
            at += c;
        }
        for (size_t i = 0; i < n; i++)
            dst[next[src[i] >> (32 + 8 * d) & 255u]++] = src[i];
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    for (size_t i = 0; i < n; i++) /* src == last: record i overwrites pairs before i only */
        r[i] = scratch[last[i] & 0xffffffffu];
    for (size_t i = 0; i < n;) {
        uint32_t key = r[i].object_side;
        size_t j = i;
        while (j < n && r[j].object_side == key)
            r[j++].object_side = g;
        if (j - i > 1) {
            uint64_t *code = (uint64_t *)(void *)(scratch + i);
            for (size_t k = i; k < j; k++)
                code[k - i] = photon_morton(cube, &r[k]);
            photon_sort(r + i, code, j - i, level + 10);
        }
        i = j;
    }
}
