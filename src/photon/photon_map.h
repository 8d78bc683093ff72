/* The photon map of one channel: every hit of every photon, with incident power,
 * position, direction, frequency, object and side (physics.md "Photon phase"), and a
 * spatial index per (object, side) answering radius and k-nearest queries.
 *
 * The record is 28 bytes: see photon_record below for what each field holds and why.
 */
#ifndef THZ_PHOTON_PHOTON_MAP_H
#define THZ_PHOTON_PHOTON_MAP_H

#include <stddef.h>
#include <stdint.h>

#include "core/cancel.h"
#include "core/error.h"
#include "core/vec3.h"

/* One stored photon hit (28 bytes). */
typedef struct photon_record {
    float position_m[3];  /* hit point */
    float power_w_per_hz; /* incident spectral power carried (already attenuated) */
    float freq_hz;        /* the photon's own frequency (float: 60 kHz resolution at 1 THz) */
    uint32_t dir_oct;     /* incoming unit direction, octahedral 2 x 16 bit */
    uint32_t tag;         /* group (object index << 1 | side: 0 front, 1 back) << 4, whether
                           * the hit is the photon's first (bit 3), its batch (bits 0-2) */
} photon_record;

_Static_assert(sizeof(photon_record) == 28, "photon_record must stay 28 bytes");

/* Photon batches: photon i of the phase (all records of its path) belongs to batch
 * i mod PHOTON_MAP_BATCHES. The batches are independent, identically distributed maps of
 * K / PHOTON_MAP_BATCHES photons each, so the spread between what each batch contributes
 * to a pixel measures the photon map's own noise there (final-gather's standard error,
 * docs/integrators.md). */
#define PHOTON_MAP_BATCHES 8u
/* The tag's fields: the batch in its low bits, then the first-hit bit, then the group. */
#define PHOTON_TAG_FIRST_HIT 8u
#define PHOTON_TAG_GROUP_SHIFT 4
/* The most objects a photon map holds (67 M): their groups (two each) take half the
 * tag's 2^28 group values, the other half left for the index build's keys
 * (photon_map_build.c). */
#define PHOTON_MAX_OBJECTS ((size_t)1 << (32 - PHOTON_TAG_GROUP_SHIFT - 2))

/* The tag of a hit on `side` of `object` by a photon of `batch`, first_hit nonzero at the
 * photon's first hit. */
static inline uint32_t photon_tag(uint32_t object, int side, int first_hit, unsigned batch)
{
    return (object << 1 | (uint32_t)side) << PHOTON_TAG_GROUP_SHIFT |
           (first_hit ? PHOTON_TAG_FIRST_HIT : 0u) | (batch & (PHOTON_MAP_BATCHES - 1u));
}

static inline unsigned photon_batch(const photon_record *p)
{
    return p->tag & (PHOTON_MAP_BATCHES - 1u);
}

/* Direction (unit) <-> 32-bit octahedral code, error < 1e-4 rad. */
uint32_t photon_encode_direction(vec3 dir);
vec3 photon_decode_direction(uint32_t code);

/* The record's group: object index << 1 | side, the map's order's first key. */
static inline uint32_t photon_group(const photon_record *p)
{
    return p->tag >> PHOTON_TAG_GROUP_SHIFT;
}
static inline uint32_t photon_object(const photon_record *p)
{
    return p->tag >> (PHOTON_TAG_GROUP_SHIFT + 1);
}
static inline int photon_side(const photon_record *p)
{
    return (int)(p->tag >> PHOTON_TAG_GROUP_SHIFT & 1u);
}
/* Whether the hit is its photon's first (where it was emitted to, before any bounce). */
static inline int photon_first_hit(const photon_record *p)
{
    return (p->tag & PHOTON_TAG_FIRST_HIT) != 0;
}

typedef struct photon_map photon_map;

/* Creates a map from photons (takes ownership of the array, which must come from
 * malloc), sorted into (object, side) groups with a spatial index each, built in
 * parallel with `threads` threads (0: all). Deterministic: the result does not depend on
 * the thread count. */
thz_status photon_map_create(photon_record *photons, size_t count, size_t n_objects, int threads,
                             photon_map **out, thz_error *err);
void photon_map_destroy(photon_map *map);

/* ---- memory kept between the maps of a run ----------------------------------------------
 * On a virtual machine, the first write to a freshly mapped page can cost a thousand times
 * the write itself (measured here: 0.35 GB/s for memory new to the process, 20 GB/s
 * reused; 28 % of the paper's case end to end). A run builds one map per channel, each
 * about the size of the last: the pool keeps the record array of a map the run is done
 * with, and the index build's scratch, for the next. Owned by the caller (one per run;
 * not shared between threads); photon_map_pool_fini frees what it holds. */
typedef struct photon_map_pool {
    photon_record *records; /* a spare record array (malloc'd), or NULL */
    size_t records_capacity;
    photon_record *scratch; /* the index build's scratch records */
    size_t scratch_capacity;
    void *index; /* the index build's counts and bounding boxes */
    size_t index_bytes;
} photon_map_pool;

