/* photon-map.thzpm writer: see photon_map_file.h for the layout. */
#include "io/photon_map_file.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>
#include <zstd_errors.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/alloc.h"
#include "core/threads.h"
#include "io/photon_map_file_format.h"
#include "scene/scene_hash.h"

/* ---- writing ------------------------------------------------------------------ */

typedef struct pmf_writer {
    const char *path;
    FILE *f;
    ZSTD_CCtx *cctx;
    uint8_t *out;
    size_t out_cap;
} pmf_writer;

static thz_status pmf_write_bytes(pmf_writer *w, const void *p, size_t n, thz_error *err)
{
    if (n && fwrite(p, 1, n, w->f) != n)
        return thz_error_set(err, THZ_ERR_IO, "cannot write photon map %s: %s", w->path,
                             strerror(errno));
    return THZ_OK;
}

static thz_status pmf_compress(pmf_writer *w, const void *src, size_t n, ZSTD_EndDirective mode,
                               thz_error *err)
{
    ZSTD_inBuffer in = {src, n, 0};
    for (;;) {
        ZSTD_outBuffer out = {w->out, w->out_cap, 0};
        size_t r = ZSTD_compressStream2(w->cctx, &out, &in, mode);
        if (ZSTD_isError(r))
            return thz_error_set(
                err,
                ZSTD_getErrorCode(r) == ZSTD_error_memory_allocation ? THZ_ERR_NOMEM
                                                                     : THZ_ERR_INTERNAL,
                "cannot compress photon map %s: %s", w->path, ZSTD_getErrorName(r));
        thz_status st = pmf_write_bytes(w, w->out, out.pos, err);
        if (st != THZ_OK)
            return st;
        if (mode == ZSTD_e_end ? r == 0 : in.pos == in.size)
            return THZ_OK;
    }
}

static thz_status pmf_begin_frame(pmf_writer *w, uint64_t content_bytes, thz_error *err)
{
    size_t r = ZSTD_CCtx_reset(w->cctx, ZSTD_reset_session_only);
    if (!ZSTD_isError(r))
        r = ZSTD_CCtx_setPledgedSrcSize(w->cctx, content_bytes);
    if (ZSTD_isError(r))
        return thz_error_set(err, THZ_ERR_INTERNAL, "cannot compress photon map %s: %s", w->path,
                             ZSTD_getErrorName(r));
    return THZ_OK;
}

/* Records compressed per call: 2 MB. */
#define PMF_CHUNK 65536u

/* Compresses one channel's records in the map's own order, which depends only on the
 * records (photon_map.c: by object and side, Morton code in the group's cube, bytes), so
 * a reader's build finds them in order and moves nothing, and read + write gives the file
 * back byte for byte. A chunk at a time. */
static thz_status pmf_write_channel(pmf_writer *w, const photon_map *map, thz_error *err)
{
    const photon_record *r = photon_map_records(map);
    size_t n = photon_map_count(map);
    thz_status st = THZ_OK;
    for (size_t i = 0; i < n && st == THZ_OK; i += PMF_CHUNK) {
        size_t m = n - i < PMF_CHUNK ? n - i : PMF_CHUNK;
        st = pmf_compress(w, r + i, m * sizeof *r, ZSTD_e_continue, err);
    }
    return st;
}

thz_status photon_map_file_write(const char *path, const thz_scene *scene,
                                 const photon_map *const *maps, const photon_stats *stats,
                                 int threads, thz_error *err)
{
    thz_status st = THZ_OK;
    size_t nc = scene->n_channels;
    pmf_writer w = {.path = path};
    size_t header_bytes = 8 * (PMF_HEADER_FIXED + (size_t)PMF_CHANNEL_WORDS * nc);
    uint8_t *header = thz_calloc(header_bytes, 1);
    w.out_cap = ZSTD_CStreamOutSize();
    w.out = thz_malloc_array(w.out_cap, 1);
    w.cctx = ZSTD_createCCtx();
    if (!header || !w.out || !w.cctx) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "cannot write photon map %s: out of memory", path);
        goto cleanup;
    }
    size_t r = ZSTD_CCtx_setParameter(w.cctx, ZSTD_c_compressionLevel, PMF_LEVEL);
    if (!ZSTD_isError(r))
        r = ZSTD_CCtx_setParameter(w.cctx, ZSTD_c_checksumFlag, 1);
    if (!ZSTD_isError(r))
        r = ZSTD_CCtx_setParameter(w.cctx, ZSTD_c_contentSizeFlag, 1);
    if (ZSTD_isError(r)) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "cannot write photon map %s: %s", path,
                           ZSTD_getErrorName(r));
        goto cleanup;
    }
    /* Workers: at least 1, whose output any count shares (0 is zstd's single-threaded
     * mode, encoded otherwise). An error here means a libzstd without threads. */
