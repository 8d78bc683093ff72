/* photon-map.thzpm: every channel's photon map and photon-phase statistics, so that
 * `render` can reuse a simulation's photons (scene-format.md "Outputs").
 *
 * Layout (little-endian, version 4):
 *   prefix, 24 bytes, uncompressed: magic "THZPMAP\x1a", u32 version, u32 flags (0;
 *     none is defined, a reader refuses any set bit),
 *     u64 total file size (detects truncation before decoding anything);
 *   zstd frame 1 (with content checksum): the header: u64 scene hashes (geometry,
 *     optics, channels; scene_hash.h), u64 n_channels, n_objects, seed, photons per
 *     channel, then per channel: f64 centre Hz, f64 relative width (0 for a measured
 *     response, whose table only the channels hash records), u64 record count, and
 *     the photon_stats (10 counters, 7 powers and means; the wall time is not stored so
 *     that a file depends only on the scene, seed and photon count), then f64 the map's
 *     reference temperature T0 in K (photon_map.h; 0 for the paper's map of L);
 *   zstd frame 2 (with content checksum and content size): the records of channel 0,
 *     1, ... as 28-byte photon_record images (photon_map.h: the tag holds the group,
 *     the first-hit bit and the batch). Within a channel they are in the map's order,
 *     which depends on the records alone (photon_map.c: by group, then Morton code in
 *     the group's cube, then bytes), so that read + write reproduces a file byte for
 *     byte and the reader's index build, finding them in order, moves nothing.
 *
 * Version 3 is version 4 with 32-byte records (PMF_RECORD_BYTES_V3: u32 object << 1 |
 * side, u32 the bounce count and the batch, where the tag is); the reader converts them
 * and sorts them again (their order of bytes was another). Version 2 is version 3 with
 * the records of a group in the order of their bytes; version 1 is version 2 without T0
 * (20 words per channel), its maps with T0 = 0 and no batches. All are still read.
 */
#ifndef THZ_IO_PHOTON_MAP_FILE_H
#define THZ_IO_PHOTON_MAP_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/file.h"
#include "photon/photon_map.h"
#include "photon/photon_stats.h"
#include "scene/scene.h"

#define PHOTON_MAP_FILE_VERSION 4u
/* core/file.h holds the magic: a file given where JSON was expected is named by it */
#define PHOTON_MAP_FILE_MAGIC FILE_MAGIC_PHOTON_MAP

/* What a file says beyond its maps. */
typedef struct photon_map_file_info {
    uint64_t seed;
    uint64_t photons_per_channel;
    size_t n_channels;
} photon_map_file_info;

/* Writes scene->n_channels maps (maps[c], borrowed) and their stats (n_channels entries,
 * may be NULL: zeros are written) to path, recording scene->photons' seed and count and
 * the scene's hashes. The records are compressed by `threads` zstd workers (0: as many
 * as OpenMP's threads); zstd's streaming output is the same for any number of workers
 * from 1 on, so the file is too (a libzstd built without threads: compressed in the
 * calling thread, which zstd encodes differently). Errors name the file. */
thz_status photon_map_file_write(const char *path, const thz_scene *scene,
                                 const photon_map *const *maps, const photon_stats *stats,
                                 int threads, thz_error *err);

/* photon_map_file_write to a file beside path under a name of its own (ending in
 * ".part"), renamed into path whole: written in place (truncated first), a save that
 * failed (a full disk, a file-size limit) left a truncated file where a good map had
 * been, and a render reading that map meanwhile, a channel at a time, failed calling it
 * corrupted. A symbolic link is written through, and the file keeps the mode of the one
 * it replaces. Where no such name can be made (a directory that takes no new file), in
 * place; so too over what is not a regular file (/dev/null, which a rename would
 * replace) and through a symbolic link to a file not there yet (a rename would replace
 * the link). Errors name path, not the temporary file. */
thz_status photon_map_file_save(const char *path, const thz_scene *scene,
                                const photon_map *const *maps, const photon_stats *stats,
                                int threads, thz_error *err);

/* Reads a photon-map file made from `scene`: fills maps[0..n_channels-1] (the caller
 * destroys them; all NULL on failure; each with its reference temperature set), stats
 * (n_channels entries, may be NULL; seconds is 0; reference_temperature_k the map's)
 * and info (may be NULL). `threads` is passed to photon_map_create. Refuses, with a
 * message naming the file: a file that is not a photon map or has a version other than
 * 1 to 3, a truncated or corrupted one (corruption is found by the zstd checksums), and
 * one made from another scene geometry, material set or channel
 * set: all THZ_ERR_INPUT (a failed read of the device is THZ_ERR_IO). */
thz_status photon_map_file_read(const char *path, const thz_scene *scene, int threads,
                                photon_map **maps, photon_stats *stats, photon_map_file_info *info,
                                thz_error *err);
/* The same, building channel `channel`'s map alone (maps[c] NULL for the others, whose
 * records are read, checked against their checksum and dropped; stats for every
 * channel): for a view of one channel, without the others' memory and index build. */
thz_status photon_map_file_read_channel(const char *path, const thz_scene *scene, int threads,
                                        size_t channel, photon_map **maps, photon_stats *stats,
                                        photon_map_file_info *info, thz_error *err);

/* Progress of a read, on the calling thread: channel c's record count before its records
 * are read (done 0) and after its map is built (done = total; a channel dropped by
 * _read_channel reports no build); non-zero stops the read with THZ_ERR_CANCELLED. */
typedef struct photon_map_file_progress {
    int (*fn)(void *user, size_t channel, uint64_t done, uint64_t total);
    void *user;
} photon_map_file_progress;

/* photon_map_file_read (want SIZE_MAX) or _read_channel (want the channel) with progress
 * (NULL: none). */
thz_status photon_map_file_read_progress(const char *path, const thz_scene *scene, int threads,
                                         size_t want, const photon_map_file_progress *progress,
                                         photon_map **maps, photon_stats *stats,
                                         photon_map_file_info *info, thz_error *err);

/* A file read one channel at a time, in channel order: for a render that holds one
 * channel's map at once instead of all (run.h: run_photons.next_map). Opening checks
 * what photon_map_file_read checks before the records (prefix, header and its checksum,
 * the scene, the counts against the file's size) and fills stats and info as it does.
 * Each photon_map_file_next reads the next channel's records and builds its map (the
 * caller destroys it); the one after the last channel's also checks the records'
 * checksum and the file's end. A corruption in a later channel's records is found when
 * that channel is read, after the earlier ones were handed out: the caller fails then. */
typedef struct photon_map_file_stream photon_map_file_stream;

thz_status photon_map_file_open(const char *path, const thz_scene *scene, photon_stats *stats,
                                photon_map_file_info *info, photon_map_file_stream **out,
                                thz_error *err);
thz_status photon_map_file_next(photon_map_file_stream *s, int threads, photon_map **map,
                                thz_error *err);
/* The record count of the file's largest channel (for a memory estimate). */
size_t photon_map_file_largest_count(const photon_map_file_stream *s);
void photon_map_file_close(photon_map_file_stream *s);

#endif
