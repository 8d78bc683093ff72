/* The photon map's layout, shared by its build (photon_map_build.c) and its queries
 * (photon_map.c), and the build's scratch from the pool; photon_map.c's header says what
 * the order of the records is and why.
 * Internal to src/photon/.
 */
#ifndef THZ_PHOTON_PHOTON_MAP_LAYOUT_H
#define THZ_PHOTON_PHOTON_MAP_LAYOUT_H

#include "photon/photon_map.h"

/* Bits per axis of the quantised positions: cells down to 2^-21 of the group's extent. */
#define PHOTON_MAP_LEVELS 21
/* Ranges up to this many records are scanned instead of split. */
#define PHOTON_MAP_LEAF 48

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

static inline uint32_t photon_quantize_axis(const photon_cube *c, const photon_record *p, int a)
{
    double q = ((double)p->position_m[a] - c->origin[a]) * c->scale;
    if (!(q > 0.0))
        return 0;
    if (q >= (double)(1u << PHOTON_MAP_LEVELS))
        return (1u << PHOTON_MAP_LEVELS) - 1;
    return (uint32_t)q;
}

/* The index build's second record array (count records): the pool's, grown if need be
 * and kept there, or without a pool a new one the caller frees. NULL when out of
 * memory. */
photon_record *photon_map_pool_scratch(photon_map_pool *pool, size_t count);

/* The index build's counts and boxes (bytes of them): as photon_map_pool_scratch. */
void *photon_map_pool_index(photon_map_pool *pool, size_t bytes);

#endif
