/* The measurements of the benchmark harness (issue 6). Each runs inside its own child
 * process (bench/thzbench.c forks one per measurement), so that the peak memory the OS
 * reports for it (getrusage) belongs to that measurement alone, and writes its results
 * into a fixed-size struct that the child sends back through a pipe.
 *
 * Everything here calls the library's own stages (scene loading, src/accel, the photon
 * phase, the renderer, the output writers, run_simulate); nothing re-implements them.
 */
#ifndef THZ_BENCH_MEASURE_H
#define THZ_BENCH_MEASURE_H

#include <stdint.h>

#include "bench_pairs.h"
#include "core/error.h"

/* Seconds on a monotonic clock, and CPU seconds of this process (all its threads). */
double bench_now_s(void);
double bench_cpu_s(void);

/* 1. The paper's case, stage by stage (the stages of run_simulate, timed one by one). */
typedef struct bench_paper {
    uint64_t photons_per_channel, channels, columns, rows, oversampling;
    uint64_t fired, stored, rays;
    uint64_t largest_map_bytes, largest_map_stored;
    uint64_t largest_map_directory_bytes; /* the renderers' lookup table over that map */
    double s_load, s_accel, s_emission_table, s_tracing, s_index, s_photons, s_render, s_output,
        s_total;
} bench_paper;

/* The same case end to end through the public API's thz_simulate and thz_run_write (what
 * `thzmap simulate` runs). */
typedef struct bench_e2e {
    double s_load, s_run, s_total;
    uint64_t fired, stored;
    uint32_t max_passes;       /* render passes of the channel that took most */
    double worst_p95_stderr_k; /* largest 95th percentile of the stderr of Tb_c, K */
    double target_noise_k;     /* the run's noise target, K (0: none) */
    double s_estimate;         /* the run's own up-front estimate of its time (thz_run_plan) */
    char integrator[16];       /* the integrator that ran */
} bench_e2e;

/* 2. The raw Embree probe for n rays in the scene. */
typedef struct bench_probe_out {
    uint64_t rays, hits;
    double seconds;
} bench_probe_out;

/* 3 and 4. Photon phase of one channel at several photon counts, each followed by a
 * render of every sensor for that channel. */
#define BENCH_MAX_POINTS 8
typedef struct bench_point {
    uint64_t photons, stored, rays, triangles, samples, pixels;
    double s_emission_table, s_tracing, s_index, s_photons, s_render, s_probe;
    double cpu_photons; /* CPU seconds of the process (all threads) in that photon phase:
                           time slices taken by other processes do not count */
    int runs;           /* photon phase runs, of which s_photons and cpu_photons the medians */
    double s_photons_fastest, cpu_photons_fastest;
    double cpu_vs_reference; /* median over the runs of CPU per photon over the reference
                                runs' around it (bench_series_cfg.ref_photons); 0: none */
} bench_point;

typedef struct bench_series {
    int n;
    uint64_t ref_photons; /* the reference runs' photons (bench_series_cfg); 0: none */
    bench_point p[BENCH_MAX_POINTS];
} bench_series;

thz_status bench_measure_paper(const char *scene_path, uint64_t photons, int threads,
                               const char *outdir, bench_paper *out, thz_error *err);
/* integrator NULL: the scene's (teraeye: the default, path); photons 0: the scene's;
 * target_noise_k 0: the scene's or the default. Settings as `thzmap simulate SCENE
 * [--integrator I] [--photons N] [--target-noise-k X]` would pass them. */
thz_status bench_measure_e2e(const char *scene_path, const char *integrator, uint64_t photons,
                             double target_noise_k, int threads, const char *outdir, bench_e2e *out,
                             thz_error *err);
/* Timed phases repeat `repeats` times (>= 1) and keep the fastest: on a shared machine
 * the minimum is the time least disturbed by other processes. */
thz_status bench_measure_probe(const char *scene_path, uint64_t rays, int threads, int repeats,
                               bench_probe_out *out, thz_error *err);

/* Photon phase (and, with render, a render of every sensor) of channel `channel` for each
 * of photons[0..n): one point each; with probe, also the raw Embree probe for the same
 * number of rays. The photon phase of a point runs at least `repeats` times and until its
 * runs took min_seconds (an odd count, at most BENCH_MAX_RUNS), and its seconds and CPU
 * seconds are the **median** run's: the fastest would favour the short points, whose
 * runs can fall wholly in a few seconds when the VM runs faster (bench_pairs.h). With
 * ref_photons, each run lies between two runs of ref_photons photons (the references),
 * and the point's cpu_vs_reference is the median over its runs of its CPU time per
 * photon over the mean of the two references' around it: the VM's speed drifts over
 * minutes, and the points of a series run minutes apart. */
typedef struct bench_series_cfg {
    size_t channel;
    const uint64_t *photons;
    int n;
    int threads, render, probe, repeats;
    double min_seconds;
    uint64_t ref_photons; /* 0: no reference runs */
} bench_series_cfg;

thz_status bench_measure_series(const char *scene_path, const bench_series_cfg *cfg,
                                bench_series *out, thz_error *err);

/* 3c. The photon phase of channel `channel` and the raw Embree probe for its rays, on 1
 * thread and on `threads`, in `pairs` rounds in one process: phase on 1 thread, on all,
 * probe on 1, on all. phase and probe hold each one's alternating pairs (bench_pairs.h);
 * bench_pairs_across(&phase, &probe) is the phase over the probe, round by round. */
typedef struct bench_threads {
    uint64_t photons, rays;
    bench_pairs phase, probe;
} bench_threads;

thz_status bench_measure_threads(const char *scene_path, size_t channel, uint64_t photons,
                                 int threads, int pairs, bench_threads *out, thz_error *err);

/* Writes the tessellated-mesh scene of the triangle scaling into path: an enclosure and
 * four icospheres of `subdivisions` (20 * 4^s triangles each), one channel. */
thz_status bench_write_mesh_scene(const char *path, unsigned subdivisions, uint64_t photons,
                                  thz_error *err);

#endif
