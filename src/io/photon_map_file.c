/* photon-map.thzpm writer and reader: see photon_map_file.h for the layout. */
#include "io/photon_map_file.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zstd.h>
#include <zstd_errors.h>

#include "core/alloc.h"
#include "core/file.h"
#include "scene/scene_hash.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "photon_map_file.c writes records as in memory: little-endian hosts only"
#endif

#define PMF_PREFIX_BYTES 24u
#define PMF_HEADER_FIXED 7u      /* u64 words before the channels */
#define PMF_CHANNEL_WORDS 21u    /* centre, width, count, 10 counters, 7 reals, T0 */
#define PMF_CHANNEL_WORDS_V1 20u /* version 1 had no T0 (its maps have T0 = 0) */
/* zstd level 1: at 3 it took twice the time (the paper's case, one channel of 10 M photons:
 * 2.9 s against 1.5 s) for a file 1.2 % smaller */
#define PMF_LEVEL 1
#define PMF_FLAGS_STORED                                                                           \
    (0xffffu | (PHOTON_MAP_BATCHES - 1u) << PHOTON_BATCH_SHIFT) /* bounces, batch */
#define PMF_MAX_HEADER_BYTES (16u << 20)
#define PMF_FRAME_HEADER_MAX 18u /* bytes: zstd's largest frame header */

/* ---- little-endian words ---------------------------------------------------- */

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

static void put_f64(uint8_t *p, double x)
{
    uint64_t v;
    memcpy(&v, &x, sizeof v);
    put_u64(p, v);
}

static double get_f64(const uint8_t *p)
{
    uint64_t v = get_u64(p);
    double x;
    memcpy(&x, &v, sizeof x);
    return x;
}

/* The stats of one channel as 17 words (order fixed by version 1). */
static void pmf_put_stats(uint8_t *p, const photon_stats *s)
{
    const uint64_t u[10] = {s->fired,       s->stored,       s->hits,    s->reflected,
                            s->transmitted, s->absorbed,     s->escaped, s->back_face_hits,
                            s->terminated,  s->bounce_capped};
    const double d[7] = {s->emitted_power_w_per_hz,
                         s->absorbed_power_w_per_hz,
                         s->escaped_power_w_per_hz,
                         s->atmosphere_power_w_per_hz,
                         s->mean_bounces,
                         s->fired_power_w_per_hz,
                         s->terminated_power_w_per_hz};
    for (int i = 0; i < 10; i++)
        put_u64(p + 8 * i, u[i]);
    for (int i = 0; i < 7; i++)
        put_f64(p + 80 + 8 * i, d[i]);
}

