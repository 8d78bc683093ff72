/* Fuzzes the photon-map reader (src/io/photon_map_file.c) against the small scene
 * tests/fuzz/files/photon_map_scene.json, in two ways:
 * - an input that starts with the magic "THZPMAP" is the .thzpm file itself (the prefix,
 *   the zstd frames, their checksums);
 * - any other input is the content of a file of this scene: its first byte chooses
 *   version 1 (bit 0 set), 4 (bit 3 set) or 3 (32-byte records, which the reader
 *   converts; 1 as well), whether the header's record counts are kept as they are
 *   (bit 1; else they split the records given among the channels) and whether the records
 *   frame omits its content size (bit 2); then come the header words (the scene's hashes
 *   and counts are filled in) and the records.
 *   The harness compresses them into frames with valid checksums, so that what lies
 *   behind them (the header's and the records' checks, the map's index built from
 *   arbitrary records) is reached.
 * A map that is read is then queried as the renderer queries it.
 */
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#include "fuzz.h"
#include "io/photon_map_file.h"
#include "scene/scene_hash.h"

#define HEADER_FIXED 7u
static thz_scene *scene;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    thz_error err = {0};
    if (scene_load(FUZZ_DIR "/files/photon_map_scene.json", &scene, &err) != THZ_OK)
        abort();
    return 0;
}

static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

/* Appends one zstd frame (with checksum; with its content size if `sized`) of
 * src[0..n) at out + *pos. */
static void put_frame(uint8_t *out, size_t cap, size_t *pos, const void *src, size_t n, bool sized)
{
    ZSTD_CCtx *cctx = ZSTD_createCCtx();
    if (!cctx || ZSTD_isError(ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1)) ||
        ZSTD_isError(ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, sized ? 1 : 0)))
        abort();
    size_t r = ZSTD_compress2(cctx, out + *pos, cap - *pos, src, n);
    if (ZSTD_isError(r))
        abort();
    *pos += r;
    ZSTD_freeCCtx(cctx);
}

/* Builds a .thzpm file of this scene from content (see the top); returns its size. */
static size_t build_file(const uint8_t *data, size_t size, uint8_t **file)
{
    unsigned options = size > 0 ? data[0] : 0u;
    unsigned version = (options & 1u) ? 1u : (options & 8u) ? 4u : 3u;
    size_t record_bytes = version < 4u ? 32u : sizeof(photon_record);
    size_t words = version == 1u ? 20u : 21u, nc = scene->n_channels;
    size_t header_bytes = 8 * (HEADER_FIXED + words * nc);
    const uint8_t *rest = size > 0 ? data + 1 : data;
    size_t rest_n = size > 0 ? size - 1 : 0;
    uint8_t *header = calloc(header_bytes, 1);
    memcpy(header, rest, rest_n < header_bytes ? rest_n : header_bytes);
    const uint8_t *records = rest_n > header_bytes ? rest + header_bytes : NULL;
    size_t n_records = records ? (rest_n - header_bytes) / record_bytes : 0;

    scene_hash h;
    scene_hash_compute(scene, &h);
    put_u64(header + 0, h.geometry);
    put_u64(header + 8, h.optics);
    put_u64(header + 16, h.channels);
    put_u64(header + 24, nc);
    put_u64(header + 32, scene->n_objects);
    size_t left = n_records;
    for (size_t c = 0; c < nc && !(options & 2u); c++) {
        uint8_t *count = header + 8 * (HEADER_FIXED + words * c) + 16;
        uint64_t n = c + 1 == nc ? left : get_u64(count) % (left + 1);
        put_u64(count, n);
        left -= n;
    }

    size_t records_bytes = n_records * record_bytes;
    size_t cap = 24 + ZSTD_compressBound(header_bytes) + ZSTD_compressBound(records_bytes);
    uint8_t *out = calloc(cap, 1);
    memcpy(out, PHOTON_MAP_FILE_MAGIC, 8);
    out[8] = (uint8_t)version;
    size_t pos = 24;
    put_frame(out, cap, &pos, header, header_bytes, true);
    put_frame(out, cap, &pos, records, records_bytes, !(options & 4u));
    put_u64(out + 16, pos);
    free(header);
    *file = out;
    return pos;
}

static void visit(void *ctx, const photon_record *p, double distance2_m2)
{
    (void)p;
    *(double *)ctx += distance2_m2;
}

static void query(const photon_map *map)
{
    const photon_record *r = photon_map_records(map);
    size_t n = photon_map_count(map);
    double sum = 0.0;
    for (size_t i = 0; i < n && i < 4; i++) {
        const photon_record *p = &r[i * (n / 4 + 1) % n];
        vec3 at = v3(p->position_m[0], p->position_m[1], p->position_m[2]);
        uint32_t object = photon_object(p);
        sum += photon_map_kth_distance2(map, object, 3u, at, 4);
        photon_map_radius(map, object, photon_side(p), at, 0.01, visit, &sum);
        sum += (double)photon_map_object_count(map, object, 3u);
    }
    volatile double sink = sum;
    (void)sink;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path;
    if (size >= 7 && memcmp(data, PHOTON_MAP_FILE_MAGIC, 7) == 0) {
        path = fuzz_temp_file("input.thzpm", data, size);
    } else {
        uint8_t *file;
        size_t n = build_file(data, size, &file);
        path = fuzz_temp_file("input.thzpm", file, n);
        free(file);
    }
    enum { MAX_CHANNELS = 8 };
    if (scene->n_channels > MAX_CHANNELS)
        abort();
    photon_map *maps[MAX_CHANNELS];
    photon_stats stats[MAX_CHANNELS];
    photon_map_file_info info;
    thz_error err = {0};
    thz_status st = photon_map_file_read(path, scene, 1, maps, stats, &info, &err);
    if (st != THZ_OK) {
        fuzz_report(err.message);
        if (!err.message[0])
            abort();
        for (size_t c = 0; c < scene->n_channels; c++)
            if (maps[c])
                abort(); /* photon_map_file.h: all NULL on failure */
        return 0;
    }
    for (size_t c = 0; c < scene->n_channels; c++) {
        query(maps[c]);
        photon_map_destroy(maps[c]);
    }
    return 0;
}
