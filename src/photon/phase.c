/* The photon phase of one channel: its sources prepared, its photons fired whole or a
 * process's share (phase_fire.c fires them: batches, OpenMP over chunks, ordered merge),
 * the map built, stats. */
#include "photon/phase.h"

#include <math.h>
#include <stdbool.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/sampling.h"
#include "core/threads.h"
#include "scene/scene_hash.h"
#include "photon/air_emission.h"
#include "photon/emission.h"
#include "photon/emission_reach.h"
#include "photon/phase_fire.h"
#include "photon/trace.h"
#include "physics/channel.h"

static thz_status phase_check(const thz_scene *scene, size_t channel, thz_error *err)
{
    if (channel >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL, "photon phase: no channel %zu (scene has %zu)",
                             channel, scene->n_channels);
    if (scene->n_objects > PHOTON_MAX_OBJECTS)
        return thz_error_set(err, THZ_ERR_LIMIT,
                             "photon phase: %zu objects is too many (a photon map holds %zu)",
                             scene->n_objects, PHOTON_MAX_OBJECTS);
    return THZ_OK;
}

/* The sources of channel `channel` for K = n_photons photons of the map of
 * L - B(t0_k) (reach: the back sides' reach shares, emission_table_init), as both the run
 * and its pilot fire them: the surfaces' table and the air
 * and boundary beside them, whose class probabilities weigh the surfaces by their
 * physical band power P_A with T0 = 0, else by the band mean of their signed sources'
 * magnitude. *surface_power_w_per_hz is P_A (statistics). Both are finalised on failure. */
static thz_status phase_sources_init(const thz_scene *scene, const accel *acc, size_t channel,
                                     uint64_t n_photons, double t0_k, const emission_reach *reach,
                                     emission_table *table, air_emission *air,
                                     double *surface_power_w_per_hz, thz_error *err)
{
    thz_status st = emission_table_init(table, scene, acc, channel, n_photons, t0_k, reach, err);
    if (st != THZ_OK)
        return st;
    double surface_power = scene_band_emitted_power_w_per_hz(scene, channel);
    double surface_mass = t0_k > 0.0 ? emission_band_magnitude_w_per_hz(table) : surface_power;
    st = air_emission_init(air, scene, acc, channel, n_photons, surface_mass, t0_k, err);
    if (st != THZ_OK) {
        emission_table_fini(table);
        return st;
    }
    *surface_power_w_per_hz = surface_power;
    return THZ_OK;
}

void photon_phase_share_fini(photon_phase_share *s)
{
    free(s->records);
    free(s->chunks);
    memset(s, 0, sizeof *s);
}

void photon_phase_share_range(uint64_t k, size_t member, size_t members, uint64_t *lo, uint64_t *hi)
{
    uint64_t batches = (k + PHASE_BATCH - 1) / PHASE_BATCH, n = members ? members : 1;
    uint64_t m = member < n ? member : n, each = batches / n, extra = batches % n;
    uint64_t b_lo = m * each + (m < extra ? m : extra);
    uint64_t b_hi = m < n ? b_lo + each + (m < extra ? 1 : 0) : batches;
    *lo = b_lo * PHASE_BATCH < k ? b_lo * PHASE_BATCH : k;
    *hi = b_hi * PHASE_BATCH < k ? b_hi * PHASE_BATCH : k;
}

/* The question of a step that reports no progress of its own (photon_map_build's
 * cancel): the photons stage's progress as it stands, `done` of `photons` (the index
 * build: its last photon not yet counted). */
typedef struct phase_asking {
    const photon_phase_options *opt;
    size_t channel, n_channels;
    uint64_t done, photons;
} phase_asking;

static int phase_cancelled(void *user)
{
    const phase_asking *a = user;
    thz_progress p = {.stage = "photons",
                      .channel = a->channel,
                      .n_channels = a->n_channels,
                      .done = a->done,
                      .total = a->photons};
    return a->opt->progress(a->opt->progress_user, &p);
}

thz_status photon_phase_prepare(const thz_scene *scene, const accel *acc,
                                const photon_phase_options *opt, thz_error *err)
{
    if (!opt || !opt->reach || opt->reach->done)
        return THZ_OK;
    return emission_reach_compute(opt->reach, scene, acc, opt->threads, opt->progress,
                                  opt->progress_user, err);
}

/* Fires photons [lo, hi) of rq from its sources: the share's records and chunk counters,
 * their sum in *total. */
