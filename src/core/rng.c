/* Counter-based random numbers from Random123's Philox4x32-10. */
#include "core/rng.h"

#include <Random123/philox.h>

void rng_refill(rng_stream *rng)
{
    philox4x32_ctr_t c = {{rng->ctr[0], rng->ctr[1], rng->ctr[2], rng->ctr[3]}};
    philox4x32_key_t k = {{rng->key[0], rng->key[1]}};
    philox4x32_ctr_t r = philox4x32(c, k);
    for (int i = 0; i < 4; i++)
        rng->buf[i] = r.v[i];
    rng->used = 0;
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
    rng->used = 4;
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
