/* photon-map.ply: the stored photons as a coloured point cloud (the paper's Fig. 3),
 * binary little-endian PLY that MeshLab, CloudCompare and Blender open.
 *
 * One vertex per photon, 39 bytes, these properties in this order:
 *   float x, y, z           the hit point, m
 *   uchar red, green, blue  the colour of the incoming direction d (the photon's unit
 *                           direction of travel as it arrived): rgb = round(255 * 0.5 *
 *                           (1 - d)), i.e. the direction it came from mapped to [0, 255]
 *                           (a photon arriving from above, travelling along -z, is
 *                           blue-ish white: (128, 128, 255))
 *   uint channel            index into the scene's channels (the map it belongs to)
 *   float power_w_per_hz    the spectral power it carries, W/Hz (negative where a
 *                           deviation map's photon carries a deficit below B(T0))
 *   int object              index into the scene's objects of the surface hit
 *   float dx, dy, dz        d itself (unit vector)
 */
#ifndef THZ_IO_PLY_H
#define THZ_IO_PLY_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "photon/photon_map.h"

/* Default cap on the number of points written. */
#define PLY_DEFAULT_MAX_POINTS 2000000u

/* Writes the photons of maps[0..n_maps-1] (borrowed; NULL entries are skipped), in map
 * order. If there are more than max_points (0: no cap), point i of the file is photon
 * floor(i * total / max_points) of the concatenation: evenly strided, deterministic.
 * Errors name the file. */
thz_status ply_write_photons(const char *path, const photon_map *const *maps, size_t n_maps,
                             uint64_t max_points, thz_error *err);

#endif
