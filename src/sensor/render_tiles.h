/* Rendering shared by processes (MPI: src/mpi/, docs/mpi.md): the pixels of a sensor are
 * split into square tiles of RENDER_TILE_PIXELS, dealt to the members diagonally (tile
 * (tx, ty) to member (tx + ty) mod n), so that every member gets tiles of every part of
 * the image. A pixel's estimates depend only on its own index (render.h, "Determinism"),
 * so a member renders its tiles exactly as one process would, and the lead (member 0)
 * copies the other members' tiles into its pixel statistics after every pass: its images
 * are bit-identical to one process's.
 *
 * The other members hold the channel's photon map too: the lead sends them the records of
 * the map it renders from (channel_begin), and each builds the same map (photon_map_create
 * sorts the records by a total order, so the same records give the same map).
 */
#ifndef THZ_SENSOR_RENDER_TILES_H
#define THZ_SENSOR_RENDER_TILES_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "photon/photon_map.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"

#define RENDER_TILE_PIXELS 16u

/* The member (of `members`) that renders pixel (col, row). */
static inline size_t render_tile_owner(uint32_t col, uint32_t row, size_t members)
{
    return members > 1 ? ((size_t)(col / RENDER_TILE_PIXELS) + row / RENDER_TILE_PIXELS) % members
                       : 0;
}

/* Doubles per pixel in a packed tile share: mean and m2, and with photon batches
 * (final-gather from a batched map) the batch sums and the disk variance. */
size_t render_tiles_doubles_per_pixel(const render_accum *acc);

/* Pixels of a columns-wide image of `pixels` pixels that `member` renders. */
size_t render_tiles_count(size_t pixels, uint32_t columns, size_t member, size_t members);

/* Copies member's pixels of acc, in pixel order, into out (render_tiles_count x
 * render_tiles_doubles_per_pixel doubles), and back (unpack: into acc). */
void render_tiles_pack(const render_accum *acc, uint32_t columns, size_t member, size_t members,
                       double *out);
void render_tiles_unpack(render_accum *acc, uint32_t columns, size_t member, size_t members,
                         const double *in);

/* What the lead asks the other members to render from: channel `channel` of the scene,
 * with the photon map `map` (NULL for path) and the render seed. */
typedef struct render_channel_request {
    uint64_t channel;
    uint64_t use_seed, seed;
    uint64_t integrator;  /* the lead's thz_integrator: every member must render with it */
    uint64_t scene_print; /* the lead's scene_hash_run: the members check it */
} render_channel_request;

/* How the lead reaches the other members; implemented over MPI by src/mpi/. */
typedef struct render_team {
    size_t members; /* processes, the lead included */
    /* The members build the channel's state (they receive map's records). */
    thz_status (*channel_begin)(void *impl, const render_channel_request *rq, const photon_map *map,
                                thz_error *err);
    /* Before the lead renders its tiles of a pass: the members start on theirs. */
    thz_status (*pass_start)(void *impl, size_t sensor, uint32_t pass, thz_error *err);
    /* After: the members' tiles copied into acc (columns wide), their counts added to
     * stats. */
    thz_status (*pass_gather)(void *impl, render_accum *acc, uint32_t columns, render_stats *stats,
                              thz_error *err);
    /* The members free the channel's state. */
    thz_status (*channel_end)(void *impl, thz_error *err);
    void *impl;
} render_team;

/* Adds b's counts (not its seconds) to a's; the objects seen from the back: of both. */
void render_stats_add_counts(render_stats *a, const render_stats *b);

#endif