static thz_status phase_fire_range(const thz_scene *scene, const accel *acc,
                                   const photon_phase_request *rq, const emission_table *table,
                                   const air_emission *air, int threads, photon_map_pool *pool,
                                   uint64_t lo, uint64_t hi, thz_progress_fn progress,
                                   void *progress_user, photon_phase_share *out,
                                   trace_counters *total, thz_error *err)
{
    memset(out, 0, sizeof *out);
    size_t n_chunks = (size_t)((hi - lo + PHASE_CHUNK - 1) / PHASE_CHUNK);
    out->chunks = thz_malloc_array(n_chunks ? n_chunks : 1, sizeof *out->chunks);
    if (!out->chunks)
        return thz_error_set(err, THZ_ERR_NOMEM, "photon phase: out of memory");
    out->n_chunks = n_chunks;
    phase_fire_args a = {.scene = scene,
                         .acc = acc,
                         .table = table,
                         .air = air,
                         .channel = (size_t)rq->channel,
                         .n_photons = rq->photons,
                         .lo = lo,
                         .hi = hi,
                         .first_photon = rq->first_photon,
                         .threads = threads,
                         .pool = pool,
                         .progress = progress,
                         .progress_user = progress_user};
    trace_optics optics;
    thz_status st = trace_optics_init(&optics, scene, err);
    if (st == THZ_OK) {
        a.optics = &optics;
        st = phase_fire(&a, &out->records, &out->count, &out->capacity, total, out->chunks, err);
        trace_optics_fini(&optics);
    }
    if (st != THZ_OK)
        photon_phase_share_fini(out);
    return st;
}

thz_status photon_phase_fire_share(const thz_scene *scene, const accel *acc,
                                   const photon_phase_request *rq, int threads,
                                   emission_reach *reach, size_t member, size_t members,
                                   photon_phase_share *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_status st = phase_check(scene, (size_t)rq->channel, err);
    if (st != THZ_OK)
        return st;
    if (rq->seed != scene->photons.seed || rq->photons != scene->photons.per_channel)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: photon phase: process %zu has photons.seed %llu and "
                             "photons.per_channel %llu, the lead %llu and %llu (every process "
                             "must load the same scene with the same options)",
                             scene->path ? scene->path : "scene", member,
                             (unsigned long long)scene->photons.seed,
                             (unsigned long long)scene->photons.per_channel,
                             (unsigned long long)rq->seed, (unsigned long long)rq->photons);
    if (rq->scene_print != scene_hash_run(scene, false))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: photon phase: process %zu's scene differs from the lead's "
                             "(objects, materials, air, channels, sensors or settings; every "
                             "process must load the same scene with the same options)",
                             scene->path ? scene->path : "scene", member);
    emission_table table;
    air_emission air;
    double surface_power;
    if (reach && rq->reference_temperature_k > 0.0)
        st = emission_reach_compute(reach, scene, acc, threads, NULL, NULL, err);
    if (st != THZ_OK)
        return st;
    st = phase_sources_init(scene, acc, (size_t)rq->channel, rq->photons,
                            rq->reference_temperature_k, reach, &table, &air, &surface_power, err);
    if (st != THZ_OK)
        return st;
    uint64_t lo, hi;
    photon_phase_share_range(rq->photons, member, members, &lo, &hi);
    trace_counters total;
    st = phase_fire_range(scene, acc, rq, &table, &air, threads, NULL, lo, hi, NULL, NULL, out,
                          &total, err);
    emission_table_fini(&table);
    air_emission_fini(&air);
    return st;
}

