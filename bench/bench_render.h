/* The integrators' measurements of issue 19 (bench/thzbench.c, sections 5 and 6). Like
 * bench_measure.h, each runs inside a child process of its own and fills a fixed-size
 * struct.
 *
 * Speed-ups: for one integrator on one channel of the paper's scene, the render stage as
 * run_simulate renders a channel (render_context_create, then its passes into the pixel
 * statistics) timed on 1 thread and on all, from one photon map built once before both
 * (the paper's map of L for photon-map, the deviation map from B(T0) for final-gather,
 * none for path). The runs alternate in pairs (1 thread, all, 1, all, ...) and the
 * speed-up is the median of the pairs' ratios (bench_pairs.h).
 *
 * Time to a converged image: path or final-gather on the whole paper's scene through the
 * public API (thz_simulate, as `thzmap simulate --integrator NAME` runs it), twice, each
 * one pass with J and then 4 J independent estimates per pixel (paths_per_sample or
 * gather_rays; final-gather fires its photon map in each run). Per channel: the RMS over
 * the objects' pixels of the per-pixel standard error of Tb (planes of the public API:
 * brightness temperature, radiance standard error, truth object_id;
 * thz_brightness_temperature_stderr), and the photon-phase and render seconds of that
 * channel from the run's summary. The objects' pixels are those whose truth object is
 * neither nothing (-1) nor the enclosure, the object whose bounding box holds every other
 * object's and the sensors (teraeye's "box"): the cylinders and the cover stripes.
 * Noise falling as 1/sqrt(render time) then gives the time to a target from the larger
 * run (bench_converge_seconds); the two runs' own exponent shows whether that holds.
 * Every channel is then run to check it: that channel alone, with the J* estimates the
 * larger run says it needs (J* = 4 J (RMS / target)^2, at least 2, at most a given cap),
 * so that its seconds to the target are measured at the target, not extrapolated across
 * a cost per sample (the first ray, the first hit's band mean) that more estimates do not
 * repeat; the worst of those runs is the figure.
 */
#ifndef THZ_BENCH_RENDER_H
#define THZ_BENCH_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bench_pairs.h"
#include "core/error.h"

#define BENCH_MAX_CHANNELS 16

/* ---- 2-thread speed-ups ------------------------------------------------------------- */

typedef struct bench_speedup_config {
    const char *integrator; /* "photon-map", "final-gather" or "path" */
    size_t channel;
    uint64_t photons;        /* of the map (ignored for path) */
    uint32_t estimates;      /* paths_per_sample or gather_rays; 0: the scene's */
    uint32_t passes;         /* passes per render (photon-map: 1) */
    uint32_t renders;        /* renders per timed run (each from render_context_create) */
    uint32_t sensor_columns; /* > 0: every sensor shrunk to this many columns (rows in
                                proportion), 1 sample per pixel (--small); 0: as is */
    int threads;             /* the "all threads" side */
    int pairs;               /* alternating pairs of timed runs (>= 1) */
} bench_speedup_config;

typedef struct bench_speedup {
    uint64_t photons, stored; /* of the map; 0 for path */
    uint32_t estimates, passes, renders;
    uint64_t samples; /* sample rays of one timed run */
    double s_map;     /* photon phase that built the map (all threads), s */
    bench_pairs runs; /* the timed runs on 1 thread and on `threads` */
} bench_speedup;

thz_status bench_measure_speedup(const char *scene_path, const bench_speedup_config *cfg,
                                 bench_speedup *out, thz_error *err);

/* ---- time to a converged image ------------------------------------------------------- */

typedef struct bench_converge_point {
    uint32_t estimates;                   /* per pixel sample in its one pass */
    double rms_k[BENCH_MAX_CHANNELS];     /* RMS over the objects' pixels of the stderr of Tb */
    double s_photons[BENCH_MAX_CHANNELS]; /* photon phase of the channel, s (0: path) */
    double s_render[BENCH_MAX_CHANNELS];  /* rendering of the channel, s */
    double s_wall;                        /* thz_simulate as a whole, s */
} bench_converge_point;

typedef struct bench_converge {
    uint64_t photons; /* per channel (0: path) */
    size_t channels;
    double freq_thz[BENCH_MAX_CHANNELS];
    uint64_t pixels, object_pixels; /* over all sensors */
    char enclosure[64];             /* the enclosure's name ("" when none) */
    bench_converge_point pt[2];
    /* The runs at the target: each channel c alone with confirm_estimates[c] estimates
     * per sample (confirm's arrays hold it at index c; its `estimates` is unused). */
    bool confirmed;
    bench_converge_point confirm;
    uint32_t confirm_estimates[BENCH_MAX_CHANNELS];
    /* refined[c]: channel c's first run at the target missed it and `confirm` holds a
     * second, with the J the fit through pt[1] and that first run (first_estimates[c],
     * first_rms_k[c]) asked for */
    bool refined[BENCH_MAX_CHANNELS];
    uint32_t first_estimates[BENCH_MAX_CHANNELS];
    double first_rms_k[BENCH_MAX_CHANNELS];
} bench_converge;

/* estimates[0] < estimates[1] (each >= 2); photons for final-gather (0: the scene's);
 * sensor_columns as in bench_speedup_config. With max_confirm > 0, then every channel run
 * alone with the estimates bench_converge_seconds says reach target_k (at most
 * max_confirm), and again where that run misses the target (bench_converge.refined). */
thz_status bench_measure_converge(const char *scene_path, const char *integrator, uint64_t photons,
                                  const uint32_t estimates[2], uint32_t sensor_columns, int threads,
                                  double target_k, uint32_t max_confirm, bench_converge *out,
                                  thz_error *err);

/* Channel c's seconds to an RMS of target_k, photon phase included, with the render time
 * scaled from the larger run as (rms / target_k)^2 (noise proportional to
 * 1/sqrt(render time)). */
double bench_converge_seconds(const bench_converge *cv, size_t c, double target_k);

/* The same from channel c's run at the target (NAN when there was none): its render
 * time, times (rms / target_k)^2 only where its rms is above target_k, plus its photon
 * phase. */
double bench_converge_confirmed_seconds(const bench_converge *cv, size_t c, double target_k);

/* Through the larger run and channel c's run at the target: RMS^2 = a / J + floor^2, J the
 * estimates per sample; the floor is what more estimates do not lower (final-gather's
 * photon map). *need: the J that reaches target_k, 0 when none does. False without the run
 * at the target. */
bool bench_converge_floor(const bench_converge *cv, size_t c, double target_k, double *a_k2,
                          double *floor2, double *need);

/* The exponent k of rms proportional to (render time)^k between the two runs of channel
 * c (-0.5 when the 1/sqrt law holds); 0 when it cannot be formed. */
double bench_converge_exponent(const bench_converge *cv, size_t c);

#endif
