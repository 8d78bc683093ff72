/* photon-map.thzpm: write + read gives the same maps, stats and reference temperatures
 * (channel 1 is a deviation map, T0 = 290 K), and read + write reproduces the file byte
 * for byte; the records are stored in the map's order, and files of versions 3 (32-byte
 * records) and 2 (those by group and bytes) read into the same maps; a version-1 file (no
 * T0, no batches) reads with T0 = 0;
 * corrupted (one byte flipped), truncated, forged (a record count the file cannot hold,
 * refused before allocating), foreign and mismatched (another geometry, channel set or
 * temperatures) files are refused with messages that name the file and say what is wrong. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

#include <cmocka.h>
#include <zstd.h>

#include "../physics/photon_scenes.h"
#include "accel/accel.h"
#include "io/photon_map_file.h"
#include "photon/phase.h"

typedef struct fixture {
    char dir[64];
    char path[128];
    thz_scene *scene;
    photon_map *maps[2];
    photon_stats stats[2];
} fixture;

static thz_scene *two_channel_scene(void)
{
    thz_scene *s = ps_box_scene(ps_scaled(20000), 5, 0.2);
    ps_add_channel(s, 0.65, 0.05);
    return s;
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    strcpy(f->dir, "/tmp/thz-pmf-XXXXXX");
    if (!mkdtemp(f->dir))
        return -1;
    snprintf(f->path, sizeof f->path, "%s/photon-map.thzpm", f->dir);
    f->scene = two_channel_scene();
    accel *acc;
    thz_error err;
    if (accel_create(f->scene, &acc, &err) != THZ_OK)
        return -1;
    for (size_t c = 0; c < 2; c++) {
        photon_phase_options po = {.reference_temperature_k = c == 1 ? 290.0 : 0.0};
        if (photon_phase_run(f->scene, acc, c, &po, &f->maps[c], &f->stats[c], &err) != THZ_OK)
            return -1;
    }
    accel_destroy(acc);
    if (photon_map_file_write(f->path, f->scene, (const photon_map *const *)f->maps, f->stats, 1,
                              &err) != THZ_OK)
        return -1;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    for (size_t c = 0; c < 2; c++)
        photon_map_destroy(f->maps[c]);
    scene_destroy(f->scene);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    if (system(cmd) != 0)
        return -1;
    free(f);
    return 0;
}

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    long size = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)size + 1);
    assert_int_equal(fread(buf, 1, (size_t)size, fp), (size_t)size);
    fclose(fp);
    *n = (size_t)size;
    return buf;
}

static void spit(const char *path, const unsigned char *buf, size_t n)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(buf, 1, n, fp), n);
    fclose(fp);
}

/* src compressed into dst as one zstd frame with a checksum and its content size, as the
 * writer makes them; returns its size. */
static size_t compress_frame(unsigned char *dst, size_t cap, const void *src, size_t n)
{
    ZSTD_CCtx *cctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
    size_t r = ZSTD_compress2(cctx, dst, cap, src, n);
    assert_false(ZSTD_isError(r));
    ZSTD_freeCCtx(cctx);
    return r;
}

/* The prefix of a file of `total` bytes: its size, and its version unless 0. */
static void set_prefix(unsigned char *out, unsigned version, size_t total)
{
    if (version)
        out[8] = (unsigned char)version;
    for (int i = 0; i < 8; i++)
        out[16 + i] = (unsigned char)((uint64_t)total >> (8 * i));
}