#ifdef _OPENMP
    int workers = thz_threads_or_all(threads);
#else
    int workers = threads > 0 ? threads : 1;
#endif
    (void)ZSTD_CCtx_setParameter(w.cctx, ZSTD_c_nbWorkers, workers > 1 ? workers : 1);

    scene_hash h;
    scene_hash_compute(scene, &h);
    uint64_t total_records = 0;
    put_u64(header + 0, h.geometry);
    put_u64(header + 8, h.optics);
    put_u64(header + 16, h.channels);
    put_u64(header + 24, nc);
    put_u64(header + 32, scene->n_objects);
    put_u64(header + 40, scene->photons.seed);
    put_u64(header + 48, scene->photons.per_channel);
    for (size_t c = 0; c < nc; c++) {
        if (!maps[c]) {
            st = thz_error_set(err, THZ_ERR_INTERNAL,
                               "cannot write photon map %s: channel %zu has no map", path, c);
            goto cleanup;
        }
        uint8_t *p = header + 8 * (PMF_HEADER_FIXED + (size_t)PMF_CHANNEL_WORDS * c);
        uint64_t count = photon_map_count(maps[c]);
        put_f64(p, scene->channels[c].center_hz);
        /* 0 for a measured response: its table is in the header's channel hash */
        put_f64(p + 8, scene->channels[c].relative_width);
        put_u64(p + 16, count);
        photon_stats s = {0};
        if (stats)
            s = stats[c];
        pmf_put_stats(p + 24, &s);
        put_f64(p + 160, photon_map_reference_temperature_k(maps[c]));
        total_records += count;
    }

    w.f = fopen(path, "wb");
    if (!w.f) {
        st = thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO),
                           "cannot create photon map %s: %s", path, strerror(errno));
        goto cleanup;
    }
    uint8_t prefix[PMF_PREFIX_BYTES] = {0};
    memcpy(prefix, PHOTON_MAP_FILE_MAGIC, 8);
    prefix[8] = (uint8_t)PHOTON_MAP_FILE_VERSION;
    st = pmf_write_bytes(&w, prefix, sizeof prefix, err); /* size patched at the end */
    if (st == THZ_OK)
        st = pmf_begin_frame(&w, header_bytes, err);
    /* the header streamed and then ended: a first call that ends the frame is zstd's
     * one-shot compression, whose jobs, unlike the stream's, depend on the workers */
    if (st == THZ_OK)
        st = pmf_compress(&w, header, header_bytes, ZSTD_e_continue, err);
    if (st == THZ_OK)
        st = pmf_compress(&w, NULL, 0, ZSTD_e_end, err);
    if (st == THZ_OK)
        st = pmf_begin_frame(&w, total_records * sizeof(photon_record), err);
    for (size_t c = 0; c < nc && st == THZ_OK; c++)
        st = pmf_write_channel(&w, maps[c], err);
    if (st == THZ_OK)
        st = pmf_compress(&w, NULL, 0, ZSTD_e_end, err);
    if (st != THZ_OK)
        goto cleanup;
    long size = ftell(w.f);
    if (size < 0 || fseek(w.f, 16, SEEK_SET) != 0) {
        st =
            thz_error_set(err, THZ_ERR_IO, "cannot write photon map %s: %s", path, strerror(errno));
        goto cleanup;
    }
    put_u64(prefix + 16, (uint64_t)size);
    st = pmf_write_bytes(&w, prefix + 16, 8, err);
    if (st != THZ_OK)
        goto cleanup;
    FILE *f = w.f;
    w.f = NULL;
    if (fclose(f) != 0)
        st =
            thz_error_set(err, THZ_ERR_IO, "cannot write photon map %s: %s", path, strerror(errno));
cleanup:
    if (w.f)
        fclose(w.f);
    ZSTD_freeCCtx(w.cctx);
    free(w.out);
    free(header);
    return st;
}
