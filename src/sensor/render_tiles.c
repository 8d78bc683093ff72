/* Pixel tiles of a render shared by processes: see render_tiles.h. */
#include "sensor/render_tiles.h"

#include <stdbool.h>

size_t render_tiles_doubles_per_pixel(const render_accum *acc)
{
    return 2 + (acc->batch ? PHOTON_MAP_BATCHES + 1 : 0);
}

size_t render_tiles_count(size_t pixels, uint32_t columns, size_t member, size_t members)
{
    size_t n = 0;
    for (size_t p = 0; p < pixels; p++)
        n += render_tile_owner((uint32_t)(p % columns), (uint32_t)(p / columns), members) == member;
    return n;
}

void render_tiles_pack(const render_accum *acc, uint32_t columns, size_t member, size_t members,
                       double *out)
{
    for (size_t p = 0; p < acc->pixels; p++) {
        if (render_tile_owner((uint32_t)(p % columns), (uint32_t)(p / columns), members) != member)
            continue;
        *out++ = acc->mean[p];
        *out++ = acc->m2[p];
        if (acc->batch) {
            for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
                *out++ = acc->batch[p * PHOTON_MAP_BATCHES + b];
            *out++ = acc->disk_var[p];
        }
    }
}

void render_tiles_unpack(render_accum *acc, uint32_t columns, size_t member, size_t members,
                         const double *in)
{
    for (size_t p = 0; p < acc->pixels; p++) {
        if (render_tile_owner((uint32_t)(p % columns), (uint32_t)(p / columns), members) != member)
            continue;
        acc->mean[p] = *in++;
        acc->m2[p] = *in++;
        if (acc->batch) {
            for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
                acc->batch[p * PHOTON_MAP_BATCHES + b] = *in++;
            acc->disk_var[p] = *in++;
        }
    }
}

void render_stats_add_counts(render_stats *a, const render_stats *b)
{
    if (b->back_face_samples) { /* the objects: of the side that saw any */
        bool none = a->back_face_samples == 0;
        if (none || b->back_face_object_lo < a->back_face_object_lo)
            a->back_face_object_lo = b->back_face_object_lo;
        if (none || b->back_face_object_hi > a->back_face_object_hi)
            a->back_face_object_hi = b->back_face_object_hi;
    }
    a->samples += b->samples;
    a->escaped_samples += b->escaped_samples;
    a->back_face_samples += b->back_face_samples;
    a->widened_gathers += b->widened_gathers;
    a->starved_gathers += b->starved_gathers;
    a->truncated_paths += b->truncated_paths;
    a->paths += b->paths;
}