static void test_round_trip(void **state)
{
    fixture *f = *state;
    photon_map *maps[2] = {NULL, NULL};
    photon_stats stats[2];
    photon_map_file_info info;
    thz_error err;
    assert_int_equal(photon_map_file_read(f->path, f->scene, 2, maps, stats, &info, &err), THZ_OK);
    assert_int_equal(info.n_channels, 2);
    assert_int_equal(info.seed, 5);
    assert_int_equal(info.photons_per_channel, f->scene->photons.per_channel);
    for (size_t c = 0; c < 2; c++) {
        assert_int_equal(photon_map_count(maps[c]), photon_map_count(f->maps[c]));
        /* The map's layout is a function of its records alone, so equal records give
         * equal arrays. */
        assert_memory_equal(photon_map_records(maps[c]), photon_map_records(f->maps[c]),
                            photon_map_count(maps[c]) * sizeof(photon_record));
        photon_stats a = f->stats[c];
        /* Timings and the ray count (benchmark only) are not in the file. */
        a.seconds = a.seconds_emission_table = a.seconds_tracing = a.seconds_index = 0.0;
        a.rays = 0;
        assert_memory_equal(&a, &stats[c], sizeof a);
        assert_true(photon_map_reference_temperature_k(maps[c]) ==
                    photon_map_reference_temperature_k(f->maps[c]));
        assert_true(stats[c].reference_temperature_k == (c == 1 ? 290.0 : 0.0));
    }
    assert_true(photon_map_reference_temperature_k(maps[1]) == 290.0);
    assert_true(photon_map_count(maps[0]) != photon_map_count(maps[1]));

    char again[160];
    snprintf(again, sizeof again, "%s/again.thzpm", f->dir);
    assert_int_equal(
        photon_map_file_write(again, f->scene, (const photon_map *const *)maps, stats, 3, &err),
        THZ_OK);
    size_t n1, n2;
    unsigned char *b1 = slurp(f->path, &n1), *b2 = slurp(again, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(b1, b2, n1);
    /* Compressed: well under 32 bytes per photon. */
    size_t records = photon_map_count(maps[0]) + photon_map_count(maps[1]);
    printf("# %zu photons in %zu bytes (%.1f bytes per photon)\n", records, n1,
           (double)n1 / (double)records);
    free(b1);
    free(b2);
    for (size_t c = 0; c < 2; c++)
        photon_map_destroy(maps[c]);
}

static void expect_refusal(const char *path, const thz_scene *scene, thz_status status,
                           const char *what);

/* The file at f->path with its header frame replaced by `header` (hsize bytes), and its
 * version by `version` unless 0, as `out_path`. */
static void spit_with_header(const fixture *f, const char *out_path, const unsigned char *header,
                             size_t hsize, unsigned version)
{
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    size_t h1 = ZSTD_findFrameCompressedSize(buf + 24, n - 24);
    assert_false(ZSTD_isError(h1));
    size_t cap = ZSTD_compressBound(hsize);
    unsigned char *out = malloc(24 + cap + (n - 24 - h1));
    size_t h0 = compress_frame(out + 24, cap, header, hsize);
    memcpy(out, buf, 24);
    memcpy(out + 24 + h0, buf + 24 + h1, n - 24 - h1);
    size_t total = 24 + h0 + (n - 24 - h1);
    set_prefix(out, version, total);
    spit(out_path, out, total);
    free(buf);
    free(out);
}

/* The records are compressed by zstd workers (photon_map_file.h): a map of several of
 * zstd's jobs (20 MB of records) gives the same file written by 1, 2 or 5 of them, and
 * reads back. */
static void test_workers(void **state)
{
    fixture *f = *state;
    thz_scene *scene = ps_box_scene(1000, 5, 0.2);
    const size_t n = 640000, groups = 2 * scene->n_objects;
    photon_record *r = malloc(n * sizeof *r);
    assert_non_null(r);
    uint64_t x = 12345;
    for (size_t i = 0; i < n; i++) {
        uint32_t u[6];
        for (int k = 0; k < 6; k++) {
            x = x * 6364136223846793005u + 1442695040888963407u;
            u[k] = (uint32_t)(x >> 32);
        }
        r[i] = (photon_record){
            .position_m = {(float)u[0] * 0x1p-32f, (float)u[1] * 0x1p-32f, (float)u[2] * 0x1p-32f},
            .power_w_per_hz = (float)u[3] * 0x1p-70f,
            .freq_hz = 3.5e11f,
            .dir_oct = u[4],
            .tag = photon_tag((uint32_t)(u[5] % groups) >> 1, (int)(u[5] % groups & 1u), 0,
                              (unsigned)(i % PHOTON_MAP_BATCHES))};
    }
    photon_map *map;
    thz_error err;
    assert_int_equal(photon_map_create(r, n, scene->n_objects, 0, &map, &err), THZ_OK);
    const int workers[3] = {1, 2, 5};
    unsigned char *first = NULL;
    size_t first_n = 0;
    for (int k = 0; k < 3; k++) {
        char path[160];
        snprintf(path, sizeof path, "%s/workers-%d.thzpm", f->dir, workers[k]);
        assert_int_equal(photon_map_file_write(path, scene, (const photon_map *const *)&map, NULL,
                                               workers[k], &err),
                         THZ_OK);
        size_t m;
        unsigned char *b = slurp(path, &m);
        assert_true(m > (size_t)8 << 20); /* several jobs of a few MB */
        if (!first) {
            first = b;
            first_n = m;
            photon_map *back = NULL;
            assert_int_equal(photon_map_file_read(path, scene, 0, &back, NULL, NULL, &err), THZ_OK);
            assert_int_equal(photon_map_count(back), n);
            assert_memory_equal(photon_map_records(back), photon_map_records(map),
                                n * sizeof(photon_record));
            photon_map_destroy(back);
        } else {
            assert_int_equal(m, first_n);
            assert_memory_equal(b, first, m);
            free(b);
        }
        unlink(path);
    }
    free(first);
    photon_map_destroy(map);
    scene_destroy(scene);
}

/* One channel read alone (what a view of its photons needs): its map equals the full
 * read's, the other holds none, every channel's statistics are read; a damaged byte in
 * the skipped channel's records is still found (they are read, not jumped over). */
static void test_one_channel(void **state)
{
    fixture *f = *state;
    thz_error err;
    for (size_t want = 0; want < 2; want++) {
        photon_map *maps[2] = {NULL, NULL};
        photon_stats stats[2];
        assert_int_equal(
            photon_map_file_read_channel(f->path, f->scene, 1, want, maps, stats, NULL, &err),
            THZ_OK);
        for (size_t c = 0; c < 2; c++) {
            photon_stats a = f->stats[c];
            a.seconds = a.seconds_emission_table = a.seconds_tracing = a.seconds_index = 0.0;
            a.rays = 0;
            assert_memory_equal(&a, &stats[c], sizeof a);
        }
        assert_null(maps[1 - want]);
        assert_non_null(maps[want]);
        assert_int_equal(photon_map_count(maps[want]), photon_map_count(f->maps[want]));
        assert_memory_equal(photon_map_records(maps[want]), photon_map_records(f->maps[want]),
                            photon_map_count(maps[want]) * sizeof(photon_record));
        assert_true(photon_map_reference_temperature_k(maps[want]) ==
                    photon_map_reference_temperature_k(f->maps[want]));
        photon_map_destroy(maps[want]);
    }
    photon_map *maps[2] = {NULL, NULL};
    assert_int_equal(photon_map_file_read_channel(f->path, f->scene, 1, 2, maps, NULL, NULL, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "no channel 2"));
    /* the file is compressed: flip a byte near the end, in channel 1's records, and read
     * channel 0 alone */
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    buf[n - 16] ^= 0x40;
    char bad[160];
    snprintf(bad, sizeof bad, "%s/bad.thzpm", f->dir);
    spit(bad, buf, n);
    free(buf);
    assert_int_not_equal(photon_map_file_read_channel(bad, f->scene, 1, 0, maps, NULL, NULL, &err),
                         THZ_OK);
    assert_null(maps[0]);
    assert_null(maps[1]);
}

/* Compares two version-3 record images: by object << 1 | side, then bytes (version 2's
 * order). */
static int image_cmp(const void *a, const void *b)
{
    uint32_t x, y;
    memcpy(&x, (const unsigned char *)a + 24, 4);
    memcpy(&y, (const unsigned char *)b + 24, 4);
    if (x != y)
        return x < y ? -1 : 1;
    return memcmp(a, b, 32);
}

/* A file of version 1, 2 or 3 made from f's: the header frame `header` (hsize bytes) and
 * the maps' records as those versions' 32-byte images (after the first 24 bytes, u32
 * object << 1 | side and u32 the bounce count, here 0 at a first hit and 1 after, | the
 * batch << 24 but in version 1), each channel's in its map's order or, by_bytes, by
 * group and then bytes. The record `forge` (SIZE_MAX: none) names object 2^30. */
static void spit_old_version(const fixture *f, const char *out_path, const unsigned char *header,
                             size_t hsize, unsigned version, bool by_bytes, size_t forge)
{
    size_t counts[2] = {photon_map_count(f->maps[0]), photon_map_count(f->maps[1])};
    size_t n = counts[0] + counts[1], isize = 32 * n;
    unsigned char *img = malloc(isize);
    assert_non_null(img);
    for (size_t c = 0, at = 0; c < 2; at += counts[c], c++) {
        const photon_record *r = photon_map_records(f->maps[c]);
        for (size_t i = 0; i < counts[c]; i++) {
            unsigned char *b = img + 32 * (at + i);
            memcpy(b, &r[i], 24);
            uint32_t object_side = photon_group(&r[i]);
            uint32_t flags = (photon_first_hit(&r[i]) ? 0u : 1u) |
                             (version == 1 ? 0u : photon_batch(&r[i]) << 24);
            if (at + i == forge)
                object_side = 1u << 31;
            memcpy(b + 24, &object_side, 4);
            memcpy(b + 28, &flags, 4);
        }
        if (by_bytes)
            qsort(img + 32 * at, counts[c], 32, image_cmp);
    }
    size_t hcap = ZSTD_compressBound(hsize), rcap = ZSTD_compressBound(isize);
    unsigned char *out = malloc(24 + hcap + rcap);
    assert_non_null(out);
    size_t h0 = compress_frame(out + 24, hcap, header, hsize);
    size_t total = 24 + h0 + compress_frame(out + 24 + h0, rcap, img, isize);
    memcpy(out, "THZPMAP\x1a", 8);
    memset(out + 8, 0, 16);
    set_prefix(out, version, total);
    spit(out_path, out, total);
    free(img);
    free(out);
}

/* f's file's header frame (*hsize bytes, malloc'd). */
static unsigned char *header_of(const fixture *f, size_t *hsize)
{
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    size_t h1 = ZSTD_findFrameCompressedSize(buf + 24, n - 24);
    assert_false(ZSTD_isError(h1));
    unsigned long long size = ZSTD_getFrameContentSize(buf + 24, h1);
    unsigned char *header = malloc(size);
    assert_int_equal(ZSTD_decompress(header, size, buf + 24, h1), size);
    free(buf);
    *hsize = size;
    return header;
}

/* The records of a and b equal, the batches aside (version 1 has none). */
static void assert_same_but_batches(const photon_map *a, const photon_map *b)
{
    size_t n = photon_map_count(a);
    assert_int_equal(photon_map_count(b), n);
    const photon_record *x = photon_map_records(a), *y = photon_map_records(b);
    for (size_t i = 0; i < n; i++) {
        photon_record p = x[i], q = y[i];
        p.tag &= ~(PHOTON_MAP_BATCHES - 1u);
        q.tag &= ~(PHOTON_MAP_BATCHES - 1u);
        assert_memory_equal(&p, &q, sizeof p);
    }
}

/* A version-1 file (20 words per channel, no T0, no batches) reads into the maps without
 * their batches, T0 = 0. */
static void test_version_1(void **state)
{
    fixture *f = *state;
    size_t hsize;
    unsigned char *header = header_of(f, &hsize);
    const size_t fixed = 7, words = 21, nc = 2;
    assert_int_equal(hsize, 8 * (fixed + words * nc));
    unsigned char *old = malloc(hsize);
    memcpy(old, header, 8 * fixed);
    for (size_t c = 0; c < nc; c++)
        memcpy(old + 8 * (fixed + 20 * c), header + 8 * (fixed + words * c), 8 * 20);
    size_t old_size = 8 * (fixed + 20 * nc);
    char v1[160];
    snprintf(v1, sizeof v1, "%s/v1.thzpm", f->dir);
    spit_old_version(f, v1, old, old_size, 1, true, SIZE_MAX);

    photon_map *maps[2] = {NULL, NULL};
    photon_stats stats[2];
    thz_error err;
    assert_int_equal(photon_map_file_read(v1, f->scene, 1, maps, stats, NULL, &err), THZ_OK);
    for (size_t c = 0; c < 2; c++) {
        assert_same_but_batches(maps[c], f->maps[c]);
        assert_int_equal(photon_map_batches(maps[c]), 1);
        assert_true(photon_map_reference_temperature_k(maps[c]) == 0.0);
        assert_true(stats[c].reference_temperature_k == 0.0);
        assert_true(stats[c].fired_power_w_per_hz == f->stats[c].fired_power_w_per_hz);
        photon_map_destroy(maps[c]);
    }
    /* Another version number is refused. */
    spit_with_header(f, v1, old, old_size, 9);
    expect_refusal(v1, f->scene, THZ_ERR_INPUT, "format version 9");
    free(header);
    free(old);
}

/* Version 4 stores each channel's records as its map holds them (so a reader's build moves
 * nothing); files of version 3 (32-byte records in their maps' order) and 2 (by group and
 * then bytes) read into the same maps byte for byte, the bounce count's zero as the
 * first-hit bit, and one naming an object past any map's is refused. */
static void test_versions_2_and_3(void **state)
{
    fixture *f = *state;
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    assert_int_equal(buf[8], 4);
    size_t h1 = ZSTD_findFrameCompressedSize(buf + 24, n - 24);
    assert_false(ZSTD_isError(h1));
    const unsigned char *frame = buf + 24 + h1;
    size_t fsize = n - 24 - h1;
    unsigned long long rsize = ZSTD_getFrameContentSize(frame, fsize);
    size_t counts[2] = {photon_map_count(f->maps[0]), photon_map_count(f->maps[1])};
    assert_int_equal(rsize, (counts[0] + counts[1]) * sizeof(photon_record));
    photon_record *rec = malloc(rsize);
    assert_int_equal(ZSTD_decompress(rec, rsize, frame, fsize), rsize);
    assert_memory_equal(rec, photon_map_records(f->maps[0]), counts[0] * sizeof *rec);
    assert_memory_equal(rec + counts[0], photon_map_records(f->maps[1]), counts[1] * sizeof *rec);
    free(buf);
    free(rec);

    size_t hsize;
    unsigned char *header = header_of(f, &hsize);
    for (unsigned version = 2; version <= 3; version++) {
        char path[160];
        snprintf(path, sizeof path, "%s/v%u.thzpm", f->dir, version);
        spit_old_version(f, path, header, hsize, version, version == 2, SIZE_MAX);
        for (int threads = 1; threads <= 2; threads++) {
            photon_map *maps[2] = {NULL, NULL};
            thz_error err;
            assert_int_equal(photon_map_file_read(path, f->scene, threads, maps, NULL, NULL, &err),
                             THZ_OK);
            for (size_t c = 0; c < 2; c++) {
                assert_int_equal(photon_map_count(maps[c]), counts[c]);
                assert_int_equal(photon_map_batches(maps[c]), PHOTON_MAP_BATCHES);
                assert_memory_equal(photon_map_records(maps[c]), photon_map_records(f->maps[c]),
                                    counts[c] * sizeof(photon_record));
                photon_map_destroy(maps[c]);
            }
        }
        spit_old_version(f, path, header, hsize, version, version == 2, counts[0] + 7);
        expect_refusal(path, f->scene, THZ_ERR_INPUT, "names an object");
    }
    free(header);
}

/* Reads `path` expecting failure with `status` and a message holding `what` and path. */
static void expect_refusal(const char *path, const thz_scene *scene, thz_status status,
                           const char *what)
{
    photon_map *maps[2] = {(photon_map *)1, (photon_map *)1};
    thz_error err;
    thz_status st = photon_map_file_read(path, scene, 1, maps, NULL, NULL, &err);
    printf("# %s\n", st == THZ_OK ? "(accepted)" : err.message);
    assert_int_equal(st, status);
    assert_non_null(strstr(err.message, what));
    assert_non_null(strstr(err.message, path));
    for (size_t c = 0; c < scene->n_channels; c++)
        assert_null(maps[c]);
}

static void test_corrupted(void **state)
{
    fixture *f = *state;
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    char bad[160];
    snprintf(bad, sizeof bad, "%s/bad.thzpm", f->dir);
    /* One flipped bit anywhere in the compressed sections: the header frame, the start,
     * middle and end of the records frame (the last bytes are its checksum). */
    const size_t where[] = {30, 60, n / 3, n / 2, n - 40, n - 2};
    for (size_t i = 0; i < sizeof where / sizeof where[0]; i++) {
        buf[where[i]] ^= 0x10;
        spit(bad, buf, n);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "corrupted");
        buf[where[i]] ^= 0x10;
    }
    /* Unknown flags in the prefix (bytes 12-15; none is defined): refused, each bit. */
    for (int bit = 0; bit < 32; bit += 7) {
        buf[12 + bit / 8] ^= (unsigned char)(1u << (bit % 8));
        spit(bad, buf, n);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "unknown flags");
        buf[12 + bit / 8] ^= (unsigned char)(1u << (bit % 8));
    }
    spit(bad, buf, n); /* and the restored bytes read */
    photon_map *ok[2] = {NULL, NULL};
    assert_int_equal(photon_map_file_read(bad, f->scene, 1, ok, NULL, NULL, NULL), THZ_OK);
    photon_map_destroy(ok[0]);
    photon_map_destroy(ok[1]);
    /* A device or a directory: refused before opening (a FIFO would block the open). */
    expect_refusal("/dev/zero", f->scene, THZ_ERR_INPUT, "is a character device");
    expect_refusal(f->dir, f->scene, THZ_ERR_INPUT, "is a directory");
    /* A damaged magic number: not a photon map at all. */
    buf[2] ^= 0x01;
    spit(bad, buf, n);
    expect_refusal(bad, f->scene, THZ_ERR_INPUT, "not a thzmap photon map");
    free(buf);
}

