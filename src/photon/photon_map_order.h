/* The order of a group's records in the photon map (photon_map.c says why): their Morton
 * codes in the group's cube, and the sort of a range of them by code and then bytes.
 * Shared by the build's passes (photon_map_build.c) and its sort (photon_map_order.c).
 * Internal to src/photon/.
 */
#ifndef THZ_PHOTON_PHOTON_MAP_ORDER_H
#define THZ_PHOTON_PHOTON_MAP_ORDER_H

#include <stddef.h>
#include <stdint.h>

#include "photon/photon_map_layout.h"

/* Levels of the first digit of a large group: 4096 ranges, a few thousand records each
 * in the paper's case (a plane's records fill a sixteenth of them). */
#define PHOTON_MAP_FIRST_LEVELS 4
#define PHOTON_MAP_DIGITS (1u << (3 * PHOTON_MAP_FIRST_LEVELS))

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
static inline uint64_t photon_spread3(uint32_t v)
{
    return (uint64_t)photon_spread7[v & 127u] | (uint64_t)photon_spread7[v >> 7 & 127u] << 21 |
           (uint64_t)photon_spread7[v >> 14 & 127u] << 42;
}

/* The full Morton code (3 LEVELS bits; x the highest bit of each level). */
static inline uint64_t photon_morton(const photon_cube *c, const photon_record *p)
{
    return photon_spread3(photon_quantize_axis(c, p, 0)) << 2 |
           photon_spread3(photon_quantize_axis(c, p, 1)) << 1 |
           photon_spread3(photon_quantize_axis(c, p, 2));
}

/* The first PHOTON_MAP_FIRST_LEVELS levels' digits of the record's Morton code
 * (photon_code_digits(photon_morton(c, p), 1, PHOTON_MAP_FIRST_LEVELS)), from the
 * quantised coordinates' top bits alone. */
static inline unsigned photon_first_digit(const photon_cube *c, const photon_record *p)
{
    _Static_assert(PHOTON_MAP_FIRST_LEVELS <= 7, "the table spreads 7 bits");
    const int shift = PHOTON_MAP_LEVELS - PHOTON_MAP_FIRST_LEVELS;
    return photon_spread7[photon_quantize_axis(c, p, 0) >> shift] << 2 |
           photon_spread7[photon_quantize_axis(c, p, 1) >> shift] << 1 |
           photon_spread7[photon_quantize_axis(c, p, 2) >> shift];
}

/* How far ahead (records; 896 bytes) the build's passes ask for the records they stream
 * through. */
#define PHOTON_PREFETCH_AHEAD 32

/* Asks the memory for record i of r[0..n) ahead of its use (nothing at or past n). The
 * build's streaming passes waited on memory without it: on the 2-core development VM of
 * 2026-12-04 16:00 (docs/benchmark.md, "Runs on the AVX-512 VM") the six maps of the
 * paper's case took 2.61 s to build on 2 threads and 2.15 s with it (the passes that read
 * the records in order 14-35 % faster, the sort 23 %); the map is the same bytes. */
static inline void photon_prefetch(const photon_record *r, size_t i, size_t n)
{
    if (i < n)
        __builtin_prefetch(r + i, 0);
}

/* The same for a record the pass will write. */
static inline void photon_prefetch_write(photon_record *r, size_t i, size_t n)
{
    if (i < n)
        __builtin_prefetch(r + i, 1);
}

/* Sorts the n records at scratch, of group g, whose codes share levels 1..level-1 (level 1
 * or 1 + PHOTON_MAP_FIRST_LEVELS), by code and then bytes into r[0..n) (n < 2^32), their
 * tags' group set to g (their own bits kept); scratch's n records are left undefined. */
void photon_sort_range(const photon_cube *cube, photon_record *scratch, photon_record *r, size_t n,
                       int level, uint32_t g);

#endif
