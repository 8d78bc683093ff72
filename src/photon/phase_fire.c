/* Firing photons [lo, hi) of a channel's phase (phase_fire.h): batch by batch, each
 * batch's chunks spread over OpenMP threads, each thread emitting its photons stage by
 * stage (vectorised) and tracing them into its own buffer, the chunks' records then
 * copied into the phase's array in chunk order. phase.c sets up the sources and calls it.
 */
#include "photon/phase_fire.h"

#include <math.h>
#include <stdbool.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/sampling.h"
#include "core/threads.h"
#include "photon/phase.h"
#include "physics/channel.h"

/* Philox blocks computed ahead for each photon (rng_init_many): it draws about 3. */
#define PHASE_RNG_BLOCKS 3u

/* Where one chunk's records landed: a range of its thread's buffer. */
typedef struct phase_chunk {
    int thread;
    size_t start, count;
    size_t offset; /* where the records go in the phase's array */
    trace_counters counters;
} phase_chunk;

/* Emits n <= RNG_MANY photons from their streams rng[j] (power 0 where nothing is emitted),
 * stage by stage over the photons: each one's class (surface, air or boundary: the last
 * two drawn whole), every surface photon's frequency, then each one's source, point and
 * angle, then all their directions. The frequencies and directions are loops the compiler
 * vectorises, which the same arithmetic one photon at a time left to the scalar units
 * (channel_sample_many_hz, sampling_direction_many). */
static void phase_emit_block(const phase_fire_args *a, rng_stream *rng, size_t n,
                             emission_photon *e)
{
    bool ok[RNG_MANY], surface[RNG_MANY];
    size_t at[RNG_MANY], ns = 0; /* the surface photons */
    for (size_t j = 0; j < n; j++) {
        ok[j] = air_emission_draw_class(a->air, &rng[j], &e[j], &surface[j]);
        if (surface[j])
            at[ns++] = j;
    }
    double u1[RNG_MANY], u2[RNG_MANY], nu[RNG_MANY];
    for (size_t k = 0; k < ns; k++) {
        u1[k] = rng_uniform32(&rng[at[k]]);
        u2[k] = rng_uniform32(&rng[at[k]]);
    }
    channel_sample_many_hz(&a->scene->channels[a->channel], u1, u2, ns, nu);
    vec3 normal[RNG_MANY], dir[RNG_MANY];
    double mu[RNG_MANY], u[RNG_MANY];
    for (size_t k = 0; k < ns; k++) {
        emission_aim aim = {.normal = v3(0.0, 0.0, 1.0), .mu = 1.0, .u = 0.0};
        ok[at[k]] = emission_sample_aim(a->table, &rng[at[k]], nu[k], &e[at[k]], &aim);
        normal[k] = aim.normal;
        mu[k] = aim.mu;
        u[k] = aim.u;
    }
    sampling_direction_many(normal, mu, u, ns, dir);
    for (size_t k = 0; k < ns; k++) {
        e[at[k]].dir = dir[k];
        air_emission_surface_share(a->air, &e[at[k]]);
    }
    for (size_t j = 0; j < n; j++)
        if (!ok[j])
            e[j].power_w_per_hz = 0.0;
}

/* The capacity the record array grows to when it must hold `need` records after `done` of
 * the `total` photons it is for: the records per photon so far, extrapolated to all of them
 * with a sixteenth and a batch to spare, so that the growth after the first batch is
 * normally the last; and at least a quarter more than `capacity`, should it not be.
 * (Doubling from one record grew it about 24 times in the paper's first channel, by realloc,
 * which moves what was written (mremap) where it cannot extend in place; under this
 * project's VMs' shadow-paging hypervisor every page moved faults again when next read: the
 * index build's first pass over that channel took 0.25 s instead of 0.02, 2026-12-05.) */
