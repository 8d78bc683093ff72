/* The photon-map file's layout constants and little-endian words, shared by its writer
 * (photon_map_file.c) and its reader (photon_map_file_read.c); photon_map_file.h gives
 * the layout. Internal to src/io/.
 */
#ifndef THZ_IO_PHOTON_MAP_FILE_FORMAT_H
#define THZ_IO_PHOTON_MAP_FILE_FORMAT_H

#include <stdint.h>
#include <string.h>

#include "photon/photon_map.h"
#include "photon/photon_stats.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the photon-map file holds records as in memory: little-endian hosts only"
#endif

#define PMF_PREFIX_BYTES 24u
#define PMF_HEADER_FIXED 7u      /* u64 words before the channels */
#define PMF_CHANNEL_WORDS 21u    /* centre, width, count, 10 counters, 7 reals, T0 */
#define PMF_CHANNEL_WORDS_V1 20u /* version 1 had no T0 (its maps have T0 = 0) */
/* zstd level 1: at 3 it took twice the time (the paper's case, one channel of 10 M photons:
 * 2.9 s against 1.5 s) for a file 1.2 % smaller */
#define PMF_LEVEL 1
/* Versions 1 to 3 held 32-byte records: photon_record's first 24 bytes, then u32 object
 * index << 1 | side, u32 the bounce count (low 16 bits) and the batch (bits 24-26). */
#define PMF_RECORD_BYTES_V3 32u
#define PMF_MAX_HEADER_BYTES (16u << 20)
#define PMF_MAX_T0_K 1e6                    /* a scene's temperatures end there */
#define PMF_MAX_PHOTONS ((uint64_t)1 << 53) /* photons.per_channel's bound */
#define PMF_FRAME_HEADER_MAX 18u            /* bytes: zstd's largest frame header */

/* The bytes of a record in a file of `version`. */
static inline size_t pmf_record_bytes(uint32_t version)
{
    return version >= 4u ? sizeof(photon_record) : PMF_RECORD_BYTES_V3;
}

/* ---- little-endian words ---------------------------------------------------- */

static inline void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static inline uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static inline uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline void put_f64(uint8_t *p, double x)
{
    uint64_t v;
    memcpy(&v, &x, sizeof v);
    put_u64(p, v);
}

static inline double get_f64(const uint8_t *p)
{
    uint64_t v = get_u64(p);
    double x;
    memcpy(&x, &v, sizeof x);
    return x;
}

/* The stats of one channel as 17 words (order fixed by version 1). */
static inline void pmf_put_stats(uint8_t *p, const photon_stats *s)
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

static inline void pmf_get_stats(const uint8_t *p, photon_stats *s)
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

#endif