thz_status photon_phase_run(const thz_scene *scene, const accel *acc, size_t channel,
                            const photon_phase_options *opt, photon_map **out_map,
                            photon_stats *stats, thz_error *err)
{
    *out_map = NULL;
    thz_status st = phase_check(scene, channel, err);
    if (st != THZ_OK)
        return st;
    double t0_k = opt ? opt->reference_temperature_k : 0.0;
    if (!(t0_k >= 0.0) || !isfinite(t0_k))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon phase: reference temperature must be >= 0 K, got %g K", t0_k);
    /* The back sides' reach shares: the run's (photon_phase_prepare, or computed here on
     * its first need and kept), else this phase's own; before the stage starts, as their
     * own stage "prepare". */
    emission_reach own = {0}, *reach = opt && opt->reach ? opt->reach : &own;
    if (t0_k > 0.0 && !reach->done) {
        st = emission_reach_compute(reach, scene, acc, opt ? opt->threads : 0,
                                    opt ? opt->progress : NULL, opt ? opt->progress_user : NULL,
                                    err);
        if (st != THZ_OK)
            return st;
    }
    double t0 = omp_get_wtime();
    if (opt && opt->progress) { /* the stage starts (its time, stats->seconds, too) */
        thz_progress p = {.stage = "photons",
                          .channel = channel,
                          .n_channels = scene->n_channels,
                          .done = 0,
                          .total = scene->photons.per_channel};
        if (opt->progress(opt->progress_user, &p) != 0) {
            emission_reach_fini(&own);
            return thz_error_set(err, THZ_ERR_CANCELLED, "photon phase: cancelled");
        }
    }
    const photon_phase_team *team = opt ? opt->team : NULL;
    photon_phase_request rq = {.channel = channel,
                               .photons = scene->photons.per_channel,
                               .first_photon = opt ? opt->first_photon : 0,
                               .seed = scene->photons.seed,
                               .reference_temperature_k = t0_k};
    uint64_t lo = 0, hi = rq.photons;
    if (team) { /* the others start on their shares while the lead builds its table */
        rq.scene_print = scene_hash_run(scene, false);
        photon_phase_share_range(rq.photons, 0, team->members, &lo, &hi);
        st = team->start(team->impl, &rq, err);
        if (st != THZ_OK) {
            emission_reach_fini(&own);
            return st;
        }
    }
    emission_table table;
    air_emission air;
    double surface_power;
    st = phase_sources_init(scene, acc, channel, rq.photons, t0_k, reach, &table, &air,
                            &surface_power, err);
    emission_reach_fini(&own);
    if (st != THZ_OK)
        return st;
    double t1 = omp_get_wtime();
    int threads = opt ? opt->threads : 0;
    photon_phase_share share;
    trace_counters c;
    photon_map_pool *pool = opt ? opt->pool : NULL;
    st = phase_fire_range(scene, acc, &rq, &table, &air, threads, pool, lo, hi,
                          opt ? opt->progress : NULL, opt ? opt->progress_user : NULL, &share, &c,
                          err);
    emission_table_fini(&table);
    double air_power = air.band_power_w_per_hz;
    air_emission_fini(&air);
    if (st == THZ_OK && team) { /* the counters again, summed in one process's order */
        st = team->gather(team->impl, &share, err);
        memset(&c, 0, sizeof c);
        for (size_t k = 0; st == THZ_OK && k < share.n_chunks; k++)
            trace_counters_add(&c, &share.chunks[k]);
    }
    size_t count = share.count, capacity = share.capacity;
    photon_record *records = share.records;
    share.records = NULL;
    photon_phase_share_fini(&share);
    if (st != THZ_OK) {
        free(records);
        return st;
    }
    double t2 = omp_get_wtime();

    /* photon_map_build takes ownership of records, also on failure. It asks for a stop
     * between its passes through the progress callback: the stage's last unit, which it
     * completes, still to come. */
    phase_asking asking = {opt, channel, scene->n_channels, rq.photons ? rq.photons - 1 : 0,
                           rq.photons};
    cancel_check cancel = {phase_cancelled, &asking};
    st = photon_map_build(records, count, capacity, scene->n_objects, threads, pool,
                          opt && opt->progress ? &cancel : NULL, out_map, err);
    if (st != THZ_OK)
        return st;
    photon_map_set_reference_temperature_k(*out_map, t0_k);
    photon_map_set_batches(*out_map, PHOTON_MAP_BATCHES);
    double t3 = omp_get_wtime();
    if (opt && opt->progress) { /* the last batch's progress (phase_fire_args) */
        thz_progress p = {.stage = "photons",
                          .channel = channel,
                          .n_channels = scene->n_channels,
                          .done = rq.photons,
                          .total = rq.photons};
        if (opt->progress(opt->progress_user, &p) != 0) {
            photon_map_destroy(*out_map);
            *out_map = NULL;
            return thz_error_set(err, THZ_ERR_CANCELLED, "photon phase: cancelled");
        }
    }

    if (stats) {
        photon_stats_init(stats);
        photon_stats_add(stats, &c, count);
        stats->emitted_power_w_per_hz = surface_power + air_power; /* + air, boundary */
        stats->reference_temperature_k = t0_k;
        stats->seconds_emission_table = t1 - t0;
        stats->seconds_tracing = t2 - t1;
        stats->seconds_index = t3 - t2;
        stats->seconds = omp_get_wtime() - t0;
    }
    return THZ_OK;
}

thz_status photon_phase_estimate_bytes(const thz_scene *scene, const accel *acc, size_t channel,
                                       double t0_k, emission_reach *reach, uint64_t *bytes,
                                       thz_error *err)
{
    *bytes = 0;
    thz_status st = phase_check(scene, channel, err);
    if (st != THZ_OK)
        return st;
    uint64_t k = scene->photons.per_channel;
    uint64_t pilot = k < PHASE_PILOT ? k : PHASE_PILOT;
    if (pilot == 0)
        return THZ_OK;
    emission_table table;
    air_emission air;
    double surface_power;
    if (reach && t0_k > 0.0)
        st = emission_reach_compute(reach, scene, acc, 0, NULL, NULL, err);
    if (st != THZ_OK)
        return st;
    st = phase_sources_init(scene, acc, channel, k, t0_k, reach, &table, &air, &surface_power, err);
    if (st != THZ_OK)
        return st;
    phase_fire_args a = {.scene = scene,
                         .acc = acc,
                         .table = &table,
                         .air = &air,
                         .channel = channel,
                         .n_photons = pilot,
                         .hi = pilot};
    photon_record *records = NULL;
    size_t count = 0, capacity = 0;
    trace_counters c;
    st = phase_fire(&a, &records, &count, &capacity, &c, NULL, err);
    emission_table_fini(&table);
    air_emission_fini(&air);
    free(records);
    if (st != THZ_OK)
        return st;
    double est = (double)count / (double)pilot * (double)k * (double)sizeof(photon_record) * 1.05;
    *bytes = est >= 1.8e19 ? UINT64_MAX : (uint64_t)ceil(est);
    return THZ_OK;
}