/* A header (with a valid checksum) whose record count is a lie is refused before the
 * records are allocated: a huge count (2^40 records, 32 TB) and one too many. */
static void test_forged_count(void **state)
{
    fixture *f = *state;
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    size_t h1 = ZSTD_findFrameCompressedSize(buf + 24, n - 24);
    unsigned long long hsize = ZSTD_getFrameContentSize(buf + 24, h1);
    unsigned char *header = malloc(hsize);
    assert_int_equal(ZSTD_decompress(header, hsize, buf + 24, h1), hsize);
    char bad[160];
    snprintf(bad, sizeof bad, "%s/forged.thzpm", f->dir);
    unsigned char *count = header + 8 * 7 + 16; /* channel 0's record count */
    uint64_t real = 0;
    for (int i = 0; i < 8; i++)
        real |= (uint64_t)count[i] << (8 * i);
    const uint64_t lies[] = {(uint64_t)1 << 40, real + 1};
    for (size_t k = 0; k < 2; k++) {
        for (int i = 0; i < 8; i++)
            count[i] = (unsigned char)(lies[k] >> (8 * i));
        spit_with_header(f, bad, header, hsize, 0);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "bytes of photons");
    }
    free(buf);
    free(header);
}

/* Values no run writes, under valid checksums: a reference temperature of 1e300 K, a
 * photon count of 0 or 2^64 - 1, a photon whose power or position is not a number.
 * Each is refused (render wrote Inf and NaN images from them, with exit status 0). */