static size_t phase_grow_capacity(size_t capacity, size_t need, uint64_t done, uint64_t total)
{
    double want = (double)need / (double)(done ? done : 1) * (double)total * (17.0 / 16.0) +
                  (double)PHASE_BATCH;
    double at_least = (double)capacity * 1.25;
    want = want > at_least ? want : at_least;
    size_t cap = want < (double)(SIZE_MAX / 2) ? (size_t)want : SIZE_MAX / 2;
    return cap > need ? cap : need;
}

thz_status phase_fire(const phase_fire_args *a, photon_record **out_records, size_t *out_count,
                      size_t *out_capacity, trace_counters *total, trace_counters *chunk_out,
                      thz_error *err)
{
    thz_status st = THZ_OK;
    int nthreads = thz_threads_or_all(a->threads);
    if (nthreads < 1)
        nthreads = 1;
    trace_buffer *bufs = thz_calloc((size_t)nthreads, sizeof *bufs);
    phase_chunk *chunks = thz_calloc(PHASE_BATCH / PHASE_CHUNK, sizeof *chunks);
    size_t count = 0, capacity = 0;
    photon_record *records = a->pool ? photon_map_pool_take(a->pool, &capacity) : NULL;
    const bool pooled = records != NULL;
    if (!records) {
        records = thz_malloc_array(1, sizeof *records);
        capacity = 1;
    }
    memset(total, 0, sizeof *total);
    if (!bufs || !chunks || !records) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "photon phase: out of memory");
        goto cleanup;
    }
    const uint64_t seed = a->scene->photons.seed;
    const uint32_t channel = (uint32_t)a->channel;

    for (uint64_t first = a->lo; first < a->hi; first += PHASE_BATCH) {
        uint64_t batch_n = a->hi - first < PHASE_BATCH ? a->hi - first : PHASE_BATCH;
        long n_chunks = (long)((batch_n + PHASE_CHUNK - 1) / PHASE_CHUNK);
        for (int t = 0; t < nthreads; t++)
            bufs[t].count = 0;
        int failed = 0;
        size_t wanted = 0; /* the records the array failed to grow to */

#pragma omp parallel num_threads(nthreads)
        {
            /* The thread's buffer and the chunk's counters are written for every record
             * and event: they live on the thread's own stack while it traces, copied back
             * once per chunk (counters) and per batch (buffer). In the shared arrays,
             * neighbours' fields share cache lines, and the two threads' writes to them
             * held the photon phase to 1.41x on 2 threads (thzbench, 3 M photons; 1.77x
             * with the copies). */
            int tid = omp_get_thread_num();
            trace_buffer b = bufs[tid];
#pragma omp for schedule(dynamic, 1)
            for (long k = 0; k < n_chunks; k++) {
                phase_chunk *ch = &chunks[k];
                trace_counters counters;
                memset(&counters, 0, sizeof counters);
                const size_t start = b.count;
                uint64_t lo = first + (uint64_t)k * PHASE_CHUNK;
                uint64_t hi =
                    lo + PHASE_CHUNK < first + batch_n ? lo + PHASE_CHUNK : first + batch_n;
                bool bad = false;
                for (uint64_t i0 = lo; i0 < hi && !bad; i0 += RNG_MANY) {
                    /* the streams of RNG_MANY photons at once, with the blocks a photon
                     * draws on average (about 3) */
                    rng_stream rng[RNG_MANY];
                    size_t n = hi - i0 < RNG_MANY ? (size_t)(hi - i0) : RNG_MANY;
                    rng_init_many(rng, n, seed, channel, RNG_PURPOSE_PHOTON, a->first_photon + i0,
                                  PHASE_RNG_BLOCKS);
                    emission_photon e[RNG_MANY];
                    phase_emit_block(a, rng, n, e);
                    for (size_t j = 0; j < n; j++) {
                        uint64_t index = a->first_photon + i0 + j;
                        e[j].batch = (uint32_t)(index % PHOTON_MAP_BATCHES);
                        if (!trace_photon(a->scene, a->acc, a->optics, &e[j], &rng[j], &b,
                                          &counters)) {
#pragma omp atomic write
                            failed = 1;
                            bad = true;
                            break;
                        }
                    }
                }
                ch->thread = tid;
                ch->start = start;
                ch->count = b.count - start;
                ch->counters = counters;
            }
            bufs[tid] = b; /* before the merge's barrier: the copy below reads it */
            /* Merge in chunk order (the result is ordered by photon index): one thread
             * sizes the array and sums the counters in that fixed order, then all copy. */
#pragma omp single
            {
                size_t added = 0;
                for (long k = 0; k < n_chunks; k++) {
                    chunks[k].offset = count + added;
                    added += chunks[k].count;
                    trace_counters_add(total, &chunks[k].counters);
                    if (chunk_out)
                        *chunk_out++ = chunks[k].counters;
                }
                if (!failed && count + added > capacity) {
                    size_t cap = phase_grow_capacity(capacity, count + added,
                                                     first + batch_n - a->lo, a->hi - a->lo);
                    photon_record *p = thz_realloc_array(records, cap, sizeof *p);
                    if (p) {
                        records = p;
                        capacity = cap;
                    } else {
                        failed = 2;
                        wanted = cap;
                    }
                }
                if (!failed)
                    count += added;
            }
            if (!failed) {
                /* The batch's range of the array, each thread its share, mapped in one call
                 * before the copies write it (thz_populate; in the first channel of a run
                 * the array is new to the process) */
                size_t from = chunks[0].offset, nt = (size_t)omp_get_num_threads(),
                       t = (size_t)omp_get_thread_num();
                thz_populate(records + from + (count - from) * t / nt,
                             ((count - from) * (t + 1) / nt - (count - from) * t / nt) *
                                 sizeof *records);
#pragma omp for schedule(static)
                for (long k = 0; k < n_chunks; k++) {
                    const phase_chunk *ch = &chunks[k];
                    if (ch->count)
                        memcpy(records + ch->offset, bufs[ch->thread].records + ch->start,
                               ch->count * sizeof *records);
                }
            }
        }
        if (failed) {
            st = failed == 2
                     ? thz_error_set(err, THZ_ERR_NOMEM,
                                     "photon phase: out of memory growing the photon map to %zu "
                                     "records (%.3g GiB; %zu stored so far)",
                                     wanted, (double)wanted * sizeof *records / 1073741824.0, count)
                     : thz_error_set(err, THZ_ERR_NOMEM,
                                     "photon phase: out of memory for photon records");
            goto cleanup;
        }

        if (a->progress && first + batch_n < a->hi) { /* a share's progress, scaled to K */
            double share = (double)(first + batch_n - a->lo) / (double)(a->hi - a->lo);
            thz_progress p = {.stage = "photons",
                              .channel = a->channel,
                              .n_channels = a->scene->n_channels,
                              .done = (uint64_t)(share * (double)a->n_photons),
                              .total = a->n_photons};
            if (a->progress(a->progress_user, &p) != 0) {
                st = thz_error_set(err, THZ_ERR_CANCELLED, "photon phase: cancelled");
                goto cleanup;
            }
        }
    }
    /* Give back the growth slack; in the pool's spare array, only beyond a quarter (the
     * next channel's map, about as large, will reuse it): a map that is kept (--save-photon-
     * map takes no spare) holds no slack. */
    if (count > 0 && (pooled ? capacity - count > count / 4 : capacity > count)) {
        photon_record *p = thz_realloc_array(records, count, sizeof *p);
        if (p) {
            records = p;
            capacity = count;
        }
    }
    *out_records = records;
    *out_count = count;
    *out_capacity = capacity;
    records = NULL;
cleanup:
    if (bufs)
        for (int t = 0; t < nthreads; t++)
            trace_buffer_fini(&bufs[t]);
    free(bufs);
    free(chunks);
    free(records);
    return st;
}
