/* photon-map.ply: a valid binary little-endian PLY header, one 39-byte vertex per photon
 * (or per strided photon under a cap) read back against the photon maps: positions,
 * channel (the map's index), signed power, object and incoming direction as stored, and
 * colours round(255 * 0.5 * (1 - d)) of that direction. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

#include <cmocka.h>

#include "../physics/photon_scenes.h"
#include "io/ply.h"

/* Two maps built from hand-made records, in known directions. */
static photon_map *make_map(size_t n, uint32_t salt)
{
    photon_record *r = calloc(n, sizeof *r);
    for (size_t i = 0; i < n; i++) {
        double t = (double)(i + salt);
        r[i].position_m[0] = (float)(0.001 * t);
        r[i].position_m[1] = (float)(-0.002 * t);
        r[i].position_m[2] = (float)(1.0 + 0.0001 * t);
        r[i].power_w_per_hz = (float)((i % 2 ? -1.0 : 1.0) * 1e-20 * (1.0 + t)); /* signed */
        r[i].freq_hz = 3.5e11f;
        vec3 d = v3_normalize(v3(cos(t), sin(t), -0.5 - 0.4 * sin(3 * t)));
        r[i].dir_oct = photon_encode_direction(d);
        r[i].tag = photon_tag((uint32_t)(i % 3), (int)(i % 2), 0, 0);
    }
    photon_map *map;
    thz_error err;
    assert_int_equal(photon_map_create(r, n, 3, 1, &map, &err), THZ_OK);
    return map;
}

static size_t parse_header(const unsigned char *buf, size_t n, uint64_t *vertices)
{
    const char *end = strstr((const char *)buf, "end_header\n");
    assert_non_null(end);
    size_t len = (size_t)(end - (const char *)buf) + strlen("end_header\n");
    assert_true(len < n || *vertices == 0);
    char *h = strndup((const char *)buf, len);
    assert_int_equal(strncmp(h, "ply\nformat binary_little_endian 1.0\n", 36), 0);
    const char *ev = strstr(h, "element vertex ");
    assert_non_null(ev);
    *vertices = strtoull(ev + 15, NULL, 10);
    assert_non_null(strstr(h, "property float x\nproperty float y\nproperty float z\n"
                              "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                              "property uint channel\nproperty float power_w_per_hz\n"
                              "property int object\n"
                              "property float dx\nproperty float dy\nproperty float dz\n"
                              "end_header\n"));
    free(h);
    return len;
}

static void check_file(const char *path, const photon_map *const *maps, size_t n_maps, uint64_t cap)
{
    thz_error err;
    assert_int_equal(ply_write_photons(path, maps, n_maps, cap, &err), THZ_OK);
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    static unsigned char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = 0;
    uint64_t v = 0, total = 0;
    size_t off = parse_header(buf, n, &v);
    for (size_t m = 0; m < n_maps; m++)
        total += maps[m] ? photon_map_count(maps[m]) : 0;
    uint64_t expect = cap && total > cap ? cap : total;
    assert_int_equal(v, expect);
    assert_int_equal(n, off + 39 * v);
    for (uint64_t i = 0; i < v; i++) {
        uint64_t k = expect == total ? i : i * total / expect; /* the documented stride */
        size_t m = 0;
        while (!maps[m] || k >= photon_map_count(maps[m])) {
            if (maps[m])
                k -= photon_map_count(maps[m]);
            m++;
        }
        const photon_record *p = &photon_map_records(maps[m])[k];
        const unsigned char *q = buf + off + 39 * i;
        float xyz[3];
        memcpy(xyz, q, 12);
        for (int c = 0; c < 3; c++)
            assert_true(xyz[c] == p->position_m[c]);
        vec3 d = photon_decode_direction(p->dir_oct);
        double dd[3] = {d.x, d.y, d.z};
        for (int c = 0; c < 3; c++) {
            double want = 255.0 * 0.5 * (1.0 - dd[c]);
            assert_true(fabs((double)q[12 + c] - want) <= 0.5 + 1e-9);
        }
        uint32_t channel;
        int32_t object;
        float power, dir[3];
        memcpy(&channel, q + 15, 4); /* little-endian host, as the file */
        memcpy(&power, q + 19, 4);
        memcpy(&object, q + 23, 4);
        memcpy(dir, q + 27, 12);
        assert_int_equal(channel, m);
        assert_true(power == p->power_w_per_hz);
        assert_int_equal(object, (int32_t)photon_object(p));
        for (int c = 0; c < 3; c++)
            assert_true(dir[c] == (float)dd[c]);
    }
}

static void test_ply(void **state)
{
    (void)state;
    char dir[] = "/tmp/thz-ply-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/photon-map.ply", dir);
    photon_map *maps[3] = {make_map(1000, 0), NULL, make_map(777, 5000)};
    check_file(path, (const photon_map *const *)maps, 3, 0);    /* all 1777 */
    check_file(path, (const photon_map *const *)maps, 3, 5000); /* cap above: all */
    check_file(path, (const photon_map *const *)maps, 3, 500);  /* strided */
    check_file(path, (const photon_map *const *)maps, 3, 1);
    photon_map *empty[1] = {NULL};
    check_file(path, (const photon_map *const *)empty, 1, 10); /* no photons: header only */
    thz_error err;
    assert_int_equal(
        ply_write_photons("/nonexistent-dir/x.ply", (const photon_map *const *)maps, 3, 0, &err),
        THZ_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent-dir/x.ply"));
    photon_map_destroy(maps[0]);
    photon_map_destroy(maps[2]);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ply),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
