/* The photon map's layout, shared by its build (photon_map_build.c) and its queries
 * (photon_map.c), and the build's scratch from the pool; photon_map.c's header says what
 * the order of the records is and why.
 * Internal to src/photon/.
 */
#ifndef THZ_PHOTON_PHOTON_MAP_LAYOUT_H
#define THZ_PHOTON_PHOTON_MAP_LAYOUT_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "photon/photon_map.h"

/* Bits per axis of the quantised positions: cells down to 2^-21 of the group's extent. */
#define PHOTON_MAP_LEVELS 21
/* Ranges up to this many records are scanned instead of split. A scan reads its records
 * in order, which the hardware prefetches; each split is three binary searches whose
 * probes it cannot: final-gather's render on the paper's scene (0.2 THz, 6 M photons,
 * 32 gather rays, rendered from one saved map, alternating builds) took 4.39 s on 1 thread
 * (median of 5) and 2.41 s on 2 (of 6) with 256, against 4.99 and 2.58 s with 48, for
 * 0.4 % more instructions; 128 and 192 fell between, 384 was slower. The visits, their
 * order and so every image are the same for any leaf size. */
#define PHOTON_MAP_LEAF 256

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

/* A group's directory goes down to the deepest level L whose cells hold at least
 * PHOTON_DIR_MIN_PER_CELL records on average, at most PHOTON_DIR_MAX_LEVELS (8^6 cells,
 * 1 MB): at most 1 byte per record (4 bytes a cell, 4 records a cell). Final-gather on the
 * paper's scene spent 9-14 % less CPU with a directory (16 per cell and 6 levels, with
 * 48-record leaves; 64 per cell helped less, 8 and 7 levels no more). The photons lie on
 * surfaces, so the occupied cells hold many times the mean: with 256-record leaves, 4 per
 * cell took the binary searches below the directory from 6.7 to 2.4 per radius query
 * (0.2 THz, 4 M photons, 50 gather rays) and final-gather's render from 5.06 to 4.87 s
 * on 1 thread, 2.86 to 2.63 s on 2 (medians of 5, alternating; the same images). */
#define PHOTON_DIR_MAX_LEVELS 6
#define PHOTON_DIR_MIN_PER_CELL 4

struct photon_map_directory {
    size_t n_groups;
    int *level;        /* [group] L: starts[group] holds the 8^L cells of level L; 0: none */
    uint32_t **starts; /* [group] 8^L + 1 offsets from the group's first record: each
                        * cell's first, then the group's end */
};

static inline uint32_t photon_quantize_axis(const photon_cube *c, const photon_record *p, int a)
{
    double q = ((double)p->position_m[a] - c->origin[a]) * c->scale;
    if (!(q > 0.0))
        return 0;
    if (q >= (double)(1u << PHOTON_MAP_LEVELS))
        return (1u << PHOTON_MAP_LEVELS) - 1;
    return (uint32_t)q;
}

/* A cell of a group's octree: its level, integer coordinates and record range. */
typedef struct photon_cell {
    int level;
    uint32_t c[3];
    uint64_t m; /* Morton index among the cells of its level (x the high bit of a digit) */
    size_t lo, hi;
} photon_cell;

/* The side of a cell of `level`, the cube's side x 2^-level: exactly ldexp's result (a
 * product by a power of two is correctly rounded), without its call, which took 3 % of a
 * photon-map render's instructions. */
static inline double photon_cell_size(const photon_cube *cube, int level)
{
    uint64_t bits = (uint64_t)(1023 - level) << 52; /* 2^-level, 0 <= level <= 1022 */
    double scale;
    memcpy(&scale, &bits, sizeof scale);
    return cube->side * scale;
}

/* Squared distance from q to the cell's box, the box widened by a millionth of its
 * side: quantisation rounds in double, so a point on a cell's face may sit in the
 * neighbouring cell; the widening keeps pruning conservative. */
static inline double photon_cell_distance2(const photon_cube *cube, const photon_cell *cell,
                                           const double q[3])
{
    double size = photon_cell_size(cube, cell->level);
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
static inline size_t photon_bit_boundary(const photon_cube *cube, const photon_record *r, size_t lo,
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
static inline void photon_cell_split(const photon_cube *cube, const photon_record *r,
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

static inline photon_cell photon_child(const photon_cell *cell, unsigned d, const size_t b[9])
{
    photon_cell ch = {.level = cell->level + 1,
                      .c = {cell->c[0] << 1 | (d >> 2 & 1u), cell->c[1] << 1 | (d >> 1 & 1u),
                            cell->c[2] << 1 | (d & 1u)},
                      .m = cell->m << 3 | d,
                      .lo = b[d],
                      .hi = b[d + 1]};
    return ch;
}

/* The index build's scratch (count records): the pool's, grown if need be
 * and kept there, or without a pool a new one the caller frees. NULL when out of
 * memory. */
photon_record *photon_map_pool_scratch(photon_map_pool *pool, size_t count);

/* The index build's counts and boxes (bytes of them): as photon_map_pool_scratch. */
void *photon_map_pool_index(photon_map_pool *pool, size_t bytes);

#endif