void photon_map_pool_fini(photon_map_pool *pool);

/* The pool's spare record array (NULL if none, or pool NULL) and its capacity, now the
 * caller's. */
photon_record *photon_map_pool_take(photon_map_pool *pool, size_t *capacity);

/* Destroys map, keeping its record array in pool when larger than the pool's spare
 * (pool NULL: photon_map_destroy). */
void photon_map_recycle(photon_map *map, photon_map_pool *pool);

/* The records of the index build's scratch for a map of count records: at least 3/8 of
 * them (count / 8 x 3 + count % 8), more only where more than that share one 4096th of a
 * large group's cube (photon_map_build.c). */
static inline size_t photon_map_scratch_records(size_t count)
{
    return count / 8 * 3 + count % 8;
}

/* photon_map_create with the array's capacity (>= count, kept for photon_map_recycle)
 * and a pool (may be NULL) whose scratch the index build uses; `cancel` (may be NULL) is
 * asked between the build's passes, on the calling thread (THZ_ERR_CANCELLED: 10^8
 * photons' build held a stop for 3 to 7 s). */
thz_status photon_map_build(photon_record *photons, size_t count, size_t capacity, size_t n_objects,
                            int threads, photon_map_pool *pool, const cancel_check *cancel,
                            photon_map **out, thz_error *err);

/* One map of the photons of n maps of one channel fired with the same K and disjoint
 * photon ranges (photon_phase_options.first_photon): their records in order, each power
 * divided by n (each map's photons carry P/K; together they are n K photons). The maps
 * must share T0; the result has it, and batches when all have them. Deterministic. With
 * a pool (may be NULL), the record array is the pool's spare grown to size (recycle the
 * last merge into it: photon_map_recycle) and the index build uses its scratch. */
thz_status photon_map_merge(const photon_map *const *maps, size_t n, size_t n_objects, int threads,
                            photon_map_pool *pool, photon_map **out, thz_error *err);

size_t photon_map_count(const photon_map *map);

/* Reference temperature T0 (K) of the map. 0 (the default of photon_map_create): the
 * paper's map, photons carry the power of L. T0 > 0: a deviation map, photons carry the
 * signed power of L - B_nu(T0), fired from the sources of that difference (phase.h);
 * the renderer adds B_nu(T0) back. In a near-isothermal scene at T0 the sources, and so
 * the map's noise, are small. */
double photon_map_reference_temperature_k(const photon_map *map);

/* PHOTON_MAP_BATCHES when the records carry their batch (maps of this version's photon
 * phase), 1 for maps without (photon_map_create's default; .thzpm version 1). */
unsigned photon_map_batches(const photon_map *map);
void photon_map_set_batches(photon_map *map, unsigned batches);
void photon_map_set_reference_temperature_k(photon_map *map, double t0_k);

/* Bytes the map holds: its records and its spatial index (the benchmark's bytes per
 * stored photon). */
size_t photon_map_bytes(const photon_map *map);
const photon_record *photon_map_records(const photon_map *map);

/* The photons of (object, side) within distance sqrt(radius2_m2) of position: calls
 * visit(ctx, photon, distance2) for each. */
typedef void (*photon_visit_fn)(void *ctx, const photon_record *p, double distance2_m2);
void photon_map_radius(const photon_map *map, uint32_t object, int side, vec3 position_m,
                       double radius2_m2, photon_visit_fn visit, void *ctx);

/* A renderer's lookup table over a map's spatial index (photon_map_directory.c): for
 * each group of records (object, side) with enough of them, the first record of every
 * cell of one level of its octree, so that a radius query finds the cells above that
 * level by index instead of by binary searches over the records, whose cache misses were
 * most of final-gather's time. The queries visit the same photons in the same order with
 * it or without it (it is built by those binary searches). It borrows the map, which
 * must outlive it unchanged; it is not part of the map (photon_map_bytes). */
typedef struct photon_map_directory photon_map_directory;
/* threads: OpenMP threads for its fill, 0: all. */
thz_status photon_map_directory_create(const photon_map *map, int threads,
                                       photon_map_directory **out, thz_error *err);
void photon_map_directory_destroy(photon_map_directory *dir);
size_t photon_map_directory_bytes(const photon_map_directory *dir);

/* photon_map_radius through dir, map's directory (NULL: without). */
void photon_map_radius_in(const photon_map *map, const photon_map_directory *dir, uint32_t object,
                          int side, vec3 position_m, double radius2_m2, photon_visit_fn visit,
                          void *ctx);

/* The number of photons of `object` over the sides in side_mask (bit 0 front, bit 1
 * back). */
size_t photon_map_object_count(const photon_map *map, uint32_t object, unsigned side_mask);

/* The squared distance to the k-th nearest photon of `object` over the sides in
 * side_mask (bit 0 front, bit 1 back), or INFINITY if it has fewer than k. */
double photon_map_kth_distance2(const photon_map *map, uint32_t object, unsigned side_mask,
                                vec3 position_m, size_t k);

#endif