static void test_forged_values(void **state)
{
    fixture *f = *state;
    size_t hsize;
    unsigned char *header = header_of(f, &hsize);
    char bad[160];
    snprintf(bad, sizeof bad, "%s/forged-values.thzpm", f->dir);
    unsigned char saved[8];
    unsigned char *t0 = header + 8 * 7 + 160; /* channel 0's T0 */
    memcpy(saved, t0, 8);
    const double hot = 1e300;
    memcpy(t0, &hot, 8);
    spit_with_header(f, bad, header, hsize, 0);
    expect_refusal(bad, f->scene, THZ_ERR_INPUT, "impossible reference temperature");
    memcpy(t0, saved, 8);
    unsigned char *count = header + 48; /* photons per channel */
    const uint64_t counts[2] = {0, UINT64_MAX};
    for (size_t k = 0; k < 2; k++) {
        for (int i = 0; i < 8; i++)
            count[i] = (unsigned char)(counts[k] >> (8 * i));
        spit_with_header(f, bad, header, hsize, 0);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "impossible photon count");
    }
    free(header);

    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    size_t h1 = ZSTD_findFrameCompressedSize(buf + 24, n - 24);
    const unsigned char *frame = buf + 24 + h1;
    size_t fsize = n - 24 - h1;
    unsigned long long rsize = ZSTD_getFrameContentSize(frame, fsize);
    photon_record *rec = malloc(rsize);
    assert_int_equal(ZSTD_decompress(rec, rsize, frame, fsize), rsize);
    size_t rcap = ZSTD_compressBound(rsize);
    unsigned char *out = malloc(24 + h1 + rcap);
    for (int what = 0; what < 3; what++) {
        photon_record keep = rec[5];
        if (what == 0)
            rec[5].power_w_per_hz = NAN;
        else if (what == 1)
            rec[5].position_m[2] = INFINITY;
        else
            rec[5].freq_hz = -1.0f;
        memcpy(out, buf, 24 + h1);
        size_t total = 24 + h1 + compress_frame(out + 24 + h1, rcap, rec, rsize);
        set_prefix(out, 0, total);
        spit(bad, out, total);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "position, power or frequency");
        rec[5] = keep;
    }
    free(out);
    free(rec);
    free(buf);
}

