/* What the photon-map file's unit tests share (test_photon_map_file.c: what is written
 * reads back, of every version; test_photon_map_file_refusals.c: damaged, forged and
 * mismatched files refused): a fixture holding a two-channel scene, its maps (channel 1
 * a deviation map, T0 = 290 K) and their file in a temporary directory; reading and
 * writing whole files; re-compressing a file's header frame; expecting a refusal.
 * Header-only (static inline), as tests/physics/photon_scenes.h. */
#ifndef THZ_TESTS_PHOTON_MAP_FILE_HELPERS_H
#define THZ_TESTS_PHOTON_MAP_FILE_HELPERS_H

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

static inline thz_scene *two_channel_scene(void)
{
    thz_scene *s = ps_box_scene(ps_scaled(20000), 5, 0.2);
    ps_add_channel(s, 0.65, 0.05);
    return s;
}

static inline int setup(void **state)
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

static inline int teardown(void **state)
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

static inline unsigned char *slurp(const char *path, size_t *n)
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

static inline void spit(const char *path, const unsigned char *buf, size_t n)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(buf, 1, n, fp), n);
    fclose(fp);
}

/* src compressed into dst as one zstd frame with a checksum and its content size, as the
 * writer makes them; returns its size. */
static inline size_t compress_frame(unsigned char *dst, size_t cap, const void *src, size_t n)
{
    ZSTD_CCtx *cctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
    size_t r = ZSTD_compress2(cctx, dst, cap, src, n);
    assert_false(ZSTD_isError(r));
    ZSTD_freeCCtx(cctx);
    return r;
}

/* The prefix of a file of `total` bytes: its size, and its version unless 0. */
static inline void set_prefix(unsigned char *out, unsigned version, size_t total)
{
    if (version)
        out[8] = (unsigned char)version;
    for (int i = 0; i < 8; i++)
        out[16 + i] = (unsigned char)((uint64_t)total >> (8 * i));
}

/* Reads `path` expecting failure with `status` and a message holding `what` and path. */
static inline void expect_refusal(const char *path, const thz_scene *scene, thz_status status,
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

/* The file at f->path with its header frame replaced by `header` (hsize bytes), and its
 * version by `version` unless 0, as `out_path`. */
static inline void spit_with_header(const fixture *f, const char *out_path,
                                    const unsigned char *header, size_t hsize, unsigned version)
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

/* f's file's header frame (*hsize bytes, malloc'd). */
static inline unsigned char *header_of(const fixture *f, size_t *hsize)
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

#endif
