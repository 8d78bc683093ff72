/* The photon phase of one channel (physics.md "Photon phase"): fires K photons from the
 * scene's emitters, traces them, and builds the channel's photon map.
 *
 * Deterministic: photon i's random numbers come from rng_init(seed, channel,
 * RNG_PURPOSE_PHOTON, i) (i counted from photon_phase_options.first_photon); photons run in batches
 * of PHASE_BATCH, each batch in chunks of PHASE_CHUNK photons spread over OpenMP threads; each
 * chunk's records and counters are merged after the batch in chunk order. The map's records
 * (ordered by photon index before photon_map_create sorts them) and the statistics (summed in that
 * fixed order) are therefore bit-identical for any thread count, and, with a team of
 * processes (below), for any number of processes.
 */
#ifndef THZ_PHOTON_PHASE_H
#define THZ_PHOTON_PHASE_H

#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/photon_map.h"
#include "photon/photon_stats.h"
#include "photon/trace.h"
#include "scene/scene.h"

#define PHASE_BATCH 65536u
#define PHASE_CHUNK 256u

typedef struct photon_phase_options {
    int threads; /* 0 = all */
    /* T0 of a deviation map (photon_map.h "Reference temperature"): 0 fires the paper's
     * map of L; T0 > 0 fires the map of L - B_nu(T0), whose sources are
     * eps B(T) - A B(T0) at surfaces, 4 pi alpha (B(T_air) - B(T0)) in the air (T_air = 0
     * for a non-emitting atmosphere) and L_b - B(T0) at the boundary. */
    double reference_temperature_k;
    /* Index of the first photon: photons first_photon .. first_photon + K - 1 are fired
     * (their random streams and batches), so that maps fired with disjoint ranges are
     * independent and merge into one of more photons (photon_map_merge). 0 by default. */
    uint64_t first_photon;
    /* The processes sharing the phase (NULL: this one alone); see photon_phase_team. */
    const struct photon_phase_team *team;
    /* Memory kept between the run's maps (photon_map.h): the record array starts from its
     * spare, and the index build uses its scratch. NULL: none. */
    photon_map_pool *pool;
    /* The one-sided solids' reach shares (emission_reach.h) kept between the run's maps:
     * computed by the first deviation map (T0 > 0) that needs them, then reused. NULL:
     * computed for this phase alone. */
    struct emission_reach *reach;
    thz_progress_fn progress;
    void *progress_user;
} photon_phase_options;

/* Computes opt->reach now, if given and not done, for the deviation maps of a run
 * (T0 > 0) that are to come: so that the memory and time estimates' pilots, which report
 * no progress, find it done. Reports to opt->progress (stage "prepare", done/total in
 * objects, channel 0; emission_reach_compute) between its rounds, and stops when it asks:
 * THZ_ERR_CANCELLED. */
thz_status photon_phase_prepare(const thz_scene *scene, const accel *acc,
                                const photon_phase_options *opt, thz_error *err);

/* Fires scene->photons.per_channel photons for channel `channel` and builds its photon
 * map (*out_map, owned by the caller). stats (may be NULL) is filled completely. Between
 * batches, on the calling thread, calls opt->progress (stage "photons", done/total in
 * photons) and stops with THZ_ERR_CANCELLED if it returns non-zero. opt may be NULL. */
thz_status photon_phase_run(const thz_scene *scene, const accel *acc, size_t channel,
                            const photon_phase_options *opt, photon_map **out_map,
                            photon_stats *stats, thz_error *err);

/* ---- a phase shared by processes (MPI: src/mpi/) ----------------------------------------
 * Member m of n fires the contiguous batches photon_phase_share_range gives it, each photon
 * with the power of the whole phase's K (not of its share), and the lead (member 0) gathers
 * the shares in member order. The records in that order are the photon-index order, and the
 * counters of every chunk, summed in that order, are the sums one process makes: the lead's
 * map and statistics are bit-identical to one process's. */

/* What the lead asks every member to fire: photons first_photon + [0, K) of a channel. */
typedef struct photon_phase_request {
    uint64_t channel;
    uint64_t photons; /* K of the whole phase */
    uint64_t first_photon;
    uint64_t seed; /* the scene's, checked by the members (same scene on every process) */
    double reference_temperature_k;
    uint64_t scene_print; /* the lead's scene_hash_run: the members check it */
} photon_phase_request;

/* One member's share: its records in photon-index order and the counters of each of its
 * chunks (PHASE_CHUNK photons; the last of the phase may be shorter), in order. */
typedef struct photon_phase_share {
    photon_record *records;
    size_t count, capacity;
    trace_counters *chunks;
    size_t n_chunks;
} photon_phase_share;

void photon_phase_share_fini(photon_phase_share *s);

/* Photons [*lo, *hi) of K (counted from the request's first photon) that member m of n
 * fires: whole batches, the first B mod n members one batch more (B = batches of K). */
void photon_phase_share_range(uint64_t k, size_t member, size_t members, uint64_t *lo,
                              uint64_t *hi);

/* Fires member `member` of `members`'s share of rq (threads and reach as
 * photon_phase_options). */
thz_status photon_phase_fire_share(const thz_scene *scene, const accel *acc,
                                   const photon_phase_request *rq, int threads,
                                   struct emission_reach *reach, size_t member, size_t members,
                                   photon_phase_share *out, thz_error *err);

/* How the lead reaches the other members; implemented over MPI by src/mpi/. */
typedef struct photon_phase_team {
    size_t members; /* processes, the lead included */
    /* Before the lead fires its share: every other member starts on rq. */
    thz_status (*start)(void *impl, const photon_phase_request *rq, thz_error *err);
    /* After: the other members' shares, in member order, appended to *share. */
    thz_status (*gather)(void *impl, photon_phase_share *share, thz_error *err);
    void *impl;
} photon_phase_team;

/* Estimated bytes of channel `channel`'s photon records for a map of reference
 * temperature t0_k (a deviation map stores a different number of hits per photon: 1.78
 * against 1.26 on the paper's scene): a pilot of PHASE_PILOT photons
 * (fewer if K is smaller) gives the mean number of stored hits per photon, times K,
 * times sizeof(photon_record), times 1.05 for the pilot's statistical error. The
 * photon map's spatial index comes on top (see photon_map.h). reach as
 * photon_phase_options (NULL: the pilot's own). */
#define PHASE_PILOT 4096u
thz_status photon_phase_estimate_bytes(const thz_scene *scene, const accel *acc, size_t channel,
                                       double t0_k, struct emission_reach *reach, uint64_t *bytes,
                                       thz_error *err);

#endif
