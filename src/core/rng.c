/* Counter-based random numbers from Random123's Philox4x32-10. */
#include "core/rng.h"

#include <Random123/philox.h>
#include <string.h>

void rng_refill(rng_stream *rng)
{
    philox4x32_ctr_t c = {{rng->ctr[0], rng->ctr[1], rng->ctr[2], rng->ctr[3]}};
    philox4x32_key_t k = {{rng->key[0], rng->key[1]}};
    philox4x32_ctr_t r = philox4x32(c, k);
    for (int i = 0; i < 4; i++)
        rng->buf[i] = r.v[i];
    rng->used = 0;
    rng->avail = 4;
    /* The low counter word counts blocks within one unit of work: 2^32 blocks of 4
     * words is far more than any photon path uses. */
    rng->ctr[0]++;
}

void rng_init(rng_stream *rng, uint64_t seed, uint32_t channel, uint32_t purpose, uint64_t index)
{
    rng->key[0] = (uint32_t)seed;
    rng->key[1] = (uint32_t)(seed >> 32);
    rng->ctr[0] = 0;
    rng->ctr[1] = (channel << 4) | (purpose & 0xfu);
    rng->ctr[2] = (uint32_t)index;
    rng->ctr[3] = (uint32_t)(index >> 32);
    rng->used = rng->avail = 0;
}

void rng_init_many(rng_stream *rng, size_t n, uint64_t seed, uint32_t channel, uint32_t purpose,
                   uint64_t index, unsigned blocks)
{
    if (n > RNG_MANY)
        n = RNG_MANY;
    if (blocks > RNG_BUFFER_BLOCKS)
        blocks = RNG_BUFFER_BLOCKS;
    const philox4x32_key_t k = {{(uint32_t)seed, (uint32_t)(seed >> 32)}};
    const uint32_t ctr1 = (channel << 4) | (purpose & 0xfu);
    uint32_t out[RNG_MANY][4];
    for (unsigned b = 0; b < blocks; b++) {
        /* one block of every stream: independent, so vectorised across the streams */
        for (size_t j = 0; j < RNG_MANY; j++) {
            uint64_t i = index + j;
            philox4x32_ctr_t c = {{b, ctr1, (uint32_t)i, (uint32_t)(i >> 32)}};
            philox4x32_ctr_t r = philox4x32(c, k);
            for (int w = 0; w < 4; w++)
                out[j][w] = r.v[w];
        }
        for (size_t j = 0; j < n; j++)
            memcpy(&rng[j].buf[4 * b], out[j], sizeof out[j]);
    }
    for (size_t j = 0; j < n; j++) {
        rng_init(&rng[j], seed, channel, purpose, index + j);
        rng[j].ctr[0] = blocks;
        rng[j].avail = 4 * blocks;
    }
}

double rng_uniform(rng_stream *rng)
{
    uint64_t hi = rng_next_u32(rng) >> 5; /* 27 bits */
    uint64_t lo = rng_next_u32(rng) >> 6; /* 26 bits */
    return (double)(hi * 67108864u + lo) * (1.0 / 9007199254740992.0);
}

double rng_uniform_open0(rng_stream *rng)
{
    return 1.0 - rng_uniform(rng);
}
