/* Binary little-endian PLY of stored photons: see ply.h. */
#include "io/ply.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define PLY_VERTEX_BYTES 39u /* 3 floats, 3 uchars, uint, float, int, 3 floats: packed */

static uint8_t ply_channel(double d)
{
    double v = floor(255.0 * 0.5 * (1.0 - d) + 0.5);
    return (uint8_t)(v < 0.0 ? 0.0 : (v > 255.0 ? 255.0 : v));
}

static void ply_put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void ply_put_f32(uint8_t *p, float x)
{
    uint32_t v;
    memcpy(&v, &x, sizeof v);
    ply_put_u32(p, v);
}

thz_status ply_write_photons(const char *path, const photon_map *const *maps, size_t n_maps,
                             uint64_t max_points, thz_error *err)
{
    uint64_t total = 0;
    for (size_t m = 0; m < n_maps; m++)
        if (maps[m])
            total += photon_map_count(maps[m]);
    /* The cap is at most 2^32 so that the stride arithmetic below cannot overflow. */
    if (max_points > UINT32_MAX)
        max_points = UINT32_MAX;
    uint64_t n_out = (max_points && total > max_points) ? max_points : total;

    FILE *f = fopen(path, "wb");
    if (!f)
        return thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO), "cannot create %s: %s", path,
                             strerror(errno));
    thz_status st = THZ_OK;
    if (fprintf(
            f,
            "ply\nformat binary_little_endian 1.0\n"
            "comment thzmap photon map: one vertex per stored photon\n"
            "comment x y z: hit point (m); dx dy dz: unit direction of travel as it arrived\n"
            "comment red green blue: 255 * 0.5 * (1 - d), the direction it came from\n"
            "comment channel, object: indices into the scene's channels and objects\n"
            "comment power_w_per_hz: spectral power carried (W/Hz, negative in deviation maps)\n"
            "comment %llu of %llu photons\n"
            "element vertex %llu\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "property uint channel\nproperty float power_w_per_hz\nproperty int object\n"
            "property float dx\nproperty float dy\nproperty float dz\n"
            "end_header\n",
            (unsigned long long)n_out, (unsigned long long)total, (unsigned long long)n_out) < 0)
        goto write_error;

    enum { PLY_BUF_POINTS = 4096 };
    uint8_t buf[PLY_BUF_POINTS * PLY_VERTEX_BYTES];
    size_t used = 0;
    size_t m = 0;
    uint64_t base = 0; /* index of maps[m]'s first photon in the concatenation */
    for (uint64_t i = 0; i < n_out; i++) {
        /* floor(i * total / n_out), exact: i (total % n_out) < n_out^2 <= 2^64. */
        uint64_t k = i * (total / n_out) + i * (total % n_out) / n_out;
        while (!maps[m] || k >= base + photon_map_count(maps[m])) {
            if (maps[m])
                base += photon_map_count(maps[m]);
            m++;
        }
        const photon_record *p = &photon_map_records(maps[m])[k - base];
        vec3 d = photon_decode_direction(p->dir_oct);
        uint8_t *q = buf + used * PLY_VERTEX_BYTES;
        for (int c = 0; c < 3; c++)
            ply_put_f32(q + 4 * c, p->position_m[c]);
        q[12] = ply_channel(d.x);
        q[13] = ply_channel(d.y);
        q[14] = ply_channel(d.z);
        ply_put_u32(q + 15, (uint32_t)m);
        ply_put_f32(q + 19, p->power_w_per_hz);
        ply_put_u32(q + 23, photon_object(p)); /* < 2^31: a non-negative int */
        ply_put_f32(q + 27, (float)d.x);
        ply_put_f32(q + 31, (float)d.y);
        ply_put_f32(q + 35, (float)d.z);
        if (++used == PLY_BUF_POINTS) {
            if (fwrite(buf, PLY_VERTEX_BYTES, used, f) != used)
                goto write_error;
            used = 0;
        }
    }
    if (used && fwrite(buf, PLY_VERTEX_BYTES, used, f) != used)
        goto write_error;
    if (fclose(f) != 0) {
        f = NULL;
        goto write_error;
    }
    return THZ_OK;

write_error:
    st = thz_error_set(err, THZ_ERR_IO, "cannot write %s: %s", path, strerror(errno));
    if (f)
        fclose(f);
    return st;
}
