/* Counter-based random numbers (Random123 Philox4x32-10).
 *
 * A stream is keyed by (seed, channel) and started at a counter given by the index of
 * the unit of work (photon, pixel sample, path), so every photon's or sample's numbers
 * are the same whichever thread computes it and in whatever order: results are
 * bit-identical for any thread count, and batches can be fired anywhere and merged.
 * `purpose` separates independent uses of the same index (emission vs rendering).
 */
#ifndef THZ_CORE_RNG_H
#define THZ_CORE_RNG_H

#include <stddef.h>
#include <stdint.h>

/* Words a stream holds ahead: up to 4 Philox blocks (rng_init_many fills them at once). */
#define RNG_BUFFER_BLOCKS 4u

typedef struct rng_stream {
    uint32_t key[2];
    uint32_t ctr[4]; /* ctr[0]: the next block to compute */
    uint32_t buf[4 * RNG_BUFFER_BLOCKS];
    unsigned used;  /* words of buf consumed */
    unsigned avail; /* words of buf filled */
} rng_stream;

/* Purposes: keep them distinct so that two uses never share numbers. */
enum {
    RNG_PURPOSE_PHOTON = 1,
    RNG_PURPOSE_RENDER = 2,
    RNG_PURPOSE_PATH = 3,
    RNG_PURPOSE_GATHER = 4,
    RNG_PURPOSE_AIR_VOLUME = 5,    /* photon/air_emission.c: the air's share of the extent */
    RNG_PURPOSE_BACK_FACE = 6,     /* photon/emission.c: back faces' reach shares */
    RNG_PURPOSE_SENSOR_NOISE = 7,  /* sensor/noise.c: radiometer noise, per pixel */
    RNG_PURPOSE_GATHER_STRATA = 8, /* sensor/integrators.c: strata of a pixel's samples */
    RNG_PURPOSE_ANALYSIS = 9,      /* analysis/: training splits, noise added to cubes */
    RNG_PURPOSE_TEST = 15
};

/* Starts the stream for unit `index` of `channel` under `seed` and `purpose`. */
void rng_init(rng_stream *rng, uint64_t seed, uint32_t channel, uint32_t purpose, uint64_t index);

/* Starts n <= RNG_MANY streams, rng[j] for unit index + j, as rng_init does, with their
 * first `blocks` (<= RNG_BUFFER_BLOCKS) Philox blocks already computed: the same words in
 * the same order as rng_init's streams give. The blocks of the n streams are computed
 * together, a loop the compiler vectorises over the streams (Random123's philox4x32 per
 * stream; 4 against 10-13 ns a block one at a time, AVX-512): the photon phase draws
 * about 3 blocks per photon. */
#define RNG_MANY 16u
void rng_init_many(rng_stream *rng, size_t n, uint64_t seed, uint32_t channel, uint32_t purpose,
                   uint64_t index, unsigned blocks);

/* The next Philox block into buf (an implementation detail of rng_next_u32). */
void rng_refill(rng_stream *rng);

/* Next 32 random bits (inline: the photon phase draws a dozen words per photon). */
static inline uint32_t rng_next_u32(rng_stream *rng)
{
    if (rng->used >= rng->avail)
        rng_refill(rng);
    return rng->buf[rng->used++];
}

/* Next 64 random bits: two words, the first the high half. */
static inline uint64_t rng_next_u64(rng_stream *rng)
{
    uint64_t hi = rng_next_u32(rng);
    return hi << 32 | rng_next_u32(rng);
}

/* Uniform double in [0, 1) with 53 random bits (two words). */
double rng_uniform(rng_stream *rng);

/* Uniform double in [0, 1) with 32 random bits (one word): a multiple of 2^-32, at most
 * 1 - 2^-32. The photon phase draws these (docs/physics.md "Random streams"): half the
 * Philox blocks of rng_uniform, and 2^-32 is far below any probability it resolves. */
static inline double rng_uniform32(rng_stream *rng)
{
    return (double)rng_next_u32(rng) * (1.0 / 4294967296.0);
}

/* Uniform double in (0, 1]: safe for log(). */
double rng_uniform_open0(rng_stream *rng);

#endif
