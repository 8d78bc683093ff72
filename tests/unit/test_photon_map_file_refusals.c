/* photon-map.thzpm files refused, with messages that name the file and say what is
 * wrong: corrupted (one byte flipped), truncated, forged (a record count the file cannot
 * hold, refused before allocating; values no run writes), foreign and mismatched (another
 * geometry, channel set or temperatures). test_photon_map_file.c: the files read. */
#include "photon_map_file_helpers.h"

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
    /* Format versions this thzmap does not know: 0 (none was written) and the next one
     * (a later thzmap's layout, which this one would misread as its own). */
    const unsigned char versions[] = {0, PHOTON_MAP_FILE_VERSION + 1u};
    for (size_t i = 0; i < 2; i++) {
        char want[64];
        snprintf(want, sizeof want, "has format version %u;", versions[i]);
        unsigned char keep = buf[8];
        buf[8] = versions[i];
        spit(bad, buf, n);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT, want);
        buf[8] = keep;
    }
    /* Bytes after the records frame: longer than the prefix says, or (the size in the
     * prefix made to match) data after the end. */
    unsigned char *longer = malloc(n + 16);
    assert_non_null(longer);
    memcpy(longer, buf, n);
    memset(longer + n, 0, 16);
    spit(bad, longer, n + 16);
    expect_refusal(bad, f->scene, THZ_ERR_INPUT, "where its header says");
    set_prefix(longer, 0, n + 16);
    spit(bad, longer, n + 16);
    expect_refusal(bad, f->scene, THZ_ERR_INPUT, "data after the end");
    free(longer);
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
    size_t hsize;
    unsigned char *header = header_of(f, &hsize);
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
    /* a frequency of 0 and an object index one past the scene's last (their bounds taken
     * as <= 0 and > n_objects, mutants, passed every other test) */
    for (int what = 0; what < 5; what++) {
        photon_record keep = rec[5];
        if (what == 0)
            rec[5].power_w_per_hz = NAN;
        else if (what == 1)
            rec[5].position_m[2] = INFINITY;
        else if (what == 2)
            rec[5].freq_hz = -1.0f;
        else if (what == 3)
            rec[5].freq_hz = 0.0f;
        else
            rec[5].tag = photon_tag((uint32_t)f->scene->n_objects, photon_side(&rec[5]),
                                    photon_first_hit(&rec[5]), photon_batch(&rec[5]));
        memcpy(out, buf, 24 + h1);
        size_t total = 24 + h1 + compress_frame(out + 24 + h1, rcap, rec, rsize);
        set_prefix(out, 0, total);
        spit(bad, out, total);
        expect_refusal(bad, f->scene, THZ_ERR_INPUT,
                       what < 4 ? "position, power or frequency"
                                : "an object the scene does not have");
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
        cmocka_unit_test_setup_teardown(test_corrupted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_forged_values, setup, teardown),
        cmocka_unit_test_setup_teardown(test_truncated, setup, teardown),
        cmocka_unit_test_setup_teardown(test_forged_count, setup, teardown),
        cmocka_unit_test_setup_teardown(test_mismatched_scene, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