static void pmf_get_stats(const uint8_t *p, photon_stats *s)
{
    memset(s, 0, sizeof *s);
    uint64_t *u[10] = {&s->fired,       &s->stored,       &s->hits,    &s->reflected,
                       &s->transmitted, &s->absorbed,     &s->escaped, &s->back_face_hits,
                       &s->terminated,  &s->bounce_capped};
    double *d[7] = {&s->emitted_power_w_per_hz,
                    &s->absorbed_power_w_per_hz,
                    &s->escaped_power_w_per_hz,
                    &s->atmosphere_power_w_per_hz,
                    &s->mean_bounces,
                    &s->fired_power_w_per_hz,
                    &s->terminated_power_w_per_hz};
    for (int i = 0; i < 10; i++)
        *u[i] = get_u64(p + 8 * i);
    for (int i = 0; i < 7; i++)
        *d[i] = get_f64(p + 80 + 8 * i);
}

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
            return thz_error_set(err, THZ_ERR_INTERNAL, "cannot compress photon map %s: %s",
                                 w->path, ZSTD_getErrorName(r));
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
 * back byte for byte. A chunk at a time, keeping only the flags the phase stored (the
 * upper bits are the map's: maps before the octree kept a kd-tree split axis there). */
static thz_status pmf_write_channel(pmf_writer *w, const photon_map *map, thz_error *err)
{
    const photon_record *r = photon_map_records(map);
    size_t n = photon_map_count(map);
    photon_record *tmp = thz_malloc_array(PMF_CHUNK, sizeof *tmp);
    if (!tmp)
        return thz_error_set(err, THZ_ERR_NOMEM, "cannot write photon map %s: out of memory",
                             w->path);
    thz_status st = THZ_OK;
    for (size_t i = 0; i < n && st == THZ_OK; i += PMF_CHUNK) {
        size_t m = n - i < PMF_CHUNK ? n - i : PMF_CHUNK;
        memcpy(tmp, r + i, m * sizeof *tmp);
        for (size_t k = 0; k < m; k++)
            tmp[k].flags &= PMF_FLAGS_STORED;
        st = pmf_compress(w, tmp, m * sizeof *tmp, ZSTD_e_continue, err);
    }
    free(tmp);
    return st;
}

thz_status photon_map_file_write(const char *path, const thz_scene *scene,
                                 const photon_map *const *maps, const photon_stats *stats,
                                 thz_error *err)
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
    if (st == THZ_OK)
        st = pmf_compress(&w, header, header_bytes, ZSTD_e_end, err);
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

/* ---- reading ------------------------------------------------------------------ */

typedef struct pmf_reader {
    const char *path;
    FILE *f;
    ZSTD_DCtx *dctx;
    uint8_t *in;
    size_t in_cap, in_pos, in_size;
    bool eof;
    bool frame_done; /* the current frame was completed (checksum verified) */
} pmf_reader;

static thz_status pmf_corrupt(const pmf_reader *r, const char *why, thz_error *err)
{
    return thz_error_set(err, THZ_ERR_IO,
                         "photon map %s is corrupted (%s); run `thzmap simulate` again", r->path,
                         why);
}

static thz_status pmf_zstd_error(const pmf_reader *r, size_t code, thz_error *err)
{
    if (ZSTD_getErrorCode(code) == ZSTD_error_checksum_wrong)
        return pmf_corrupt(r, "checksum mismatch", err);
    return pmf_corrupt(r, ZSTD_getErrorName(code), err);
}

static thz_status pmf_fill(pmf_reader *r, thz_error *err)
{
    if (r->in_pos < r->in_size || r->eof)
        return THZ_OK;
    r->in_size = fread(r->in, 1, r->in_cap, r->f);
    r->in_pos = 0;
    if (r->in_size == 0) {
        if (ferror(r->f))
            return thz_error_set(err, THZ_ERR_IO, "cannot read photon map %s: %s", r->path,
                                 strerror(errno));
        r->eof = true;
    }
    return THZ_OK;
}

/* Decompresses exactly n bytes of the current frame into dst. */
static thz_status pmf_read(pmf_reader *r, void *dst, size_t n, thz_error *err)
{
    ZSTD_outBuffer out = {dst, n, 0};
    while (out.pos < n) {
        thz_status st = pmf_fill(r, err);
        if (st != THZ_OK)
            return st;
        if (r->eof)
            return pmf_corrupt(r, "its data ends early", err);
        ZSTD_inBuffer in = {r->in, r->in_size, r->in_pos};
        size_t ret = ZSTD_decompressStream(r->dctx, &out, &in);
        r->in_pos = in.pos;
        if (ZSTD_isError(ret))
            return pmf_zstd_error(r, ret, err);
        if (ret == 0 && out.pos < n)
            return pmf_corrupt(r, "a section is shorter than its header says", err);
        r->frame_done = ret == 0;
    }
    return THZ_OK;
}

/* Finishes the current frame, which must hold no more data (checks its checksum). */
static thz_status pmf_end_frame(pmf_reader *r, thz_error *err)
{
    /* Once a frame is done, zstd would start decoding the next one. */
    if (r->frame_done) {
        r->frame_done = false;
        return THZ_OK;
    }
    for (;;) {
        thz_status st = pmf_fill(r, err);
        if (st != THZ_OK)
            return st;
        uint8_t extra;
        ZSTD_outBuffer out = {&extra, 1, 0};
        ZSTD_inBuffer in = {r->in, r->in_size, r->in_pos};
        size_t ret = ZSTD_decompressStream(r->dctx, &out, &in);
        r->in_pos = in.pos;
        if (ZSTD_isError(ret))
            return pmf_zstd_error(r, ret, err);
        if (out.pos > 0)
            return pmf_corrupt(r, "a section is longer than its header says", err);
        if (ret == 0)
            return THZ_OK;
        if (r->eof)
            return pmf_corrupt(r, "its data ends early", err);
    }
}

/* Makes at least n bytes (n <= in_cap) of input available at r->in + r->in_pos, or all
 * that is left of the file. */
static thz_status pmf_peek(pmf_reader *r, size_t n, thz_error *err)
{
    size_t have = r->in_size - r->in_pos;
    if (have >= n || r->eof)
        return THZ_OK;
    memmove(r->in, r->in + r->in_pos, have);
    r->in_pos = 0;
    r->in_size = have + fread(r->in + have, 1, r->in_cap - have, r->f);
    if (ferror(r->f))
        return thz_error_set(err, THZ_ERR_IO, "cannot read photon map %s: %s", r->path,
                             strerror(errno));
    return THZ_OK;
}

/* Before the records are allocated: the header's counts (nc channels) must be the
 * bytes the records frame states it holds (when it states them), and no more than the
 * rest of the file (file_bytes in all) can decompress to: a zstd block holds at most
 * ZSTD_BLOCKSIZE_MAX bytes and takes at least 4 (a 3-byte header and one RLE byte). */
static thz_status pmf_check_counts(pmf_reader *r, const uint8_t *header, size_t channel_words,
                                   size_t nc, uint64_t file_bytes, thz_error *err)
{
    uint64_t total = 0;
    for (size_t c = 0; c < nc; c++) {
        uint64_t count = get_u64(header + 8 * (PMF_HEADER_FIXED + channel_words * c) + 16);
        if (count > (UINT64_MAX - total) / sizeof(photon_record))
            return pmf_corrupt(r, "impossible record count", err);
        total += count * sizeof(photon_record);
    }
    thz_status st = pmf_peek(r, PMF_FRAME_HEADER_MAX, err);
    if (st != THZ_OK)
        return st;
    long pos = ftell(r->f);
    uint64_t consumed = pos >= 0 ? (uint64_t)pos - (r->in_size - r->in_pos) : 0;
    uint64_t rest = file_bytes > consumed ? file_bytes - consumed : 0;
    unsigned long long stated = ZSTD_getFrameContentSize(r->in + r->in_pos, r->in_size - r->in_pos);
    if (stated == ZSTD_CONTENTSIZE_ERROR)
        return pmf_corrupt(r, "bad records section", err);
    if (stated != ZSTD_CONTENTSIZE_UNKNOWN && stated != total)
        return thz_error_set(err, THZ_ERR_IO,
                             "photon map %s is corrupted (its header counts %llu bytes of photons, "
                             "its records section holds %llu); run `thzmap simulate` again",
                             r->path, (unsigned long long)total, stated);
    if (total > SIZE_MAX || total / ZSTD_BLOCKSIZE_MAX > rest / 4 + 1)
        return thz_error_set(err, THZ_ERR_IO,
                             "photon map %s is corrupted (its header counts %llu bytes of photons, "
                             "more than its %llu remaining bytes can hold); run `thzmap simulate` "
                             "again",
                             r->path, (unsigned long long)total, (unsigned long long)rest);
    return THZ_OK;
}

/* Reads n bytes of r's current frame and drops them, through a bounded buffer. */
static thz_status pmf_skip(pmf_reader *r, uint64_t n, thz_error *err)
{
    uint8_t buf[65536];
    thz_status st = THZ_OK;
    while (st == THZ_OK && n > 0) {
        size_t k = n < sizeof buf ? (size_t)n : sizeof buf;
        st = pmf_read(r, buf, k, err);
        n -= k;
    }
    return st;
}

/* photon_map_file_read of every channel (want = SIZE_MAX) or of channel want alone. */
static thz_status pmf_read_file(const char *path, const thz_scene *scene, int threads, size_t want,
                                photon_map **maps, photon_stats *stats, photon_map_file_info *info,
                                thz_error *err)
{
    thz_status st = THZ_OK;
    size_t nc = scene->n_channels;
    pmf_reader r = {.path = path};
    uint8_t *header = NULL;
    photon_record **records = thz_calloc(nc ? nc : 1, sizeof *records);
    double *t0_k = thz_calloc(nc ? nc : 1, sizeof *t0_k); /* each map's reference temperature */
    for (size_t c = 0; c < nc; c++)
        maps[c] = NULL;
    if (!records || !t0_k) {
        free(records);
        free(t0_k);
        return thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
    }

    /* a FIFO or a device would block the open or never end: regular files only (the
     * size is checked against the prefix below) */
    struct stat file;
    if (stat(path, &file) == 0 && !S_ISREG(file.st_mode)) {
        st = file_check_regular(path, NULL, UINT64_MAX, NULL, err);
        thz_error_prefix(err, "photon map ");
        goto cleanup;
    }
    r.f = fopen(path, "rb");
    if (!r.f) {
        st = errno == ENOMEM
                 ? thz_error_set(err, THZ_ERR_NOMEM, "out of memory while opening photon map %s",
                                 path)
                 : thz_error_set(err, errno == ENOENT ? THZ_ERR_INPUT : THZ_ERR_IO,
                                 "cannot open photon map %s: %s", path, strerror(errno));
        goto cleanup;
    }
    long actual = -1;
    if (fseek(r.f, 0, SEEK_END) == 0)
        actual = ftell(r.f);
    if (actual < 0 || fseek(r.f, 0, SEEK_SET) != 0) {
        st = thz_error_set(err, THZ_ERR_IO, "cannot read photon map %s: %s", path, strerror(errno));
        goto cleanup;
    }
    uint8_t prefix[PMF_PREFIX_BYTES];
    size_t got = fread(prefix, 1, sizeof prefix, r.f);
    if (got >= 8 && memcmp(prefix, PHOTON_MAP_FILE_MAGIC, 8) != 0) {
        st = thz_error_set(err, THZ_ERR_INPUT, "%s is not a thzmap photon map (.thzpm) file", path);
        goto cleanup;
    }
    if (got < sizeof prefix) {
        st = thz_error_set(err, THZ_ERR_IO,
                           "photon map %s is truncated (%ld bytes); run `thzmap simulate` again",
                           path, actual);
        goto cleanup;
    }
    uint32_t version = (uint32_t)(get_u64(prefix + 8) & 0xffffffffu);
    if (version < 1u || version > PHOTON_MAP_FILE_VERSION) {
        st =
            thz_error_set(err, THZ_ERR_INPUT,
                          "photon map %s has format version %u; this thzmap reads versions 1 to %u",
                          path, version, PHOTON_MAP_FILE_VERSION);
        goto cleanup;
    }
    /* No flag is defined yet: a set bit means a format this thzmap would misread. */
    uint32_t flags = (uint32_t)(get_u64(prefix + 8) >> 32);
    if (flags != 0u) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "photon map %s has unknown flags 0x%08x in its prefix (this thzmap "
                           "knows none); it was written by another program or is corrupted",
                           path, (unsigned)flags);
        goto cleanup;
    }
    const size_t channel_words = version == 1u ? PMF_CHANNEL_WORDS_V1 : PMF_CHANNEL_WORDS;
    uint64_t stated = get_u64(prefix + 16);
    if ((uint64_t)actual < stated) {
        st = thz_error_set(
            err, THZ_ERR_IO,
            "photon map %s is truncated (%ld of %llu bytes); run `thzmap simulate` again", path,
            actual, (unsigned long long)stated);
        goto cleanup;
    }
    if ((uint64_t)actual > stated) {
        st = thz_error_set(err, THZ_ERR_IO,
                           "photon map %s is corrupted (%ld bytes where its header says %llu); run "
                           "`thzmap simulate` again",
                           path, actual, (unsigned long long)stated);
        goto cleanup;
    }

    r.in_cap = ZSTD_DStreamInSize();
    r.in = thz_malloc_array(r.in_cap, 1);
    r.dctx = ZSTD_createDCtx();
    if (!r.in || !r.dctx) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
        goto cleanup;
    }

    /* Frame 1: the header, whose size the frame states; checksum verified before use. */
    st = pmf_fill(&r, err);
    if (st != THZ_OK)
        goto cleanup;
    unsigned long long hsize = ZSTD_getFrameContentSize(r.in + r.in_pos, r.in_size - r.in_pos);
    if (hsize == ZSTD_CONTENTSIZE_ERROR || hsize == ZSTD_CONTENTSIZE_UNKNOWN ||
        hsize < 8 * PMF_HEADER_FIXED || hsize > PMF_MAX_HEADER_BYTES) {
        st = pmf_corrupt(&r, "bad header", err);
        goto cleanup;
    }
    header = thz_malloc_array((size_t)hsize, 1);
    if (!header) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
        goto cleanup;
    }
    st = pmf_read(&r, header, (size_t)hsize, err);
    if (st == THZ_OK)
        st = pmf_end_frame(&r, err);
    if (st != THZ_OK)
        goto cleanup;
    uint64_t file_nc = get_u64(header + 24);
    if (file_nc > (PMF_MAX_HEADER_BYTES / 8) ||
        hsize != 8 * (PMF_HEADER_FIXED + channel_words * file_nc)) {
        st = pmf_corrupt(&r, "inconsistent header", err);
        goto cleanup;
    }

    /* Does it belong to this scene? */
    scene_hash h;
    scene_hash_compute(scene, &h);
    if (get_u64(header + 0) != h.geometry || get_u64(header + 32) != scene->n_objects) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "photon map %s was made from another scene geometry (objects or meshes "
                           "differ from %s); run `thzmap simulate` on this scene",
                           path, scene->path ? scene->path : "this scene");
        goto cleanup;
    }
    if (file_nc != nc) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "photon map %s was made from another channel set (%llu channels; %s has "
                           "%zu); run `thzmap simulate` on this scene",
                           path, (unsigned long long)file_nc,
                           scene->path ? scene->path : "this scene", nc);
        goto cleanup;
    }
    if (get_u64(header + 16) != h.channels) {
        st =
            thz_error_set(err, THZ_ERR_INPUT,
                          "photon map %s was made from another channel set (frequencies, widths or "
                          "responses differ from %s); run `thzmap simulate` on this scene",
                          path, scene->path ? scene->path : "this scene");
        goto cleanup;
    }
    if (get_u64(header + 8) != h.optics) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "photon map %s was made from another scene (materials, temperatures or "
                           "atmosphere differ from %s); run `thzmap simulate` on this scene",
                           path, scene->path ? scene->path : "this scene");
        goto cleanup;
    }

    /* Frame 2: the records. Before allocating them, the counts must fit what the rest of
     * the file can hold. */
    st = pmf_check_counts(&r, header, channel_words, nc, (uint64_t)actual, err);
    if (st != THZ_OK)
        goto cleanup;
    for (size_t c = 0; c < nc; c++) {
        const uint8_t *p = header + 8 * (PMF_HEADER_FIXED + channel_words * c);
        uint64_t count = get_u64(p + 16);
        if (want != SIZE_MAX && c != want) {
            st = pmf_skip(&r, count * sizeof(photon_record), err);
            if (st != THZ_OK)
                goto cleanup;
            if (stats) {
                pmf_get_stats(p + 24, &stats[c]);
                stats[c].seconds = 0.0;
                stats[c].reference_temperature_k = version == 1u ? 0.0 : get_f64(p + 160);
            }
            continue;
        }
        records[c] = thz_malloc_array((size_t)count, sizeof(photon_record));
        if (!records[c]) {
            st = thz_error_set(err, THZ_ERR_NOMEM,
                               "cannot read photon map %s: out of memory for %llu photons", path,
                               (unsigned long long)count);
            goto cleanup;
        }
        st = pmf_read(&r, records[c], (size_t)count * sizeof(photon_record), err);
        if (st != THZ_OK)
            goto cleanup;
        for (size_t i = 0; i < count; i++) {
            if ((records[c][i].object_side >> 1) >= scene->n_objects) {
                st = pmf_corrupt(&r, "a photon names an object the scene does not have", err);
                goto cleanup;
            }
        }
        t0_k[c] = version == 1u ? 0.0 : get_f64(p + 160);
        if (!(t0_k[c] >= 0.0) || !isfinite(t0_k[c])) {
            st = pmf_corrupt(&r, "impossible reference temperature", err);
            goto cleanup;
        }
        if (stats) {
            pmf_get_stats(p + 24, &stats[c]);
            stats[c].seconds = 0.0;
            stats[c].reference_temperature_k = t0_k[c];
        }
    }
    st = pmf_end_frame(&r, err);
    if (st != THZ_OK)
        goto cleanup;
    st = pmf_fill(&r, err);
    if (st != THZ_OK)
        goto cleanup;
    if (!r.eof) {
        st = pmf_corrupt(&r, "data after the end", err);
        goto cleanup;
    }

    for (size_t c = 0; c < nc; c++) {
        if (want != SIZE_MAX && c != want)
            continue;
        const uint8_t *p = header + 8 * (PMF_HEADER_FIXED + channel_words * c);
        photon_record *rec = records[c];
        records[c] = NULL; /* photon_map_create owns it from here, also on failure */
        st = photon_map_create(rec, (size_t)get_u64(p + 16), scene->n_objects, threads, &maps[c],
                               err);
        if (st != THZ_OK) {
            thz_error_prefix(err, "photon map %s: ", path);
            goto cleanup;
        }
        photon_map_set_reference_temperature_k(maps[c], t0_k[c]);
        /* version 1 stored no batches (its flags' upper bits are 0) */
        photon_map_set_batches(maps[c], version == 1u ? 1u : PHOTON_MAP_BATCHES);
    }
    if (info) {
        info->n_channels = nc;
        info->seed = get_u64(header + 40);
        info->photons_per_channel = get_u64(header + 48);
    }

cleanup:
    if (st != THZ_OK) {
        for (size_t c = 0; c < nc; c++) {
            photon_map_destroy(maps[c]);
            maps[c] = NULL;
        }
    }
    for (size_t c = 0; c < nc; c++)
        free(records[c]);
    free(records);
    free(t0_k);
    free(header);
    ZSTD_freeDCtx(r.dctx);
    free(r.in);
    if (r.f)
        fclose(r.f);
    return st;
}

thz_status photon_map_file_read(const char *path, const thz_scene *scene, int threads,
                                photon_map **maps, photon_stats *stats, photon_map_file_info *info,
                                thz_error *err)
{
    return pmf_read_file(path, scene, threads, SIZE_MAX, maps, stats, info, err);
}

thz_status photon_map_file_read_channel(const char *path, const thz_scene *scene, int threads,
                                        size_t channel, photon_map **maps, photon_stats *stats,
                                        photon_map_file_info *info, thz_error *err)
{
    if (channel >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s: no channel %zu (the scene has %zu)", path, channel,
                             scene->n_channels);
    return pmf_read_file(path, scene, threads, channel, maps, stats, info, err);
}
