/* photon-map.thzpm: write + read gives the same maps, stats and reference temperatures
 * (channel 1 is a deviation map, T0 = 290 K), and read + write reproduces the file byte
 * for byte, whatever the number of compressing workers; one channel reads alone; the
 * records are stored in the map's order, and files of versions 3 (32-byte records) and 2
 * (those by group and bytes) read into the same maps; a version-1 file (no T0, no
 * batches) reads with T0 = 0. test_photon_map_file_refusals.c: the files refused. */
#include "photon_map_file_helpers.h"

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
    /* The header's channel words that no reader of thzmap uses, for other programs
     * (photon_map_file.h's layout): each channel's centre in Hz and relative width. */
    size_t hsize;
    unsigned char *header = header_of(f, &hsize);
    for (size_t c = 0; c < 2; c++) {
        double centre, width;
        memcpy(&centre, header + 8 * (7 + 21 * c), 8); /* little-endian hosts only */
        memcpy(&width, header + 8 * (7 + 21 * c) + 8, 8);
        assert_true(centre == f->scene->channels[c].center_hz);
        assert_true(width == f->scene->channels[c].relative_width);
    }
    free(header);

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_one_channel, setup, teardown),
        cmocka_unit_test_setup_teardown(test_workers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_version_1, setup, teardown),
        cmocka_unit_test_setup_teardown(test_versions_2_and_3, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