static void test_truncated(void **state)
{
    fixture *f = *state;
    size_t n;
    unsigned char *buf = slurp(f->path, &n);
    char bad[160];
    snprintf(bad, sizeof bad, "%s/short.thzpm", f->dir);
    const size_t lengths[] = {n - 1, n / 2, 100, 20, 0};
    for (size_t i = 0; i < sizeof lengths / sizeof lengths[0]; i++) {
        spit(bad, buf, lengths[i]);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, "truncated");
    }
    free(buf);
    char missing[160];
    snprintf(missing, sizeof missing, "%s/missing.thzpm", f->dir);
    expect_refusal(missing, f->scene, THZ_ERR_INPUT, "cannot open");
}

static void test_mismatched_scene(void **state)
{
    fixture *f = *state;
    /* Another geometry: the cube moved by 1 mm. */
    thz_scene *s = two_channel_scene();
    s->objects[1].mesh.positions[0] += 0.001f;
    expect_refusal(f->path, s, THZ_ERR_INPUT, "another scene geometry");
    scene_destroy(s);
    /* Another channel set: one channel less, or one moved. */
    s = two_channel_scene();
    s->n_channels = 1;
    expect_refusal(f->path, s, THZ_ERR_INPUT, "another channel set");
    s->n_channels = 2;
    s->channels[1].center_hz *= 1.01;
    expect_refusal(f->path, s, THZ_ERR_INPUT, "another channel set");
    scene_destroy(s);
    /* Another temperature. */
    s = two_channel_scene();
    s->objects[2].temperature_k += 1.0;
    expect_refusal(f->path, s, THZ_ERR_INPUT, "temperatures");
    scene_destroy(s);
    /* Seed and photon count are not part of the match: a map fired with --photons N
     * renders any time. */
    s = two_channel_scene();
    s->photons.seed = 99;
    s->photons.per_channel = 5;
    photon_map *maps[2];
    thz_error err;
    assert_int_equal(photon_map_file_read(f->path, s, 1, maps, NULL, NULL, &err), THZ_OK);
    photon_map_destroy(maps[0]);
    photon_map_destroy(maps[1]);
    scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_one_channel, setup, teardown),
        cmocka_unit_test_setup_teardown(test_workers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_version_1, setup, teardown),
        cmocka_unit_test_setup_teardown(test_versions_2_and_3, setup, teardown),
        cmocka_unit_test_setup_teardown(test_corrupted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_forged_values, setup, teardown),
        cmocka_unit_test_setup_teardown(test_truncated, setup, teardown),
        cmocka_unit_test_setup_teardown(test_forged_count, setup, teardown),
        cmocka_unit_test_setup_teardown(test_mismatched_scene, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
