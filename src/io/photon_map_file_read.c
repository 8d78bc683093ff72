/* photon-map.thzpm reader: see photon_map_file.h for the layout. */
#include "io/photon_map_file.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zstd.h>
#include <zstd_errors.h>

#include "core/alloc.h"
#include "core/file.h"
#include "io/photon_map_file_format.h"
#include "scene/scene_hash.h"

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

/* A damaged file is bad input (exit status 2), as a damaged scene or mesh is; a failed read
 * of the device is THZ_ERR_IO. */
static thz_status pmf_corrupt(const pmf_reader *r, const char *why, thz_error *err)
{
    return thz_error_set(err, THZ_ERR_INPUT,
                         "photon map %s is corrupted (%s); run `thzmap simulate` again", r->path,
                         why);
}

static thz_status pmf_zstd_error(const pmf_reader *r, size_t code, thz_error *err)
{
    if (ZSTD_getErrorCode(code) == ZSTD_error_checksum_wrong)
        return pmf_corrupt(r, "checksum mismatch", err);
    /* zstd's own window buffer, allocated as the first frame is read: the machine's fault,
     * not the file's (test_alloc_fail found it called corrupt, exit status 2) */
    if (ZSTD_getErrorCode(code) == ZSTD_error_memory_allocation)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory while reading photon map %s",
                             r->path);
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
                                   size_t record_bytes, size_t nc, uint64_t file_bytes,
                                   thz_error *err)
{
    uint64_t total = 0;
    for (size_t c = 0; c < nc; c++) {
        uint64_t count = get_u64(header + 8 * (PMF_HEADER_FIXED + channel_words * c) + 16);
        if (count > (UINT64_MAX - total) / record_bytes)
            return pmf_corrupt(r, "impossible record count", err);
        total += count * record_bytes;
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
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s is corrupted (its header counts %llu bytes of photons, "
                             "its records section holds %llu); run `thzmap simulate` again",
                             r->path, (unsigned long long)total, stated);
    if (total > SIZE_MAX || total / ZSTD_BLOCKSIZE_MAX > rest / 4 + 1)
        return thz_error_set(err, THZ_ERR_INPUT,
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

struct photon_map_file_stream {
    pmf_reader r;
    const thz_scene *scene;
    uint8_t *header;
    uint32_t version;
    size_t channel_words;
    size_t next; /* the channel whose records come next */
};

void photon_map_file_close(photon_map_file_stream *s)
{
    if (!s)
        return;
    free(s->header);
    ZSTD_freeDCtx(s->r.dctx);
    free(s->r.in);
    if (s->r.f)
        fclose(s->r.f);
    free(s);
}

/* Channel c's words in the header. */
static const uint8_t *pmf_channel_words(const photon_map_file_stream *s, size_t c)
{
    return s->header + 8 * (PMF_HEADER_FIXED + s->channel_words * c);
}

/* The prefix: magic, version, flags, and the file's size against the one it states.
 * Sets s->version and s->channel_words; *actual gets the file's size. */
static thz_status pmf_open_prefix(photon_map_file_stream *s, long *actual, thz_error *err)
{
    const char *path = s->r.path;
    /* a FIFO or a device would block the open or never end: regular files only (the
     * size is checked against the prefix below) */
    struct stat file;
    if (stat(path, &file) == 0 && !S_ISREG(file.st_mode)) {
        thz_status st = file_check_regular(path, NULL, UINT64_MAX, NULL, err);
        thz_error_prefix(err, "photon map ");
        return st;
    }
    s->r.f = fopen(path, "rb");
    if (!s->r.f)
        return errno == ENOMEM
                   ? thz_error_set(err, THZ_ERR_NOMEM, "out of memory while opening photon map %s",
                                   path)
                   : thz_error_set(err, errno == ENOENT ? THZ_ERR_INPUT : THZ_ERR_IO,
                                   "cannot open photon map %s: %s", path, strerror(errno));
    *actual = -1;
    if (fseek(s->r.f, 0, SEEK_END) == 0)
        *actual = ftell(s->r.f);
    if (*actual < 0 || fseek(s->r.f, 0, SEEK_SET) != 0)
        return thz_error_set(err, THZ_ERR_IO, "cannot read photon map %s: %s", path,
                             strerror(errno));
    uint8_t prefix[PMF_PREFIX_BYTES];
    size_t got = fread(prefix, 1, sizeof prefix, s->r.f);
    if (got >= 8 && memcmp(prefix, PHOTON_MAP_FILE_MAGIC, 8) != 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s is not a thzmap photon map (.thzpm) file",
                             path);
    if (got < sizeof prefix)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s is truncated (%ld bytes); run `thzmap simulate` again",
                             path, *actual);
    uint32_t version = (uint32_t)(get_u64(prefix + 8) & 0xffffffffu);
    if (version < 1u || version > PHOTON_MAP_FILE_VERSION)
        return thz_error_set(
            err, THZ_ERR_INPUT,
            "photon map %s has format version %u; this thzmap reads versions 1 to %u", path,
            version, PHOTON_MAP_FILE_VERSION);
    /* No flag is defined yet: a set bit means a format this thzmap would misread. */
    uint32_t flags = (uint32_t)(get_u64(prefix + 8) >> 32);
    if (flags != 0u)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s has unknown flags 0x%08x in its prefix (this thzmap "
                             "knows none); it was written by another program or is corrupted",
                             path, (unsigned)flags);
    s->version = version;
    s->channel_words = version == 1u ? PMF_CHANNEL_WORDS_V1 : PMF_CHANNEL_WORDS;
    uint64_t stated = get_u64(prefix + 16);
    if ((uint64_t)*actual < stated)
        return thz_error_set(
            err, THZ_ERR_INPUT,
            "photon map %s is truncated (%ld of %llu bytes); run `thzmap simulate` again", path,
            *actual, (unsigned long long)stated);
    if ((uint64_t)*actual > stated)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s is corrupted (%ld bytes where its header says %llu); "
                             "run `thzmap simulate` again",
                             path, *actual, (unsigned long long)stated);
    return THZ_OK;
}

/* Frame 1, the header (checksum verified before use), and whether it belongs to
 * s->scene. */
static thz_status pmf_open_header(photon_map_file_stream *s, thz_error *err)
{
    pmf_reader *r = &s->r;
    const char *path = r->path;
    const thz_scene *scene = s->scene;
    thz_status st = pmf_fill(r, err);
    if (st != THZ_OK)
        return st;
    unsigned long long hsize = ZSTD_getFrameContentSize(r->in + r->in_pos, r->in_size - r->in_pos);
    if (hsize == ZSTD_CONTENTSIZE_ERROR || hsize == ZSTD_CONTENTSIZE_UNKNOWN ||
        hsize < 8 * PMF_HEADER_FIXED || hsize > PMF_MAX_HEADER_BYTES)
        return pmf_corrupt(r, "bad header", err);
    s->header = thz_malloc_array((size_t)hsize, 1);
    if (!s->header)
        return thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
    st = pmf_read(r, s->header, (size_t)hsize, err);
    if (st == THZ_OK)
        st = pmf_end_frame(r, err);
    if (st != THZ_OK)
        return st;
    const uint8_t *header = s->header;
    uint64_t file_nc = get_u64(header + 24);
    if (file_nc > (PMF_MAX_HEADER_BYTES / 8) ||
        hsize != 8 * (PMF_HEADER_FIXED + s->channel_words * file_nc))
        return pmf_corrupt(r, "inconsistent header", err);

    /* Does it belong to this scene? */
    scene_hash made = {.geometry = get_u64(header + 0),
                       .optics = get_u64(header + 8),
                       .channels = get_u64(header + 16)};
    char maps[sizeof err->message];
    snprintf(maps, sizeof maps, "photon map %s", path);
    st = scene_hash_fit(&made, get_u64(header + 32), file_nc, scene, maps,
                        "run `thzmap simulate` on this scene", err);
    if (st != THZ_OK)
        return st;
    for (size_t c = 0; c < scene->n_channels; c++) {
        double t0_k = s->version == 1u ? 0.0 : get_f64(pmf_channel_words(s, c) + 160);
        if (!(t0_k >= 0.0 && t0_k <= PMF_MAX_T0_K))
            return pmf_corrupt(r, "impossible reference temperature", err);
    }
    uint64_t per_channel = get_u64(header + 48);
    if (per_channel == 0 || per_channel > PMF_MAX_PHOTONS)
        return pmf_corrupt(r, "impossible photon count", err);
    return THZ_OK;
}

thz_status photon_map_file_open(const char *path, const thz_scene *scene, photon_stats *stats,
                                photon_map_file_info *info, photon_map_file_stream **out,
                                thz_error *err)
{
    *out = NULL;
    photon_map_file_stream *s = thz_calloc(1, sizeof *s);
    if (!s)
        return thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
    s->r.path = path;
    s->scene = scene;
    long actual = -1;
    thz_status st = pmf_open_prefix(s, &actual, err);
    if (st == THZ_OK) {
        s->r.in_cap = ZSTD_DStreamInSize();
        s->r.in = thz_malloc_array(s->r.in_cap, 1);
        s->r.dctx = ZSTD_createDCtx();
        if (!s->r.in || !s->r.dctx)
            st =
                thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
    }
    if (st == THZ_OK)
        st = pmf_open_header(s, err);
    /* Frame 2: the records. Before any is allocated, the counts must fit what the rest of
     * the file can hold. */
    if (st == THZ_OK)
        st = pmf_check_counts(&s->r, s->header, s->channel_words, pmf_record_bytes(s->version),
                              scene->n_channels, (uint64_t)actual, err);
    if (st != THZ_OK) {
        photon_map_file_close(s);
        return st;
    }
    for (size_t c = 0; stats && c < scene->n_channels; c++) {
        const uint8_t *p = pmf_channel_words(s, c);
        pmf_get_stats(p + 24, &stats[c]);
        stats[c].seconds = 0.0;
        stats[c].reference_temperature_k = s->version == 1u ? 0.0 : get_f64(p + 160);
    }
    if (info) {
        info->n_channels = scene->n_channels;
        info->seed = get_u64(s->header + 40);
        info->photons_per_channel = get_u64(s->header + 48);
    }
    *out = s;
    return THZ_OK;
}

size_t photon_map_file_largest_count(const photon_map_file_stream *s)
{
    size_t most = 0;
    for (size_t c = 0; c < s->scene->n_channels; c++) {
        uint64_t n = get_u64(pmf_channel_words(s, c) + 16);
        most = n > most ? (size_t)n : most; /* pmf_check_counts: the bytes fit size_t */
    }
    return most;
}

/* n records of a file of version 1 to 3 into records: each 32-byte image's object and
 * side, bounce count and batch into the tag (PMF_RECORD_BYTES_V3). */
static thz_status pmf_read_v3(pmf_reader *r, photon_record *records, size_t n, thz_error *err)
{
    enum { CHUNK = 1024 };
    uint8_t buf[CHUNK * PMF_RECORD_BYTES_V3];
    for (size_t i = 0; i < n; i += CHUNK) {
        size_t m = n - i < CHUNK ? n - i : CHUNK;
        thz_status st = pmf_read(r, buf, m * PMF_RECORD_BYTES_V3, err);
        if (st != THZ_OK)
            return st;
        for (size_t k = 0; k < m; k++) {
            const uint8_t *b = buf + k * PMF_RECORD_BYTES_V3;
            photon_record *q = &records[i + k];
            memcpy(q, b, offsetof(photon_record, tag));
            uint32_t object_side = get_u32(b + 24), flags = get_u32(b + 28);
            if (object_side >> 1 >= PHOTON_MAX_OBJECTS)
                return pmf_corrupt(r, "a photon names an object the scene does not have", err);
            q->tag = photon_tag(object_side >> 1, (int)(object_side & 1u), (flags & 0xffffu) == 0,
                                flags >> 24);
        }
    }
    return THZ_OK;
}

/* The next channel's records: into a new array (*records, *count) when keep, else
 * checked against the checksum and dropped. After the last channel's, the records
 * frame's end and the file's. */
static thz_status pmf_next_records(photon_map_file_stream *s, bool keep, photon_record **records,
                                   size_t *count, thz_error *err)
{
    pmf_reader *r = &s->r;
    if (s->next >= s->scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "photon map %s: no channel %zu", r->path,
                             s->next);
    size_t n = (size_t)get_u64(pmf_channel_words(s, s->next) + 16);
    thz_status st = THZ_OK;
    if (!keep) {
        st = pmf_skip(r, (uint64_t)n * pmf_record_bytes(s->version), err);
    } else {
        *records = thz_malloc_array(n ? n : 1, sizeof(photon_record));
        *count = n;
        if (!*records)
            return thz_error_set(err, THZ_ERR_NOMEM,
                                 "cannot read photon map %s: out of memory for %zu photons",
                                 r->path, n);
        st = s->version >= 4u ? pmf_read(r, *records, n * sizeof(photon_record), err)
                              : pmf_read_v3(r, *records, n, err);
        for (size_t i = 0; st == THZ_OK && i < n; i++) {
            const photon_record *q = &(*records)[i];
            if (photon_object(q) >= s->scene->n_objects)
                st = pmf_corrupt(r, "a photon names an object the scene does not have", err);
            else if (!isfinite(q->position_m[0]) || !isfinite(q->position_m[1]) ||
                     !isfinite(q->position_m[2]) || !isfinite(q->power_w_per_hz) ||
                     !(q->freq_hz > 0.0f && isfinite(q->freq_hz)))
                st = pmf_corrupt(r,
                                 "a photon's position, power or frequency is impossible (not "
                                 "finite, or a frequency <= 0)",
                                 err);
        }
        if (st != THZ_OK) {
            free(*records);
            *records = NULL;
        }
    }
    if (st == THZ_OK && ++s->next == s->scene->n_channels) {
        st = pmf_end_frame(r, err);
        if (st == THZ_OK)
            st = pmf_fill(r, err);
        if (st == THZ_OK && !r->eof)
            st = pmf_corrupt(r, "data after the end", err);
        if (st != THZ_OK && keep) {
            free(*records);
            *records = NULL;
        }
    }
    return st;
}

/* Channel c's map from its records (taken, also on failure), with its T0 and batches. */
static thz_status pmf_build(const photon_map_file_stream *s, size_t c, photon_record *records,
                            size_t count, int threads, photon_map **map, thz_error *err)
{
    thz_status st = photon_map_create(records, count, s->scene->n_objects, threads, map, err);
    if (st != THZ_OK) {
        thz_error_prefix(err, "photon map %s: ", s->r.path);
        return st;
    }
    photon_map_set_reference_temperature_k(
        *map, s->version == 1u ? 0.0 : get_f64(pmf_channel_words(s, c) + 160));
    /* version 1 stored no batches (its flags' upper bits are 0) */
    photon_map_set_batches(*map, s->version == 1u ? 1u : PHOTON_MAP_BATCHES);
    return THZ_OK;
}

thz_status photon_map_file_next(photon_map_file_stream *s, int threads, photon_map **map,
                                thz_error *err)
{
    *map = NULL;
    size_t c = s->next, count = 0;
    photon_record *records = NULL;
    thz_status st = pmf_next_records(s, true, &records, &count, err);
    if (st == THZ_OK)
        st = pmf_build(s, c, records, count, threads, map, err);
    return st;
}

/* Reports channel c's done of total to progress (may be NULL); THZ_ERR_CANCELLED when
 * it says stop. */
static thz_status pmf_report(const photon_map_file_progress *progress, const char *path, size_t c,
                             uint64_t done, uint64_t total, thz_error *err)
{
    if (progress && progress->fn && progress->fn(progress->user, c, done, total) != 0)
        return thz_error_set(err, THZ_ERR_CANCELLED, "reading photon map %s: cancelled", path);
    return THZ_OK;
}

/* photon_map_file_read of every channel (want = SIZE_MAX) or of channel want alone: all
 * the records read and the checksum verified before any map is built. */
static thz_status pmf_read_file(const char *path, const thz_scene *scene, int threads, size_t want,
                                const photon_map_file_progress *progress, photon_map **maps,
                                photon_stats *stats, photon_map_file_info *info, thz_error *err)
{
    size_t nc = scene->n_channels;
    for (size_t c = 0; c < nc; c++)
        maps[c] = NULL;
    photon_record **records = thz_calloc(nc ? nc : 1, sizeof *records);
    size_t *counts = thz_calloc(nc ? nc : 1, sizeof *counts);
    photon_map_file_stream *s = NULL;
    thz_status st = THZ_OK;
    if (!records || !counts)
        st = thz_error_set(err, THZ_ERR_NOMEM, "cannot read photon map %s: out of memory", path);
    if (st == THZ_OK)
        st = photon_map_file_open(path, scene, stats, info, &s, err);
    for (size_t c = 0; st == THZ_OK && c < nc; c++) {
        uint64_t n = get_u64(pmf_channel_words(s, c) + 16);
        st = pmf_report(progress, path, c, 0, n, err);
        if (st == THZ_OK)
            st = pmf_next_records(s, want == SIZE_MAX || c == want, &records[c], &counts[c], err);
    }
    for (size_t c = 0; st == THZ_OK && c < nc; c++) {
        if (records[c]) {
            photon_record *rec = records[c];
            size_t n = counts[c];
            records[c] = NULL; /* pmf_build owns it from here, also on failure */
            st = pmf_build(s, c, rec, n, threads, &maps[c], err);
            if (st == THZ_OK)
                st = pmf_report(progress, path, c, n, n, err);
        }
    }
    if (st != THZ_OK)
        for (size_t c = 0; c < nc; c++) {
            photon_map_destroy(maps[c]);
            maps[c] = NULL;
        }
    for (size_t c = 0; records && c < nc; c++)
        free(records[c]);
    free(records);
    free(counts);
    photon_map_file_close(s);
    return st;
}

thz_status photon_map_file_read(const char *path, const thz_scene *scene, int threads,
                                photon_map **maps, photon_stats *stats, photon_map_file_info *info,
                                thz_error *err)
{
    return photon_map_file_read_progress(path, scene, threads, SIZE_MAX, NULL, maps, stats, info,
                                         err);
}

thz_status photon_map_file_read_channel(const char *path, const thz_scene *scene, int threads,
                                        size_t channel, photon_map **maps, photon_stats *stats,
                                        photon_map_file_info *info, thz_error *err)
{
    return photon_map_file_read_progress(path, scene, threads, channel, NULL, maps, stats, info,
                                         err);
}

thz_status photon_map_file_read_progress(const char *path, const thz_scene *scene, int threads,
                                         size_t want, const photon_map_file_progress *progress,
                                         photon_map **maps, photon_stats *stats,
                                         photon_map_file_info *info, thz_error *err)
{
    if (want != SIZE_MAX && want >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon map %s: no channel %zu (the scene has %zu)", path, want,
                             scene->n_channels);
    return pmf_read_file(path, scene, threads, want, progress, maps, stats, info, err);
}
