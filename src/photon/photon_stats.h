/* Run statistics of the photon phase for one channel (summary.json "channels"): filled
 * from the tracer's counters by the phase, merged over photon passes by the run, written
 * to summary.json (io/summary.c) and photon-map files (io/photon_map_file.c). This file
 * and photon_stats.c are their one owner. */
#ifndef THZ_PHOTON_PHOTON_STATS_H
#define THZ_PHOTON_PHOTON_STATS_H

#include <stdint.h>

typedef struct photon_stats {
    uint64_t fired;                   /* K */
    uint64_t stored;                  /* records in the photon map */
    uint64_t hits;                    /* surface hits (each stored) */
    uint64_t reflected;               /* roulette: reflection (a lobe sample lost is absorbed) */
    uint64_t transmitted;             /* roulette: transmission through a shell */
    uint64_t absorbed;                /* roulette: absorption (front or back side) */
    uint64_t escaped;                 /* left the scene without a hit */
    uint64_t back_face_hits;          /* hits on the back side of one-sided solids (absorbed) */
    uint64_t terminated;              /* ended by the low-power roulette */
    double emitted_power_w_per_hz;    /* band mean P_A of the scene's physical sources (the
                                         power fired when T0 = 0) */
    double absorbed_power_w_per_hz;   /* sum of power absorbed by surfaces */
    double escaped_power_w_per_hz;    /* sum of power that left the scene */
    double atmosphere_power_w_per_hz; /* sum of power absorbed by the atmosphere */
    double mean_bounces;              /* mean number of hits per photon path */
    double seconds;                   /* wall time of the phase (not reproducible) */
    /* Energy balance (added by the photon phase): absorbed + escaped + atmosphere +
     * terminated power = fired power exactly; fired power estimates emitted power. */
    double fired_power_w_per_hz;      /* sum of the photons' initial powers */
    double terminated_power_w_per_hz; /* net power removed by the low-power roulette (removed
                                         at termination minus added to survivors; zero in
                                         expectation) and by the bounce cap */
    uint64_t bounce_capped;           /* paths stopped at the bounce cap (included in
                                         terminated; should be 0) */
    /* Where the phase's time went (added for the benchmark, issue 6; wall times, not
     * reproducible): seconds = seconds_emission_table + seconds_tracing + seconds_index
     * + a little bookkeeping. */
    uint64_t rays;                 /* rays cast: one per hit, escape or low-power stop */
    double seconds_emission_table; /* emission_table_init */
    double seconds_tracing;        /* firing, tracing and merging the records of every batch */
    double seconds_index;          /* photon_map_create: grouping and the spatial index */
    /* Reference temperature T0 of the map (K; 0: the paper's map of L). With T0 > 0 the
     * photons carry the signed power of L - B_nu(T0) (photon_map.h): fired, absorbed,
     * escaped, atmosphere and terminated powers are the deviation map's signed sums (the
     * balance still closes exactly; fired estimates the band power of the deviation
     * sources, not emitted_power_w_per_hz), and the counts count photons of either sign. */
    double reference_temperature_k;
} photon_stats;

struct trace_counters; /* photon/trace.h */

/* Empty statistics (every count and sum 0). */
void photon_stats_init(photon_stats *s);

/* Adds the outcome of traced paths (trace.h's counters, summed in a fixed order) and the
 * records they stored: counts and power sums add up, mean_bounces follows. Times,
 * emitted power and T0 are the caller's to set. */
void photon_stats_add(photon_stats *s, const struct trace_counters *c, uint64_t stored);

/* Merges the statistics of photon pass p into sum, which holds passes - 1 earlier ones
 * (passes >= 1; the first is copied): counts and times add up, powers are the merged
 * photons' (each pass's divided by the number of passes: the mean of the passes'). */
void photon_stats_merge(photon_stats *sum, const photon_stats *p, uint32_t passes);

#endif
