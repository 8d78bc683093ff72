/* thzbench: the benchmark harness (issues 6 and 19). One command runs every measurement,
 * prints a table and writes it as JSON:
 *
 *   1. the paper's case (examples/teraeye) at full size, stage by stage, and end to end
 *      through thz_simulate twice: with the paper's method (photon-map, the same photon
 *      count), which the 10 s target is judged on, and with the scene's default integrator
 *      (path to its default noise target), which `thzmap simulate SCENE` runs;
 *   2. the tracing limit: a raw Embree probe casting as many rays as that photon phase;
 *   3. scaling in photons (1, 3, 10, 30, 100 M in one channel, as memory allows), in
 *      triangles (about 1 k to 1 M, a tessellated mesh scene), each point the median of
 *      its runs, and in threads (1 against all, in rounds that also give the photon phase
 *      over the probe);
 *   4. rendering: gathers/s and time per pixel as the photons per pixel grow;
 *   5. each integrator's render stage on 1 thread against all (bench_render.h);
 *   6. the time to a converged image, path and final-gather: the RMS over the objects'
 *      pixels of the per-pixel noise, extrapolated to 0.05 K, every channel then run at
 *      the estimates that asks for, the worst of those runs the figure (bench_render.h);
 *
 * and ends with issue 19's targets and issue 6's, each with its value, limit and verdict.
 * This file holds the counts, the order and the targets; each section's table and JSON
 * are bench_report.h's. Every measurement runs in a child process of its own
 * (bench_child.h). --small shrinks every count so that the whole run takes seconds (the
 * CI test); it asserts nothing about speed.
 *
 * Usage: thzbench [--small] [--json PATH] [--threads N] [--scene PATH] [--no-e2e]
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <jansson.h>

#include "bench_child.h"
#include "bench_measure.h"
#include "bench_render.h"
#include "bench_report.h"

#ifndef THZ_SOURCE_DIR
#define THZ_SOURCE_DIR "."
#endif

typedef struct bench_job {
    const char *scene;
    const char *outdir;
    uint64_t photons;
    uint64_t rays;
    int threads;
    int repeats;
    bench_series_cfg series; /* bench_job_series */
} bench_job;

static thz_status bench_job_paper(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_paper(j->scene, j->photons, j->threads, j->outdir, out, err);
}

typedef struct bench_e2e_job {
    const char *scene, *outdir, *integrator;
    uint64_t photons;
    double target_noise_k;
    int threads;
} bench_e2e_job;

static thz_status bench_job_e2e(const void *arg, void *out, thz_error *err)
{
    const bench_e2e_job *j = arg;
    return bench_measure_e2e(j->scene, j->integrator, j->photons, j->target_noise_k, j->threads,
                             j->outdir, out, err);
}

typedef struct bench_speedup_job {
    const char *scene;
    bench_speedup_config cfg;
} bench_speedup_job;

static thz_status bench_job_speedup(const void *arg, void *out, thz_error *err)
{
    const bench_speedup_job *j = arg;
    return bench_measure_speedup(j->scene, &j->cfg, out, err);
}

typedef struct bench_converge_job {
    const char *scene, *integrator;
    uint64_t photons;
    uint32_t estimates[2];
    uint32_t sensor_columns;
    int threads;
    double target_k;
    uint32_t max_confirm;
} bench_converge_job;

static thz_status bench_job_converge(const void *arg, void *out, thz_error *err)
{
    const bench_converge_job *j = arg;
    return bench_measure_converge(j->scene, j->integrator, j->photons, j->estimates,
                                  j->sensor_columns, j->threads, j->target_k, j->max_confirm, out,
                                  err);
}

static thz_status bench_job_probe(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_probe(j->scene, j->rays, j->threads, j->repeats, out, err);
}

static thz_status bench_job_series(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_series(j->scene, &j->series, out, err);
}

typedef struct bench_threads_job {
    const char *scene;
    size_t channel;
    uint64_t photons;
    int threads, pairs;
} bench_threads_job;

static thz_status bench_job_threads(const void *arg, void *out, thz_error *err)
{
    const bench_threads_job *j = arg;
    return bench_measure_threads(j->scene, j->channel, j->photons, j->threads, j->pairs, out, err);
}

/* In a child too: an OpenMP team in this process would not survive the forks after it. */
static thz_status bench_job_ceiling(const void *arg, void *out, thz_error *err)
{
    const bench_threads_job *j = arg;
    (void)err;
    bench_measure_ceiling(j->threads, j->pairs, out);
    return THZ_OK;
}

static void bench_print_usage(FILE *f)
{
    fprintf(f, "usage: thzbench [--small] [--json PATH] [--threads N] [--scene PATH] [--no-e2e]\n"
               "  --small      counts shrunk to seconds (CI); speed targets are not meaningful\n"
               "  --json PATH  where the results go (default: thzbench.json)\n"
               "  --threads N  threads of the 'all threads' runs (default: all cores)\n"
               "  --scene PATH the paper's case (default: examples/teraeye/scene.json)\n"
               "  --no-e2e     skip the end-to-end runs through thz_simulate\n");
}

int main(int argc, char **argv)
{
    bool small = false, e2e = true;
    const char *json_path = "thzbench.json";
    const char *scene = THZ_SOURCE_DIR "/examples/teraeye/scene.json";
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = ncpu > 0 ? (int)ncpu : 1;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--small") == 0) {
            small = true;
        } else if (strcmp(argv[i], "--no-e2e") == 0) {
            e2e = false;
        } else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
            json_path = argv[++i];
        } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc) {
            scene = argv[++i];
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            threads = atoi(argv[++i]);
            if (threads < 1) {
                bench_print_usage(stderr);
                return 2;
            }
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            bench_print_usage(stdout);
            return 0;
        } else {
            bench_print_usage(stderr);
            return 2;
        }
    }

    char tmp[4096];
    const char *tmpdir = getenv("TMPDIR");
    snprintf(tmp, sizeof tmp, "%s/thzbench-XXXXXX", tmpdir && *tmpdir ? tmpdir : "/tmp");
    if (!mkdtemp(tmp)) {
        fprintf(stderr, "thzbench: cannot create a temporary directory: %s\n", strerror(errno));
        return 1;
    }
    char outdir[4200], meshdir[4200];
    snprintf(outdir, sizeof outdir, "%s/out", tmp);
    snprintf(meshdir, sizeof meshdir, "%s/mesh", tmp);

    /* Counts: the in full, about a thousandth of them with --small. */
    const uint64_t paper_photons = small ? 20000 : 0; /* 0: the scene's (10 M) */
    /* The 1 M to 100 M; a point that would not fit in the memory available now
     * is left out and said so (bench_fits). */
    const uint64_t full_series[] = {1000000, 3000000, 10000000, 30000000, 100000000};
    const uint64_t small_series[] = {10000, 30000, 100000};
    const uint64_t *all_series = small ? small_series : full_series;
    const int n_all_series = small ? 3 : 5;
    uint64_t series[8];
    int n_series = 0;
    for (int k = 0; k < n_all_series; k++) {
        if (bench_fits(all_series[k]))
            series[n_series++] = all_series[k];
        else
            printf("(%llu photons left out of the photon scaling: about %.1f GB needed, %.1f GB "
                   "available)\n",
                   (unsigned long long)all_series[k], 1e-9 * bench_bytes_needed(all_series[k]),
                   1e-9 * bench_mem_available());
    }
    const unsigned subdiv_lo = small ? 1 : 2, subdiv_hi = small ? 3 : 7;
    const uint64_t mesh_photons = small ? 10000 : 1000000;
    const uint64_t thread_photons = small ? 20000 : 3000000;
    const size_t series_channel = 2; /* 0.6 THz in the paper's case */
    /* The probe and the renders are timed as the fastest of `repeats` runs (the paper's
     * case itself runs once); a scaling point's photon phase as the median of at least
     * `repeats` runs that take at least series_seconds together (bench_measure.h). */
    const int repeats = small ? 1 : 3;
    const double series_seconds = small ? 0.0 : 3.0;
    /* Each run of a photon scaling point lies between two reference runs of the first
     * point's count, whose mean CPU time per photon it is compared with (the flatness
     * target). */
    const uint64_t series_ref = all_series[0];
    /* Thread speed-ups: alternating pairs of runs, the median of their ratios (an odd
     * count: one pair's) */
    const int pairs = small ? 3 : 7;
    /* The integrators (section 5). final-gather's deviation map: 1 M photons, as
     * docs/integrators.md measures it. The speed-ups render channel 3 from one map (the
     * paper's photon count for photon-map), with work that takes a few seconds on 1
     * thread: photon-map 10 renders, final-gather one pass of the scene's 32 gather rays,
     * path 10 passes of the scene's 16 paths (0: the scene's estimates per pass). */
    const uint64_t fg_photons = small ? 20000 : 1000000;
    /* Time to a converged image (section 6), final-gather: 4 M photons, about the count
     * that reaches 0.05 K soonest on the paper's scene (0.2 THz, fitted through 32 and 64
     * gather rays: at 3, 4, 5 and 6 M photons the map's floor 0.042, 0.037, 0.035,
     * 0.033 K and 68, 50, 43, 39 gather rays; docs/integrators.md). A million photons
     * more cost 0.8 CPU s and save about 5 gather rays, 0.45 CPU s (2026-12-04). Before
     * the guide the optimum was flat from 4 to 8 M and 8 M was kept; with it, 6 M until
     * the render got cheaper. */
    const uint64_t conv_fg_photons = small ? 20000 : 4000000;
    const uint32_t speedup_estimates[3] = {0, small ? 2 : 0, small ? 2 : 0};
    const uint32_t speedup_passes[3] = {1, 1, small ? 1 : 10};
    const uint32_t speedup_renders[3] = {small ? 1 : 10, 1, 1};
    /* Time to a converged image: one pass with J, then 4 J estimates per sample (path's
     * paths, final-gather's gather rays), RMS to converged_k. */
    const uint32_t conv_estimates[2][2] = {{small ? 2 : 4, small ? 4 : 16},
                                           {small ? 2 : 8, small ? 4 : 32}};
    const double converged_k = 0.05;
    /* The worst channel is then run at the estimates its extrapolation needs, at most
     * these (--small: a token run; the paper's scene needs about 120 paths and 200 gather
     * rays, 1 and 35 s) */
    const uint32_t conv_max_confirm[2] = {small ? 8 : 1024, small ? 8 : 512};
    /* --small renders sections 5 and 6 on 16 x 16 pixels, one sample each */
    const uint32_t small_columns = small ? 16 : 0;
    /* The default end to end is path to 0.1 K (default target); --small loosens it. */
    const double default_target_k = small ? 1.0 : 0.0;

    json_t *root = json_object();
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    json_object_set_new(root, "thzbench", json_integer(1));
    json_object_set_new(root, "date", json_string(date));
    json_object_set_new(root, "small", json_boolean(small));
    json_object_set_new(root, "threads", json_integer(threads));
    json_object_set_new(root, "cpus", json_integer(ncpu));
    json_object_set_new(root, "repeats", json_integer(repeats));
    json_object_set_new(root, "scene", json_string(scene));
    json_object_set_new(root, "load_average_start", bench_real(bench_load1()));

    thz_error err;
    memset(&err, 0, sizeof err);
    thz_status st = THZ_OK;
    printf("thzbench%s: %d threads on %ld cpus, load average %.2f, %s\n", small ? " --small" : "",
           threads, ncpu, bench_load1(), date);

    /* 1. The paper's case. */
    bench_paper paper;
    bench_usage paper_use = {0, 0.0};
    bench_job jp = {.scene = scene, .outdir = outdir, .photons = paper_photons, .threads = threads};
    double load_paper = bench_load1();
    st = bench_fork(bench_job_paper, &jp, &paper, sizeof paper, &paper_use, &err);
    const uint64_t paper_peak = paper_use.peak_bytes;
    if (st != THZ_OK)
        goto fail;
    double bpp = 0.0;
    json_t *jpaper = bench_report_paper(&paper, &paper_use, load_paper, &bpp);

    /* End to end through the public API. The paper's case is its method, photon-map with
     * the photon count above: the <= 10 s target is judged on it. The default
     * integrator (path, with its default noise target) is what `thzmap simulate
     * SCENE` runs, reported on its own line. */
    bench_e2e e2e_pm, e2e_def;
    memset(&e2e_pm, 0, sizeof e2e_pm);
    memset(&e2e_def, 0, sizeof e2e_def);
    if (e2e) {
        bench_e2e_job je = {.scene = scene,
                            .outdir = outdir,
                            .integrator = "photon-map",
                            .photons = paper.photons_per_channel,
                            .threads = threads};
        bench_usage use = {0, 0.0};
        double l = bench_load1();
        st = bench_fork(bench_job_e2e, &je, &e2e_pm, sizeof e2e_pm, &use, &err);
        if (st != THZ_OK)
            goto fail;
        json_object_set_new(jpaper, "run_simulate",
                            bench_report_e2e("the paper's method (judged against the 10 s target)",
                                             &e2e_pm, &use, l));
        bench_e2e_job jd = {.scene = scene,
                            .outdir = outdir,
                            .target_noise_k = default_target_k,
                            .threads = threads};
        l = bench_load1();
        st = bench_fork(bench_job_e2e, &jd, &e2e_def, sizeof e2e_def, &use, &err);
        if (st != THZ_OK)
            goto fail;
        json_object_set_new(jpaper, "run_simulate_default",
                            bench_report_e2e(small ? "the scene's default integrator, as `thzmap "
                                                     "simulate SCENE` (--small: looser target)"
                                                   : "the scene's default integrator, as `thzmap "
                                                     "simulate SCENE`",
                                             &e2e_def, &use, l));
    }
    json_object_set_new(root, "paper_case", jpaper);

    /* 2. The tracing limit. */
    bench_probe_out probe;
    bench_job jr = {.scene = scene, .rays = paper.rays, .threads = threads, .repeats = repeats};
    double load_probe = bench_load1();
    st = bench_fork(bench_job_probe, &jr, &probe, sizeof probe, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    double ratio_phase = 0.0;
    json_object_set_new(root, "tracing_limit",
                        bench_report_probe(&probe, &paper, load_probe, &ratio_phase));

    /* 3a + 4. Photons per channel, and rendering as photons per pixel grow. */
    bench_series sp;
    bench_job js = {.scene = scene,
                    .series = {.channel = series_channel,
                               .photons = series,
                               .n = n_series,
                               .threads = threads,
                               .render = 1,
                               .repeats = repeats,
                               .min_seconds = series_seconds,
                               .ref_photons = series_ref}};
    double load_sp = bench_load1();
    st = bench_fork(bench_job_series, &js, &sp, sizeof sp, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    json_object_set_new(root, "scaling_photons",
                        bench_report_photons(&sp, series_channel, load_sp));

    /* 3b. Triangles. */
    bench_series tri;
    memset(&tri, 0, sizeof tri);
    double load_tri = bench_load1();
    json_t *jtri = json_array();
    bench_report_triangles_head(mesh_photons, load_tri);
    for (unsigned sd = subdiv_lo; sd <= subdiv_hi; sd++) {
        char path[4300];
        snprintf(path, sizeof path, "%s-s%u.json", meshdir, sd);
        st = bench_write_mesh_scene(path, sd, mesh_photons, &err);
        if (st != THZ_OK)
            goto fail;
        bench_series one;
        bench_job jm = {.scene = path,
                        .series = {.channel = 0,
                                   .photons = &mesh_photons,
                                   .n = 1,
                                   .threads = threads,
                                   .probe = 1,
                                   .repeats = repeats,
                                   .min_seconds = series_seconds}};
        st = bench_fork(bench_job_series, &jm, &one, sizeof one, NULL, &err);
        remove(path);
        if (st != THZ_OK)
            goto fail;
        const bench_point *p = &one.p[0];
        tri.p[tri.n++] = *p;
        json_array_append_new(jtri, bench_report_triangles_row(p));
    }
    json_object_set_new(root, "scaling_triangles", jtri);

    /* 3c. Threads: the photon phase and the raw probe, 1 thread against all, in
     * alternating pairs in one process (bench_pairs.h), with the machine's own ceiling;
     * and from the same rounds the phase over the probe on all threads. */
    bench_threads th;
    bench_threads_job jthr = {.scene = scene,
                              .channel = series_channel,
                              .photons = thread_photons,
                              .threads = threads,
                              .pairs = pairs};
    double load_th = bench_load1();
    st = bench_fork(bench_job_threads, &jthr, &th, sizeof th, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    bench_pairs ceiling;
    st = bench_fork(bench_job_ceiling, &jthr, &ceiling, sizeof ceiling, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    double speedup = bench_pairs_speedup(&th.phase), across[3];
    json_object_set_new(
        root, "scaling_threads",
        bench_report_threads(&th, &ceiling, series_channel, threads, pairs, load_th, across));

    /* 4. Rendering. */
    json_object_set_new(root, "rendering", bench_report_rendering(&sp, series_channel));

    /* 5. The integrators' 2-thread speed-ups, and 6. the time to a converged image. */
    bench_speedup spd[3];
    const char *integrators[3] = {"photon-map", "final-gather", "path"};
    memset(spd, 0, sizeof spd);
    double load_spd = bench_load1();
    for (int i = 0; i < 3; i++) {
        bench_speedup_job jj = {.scene = scene,
                                .cfg = {.integrator = integrators[i],
                                        .channel = series_channel,
                                        .photons = i == 0 ? paper.photons_per_channel : fg_photons,
                                        .estimates = speedup_estimates[i],
                                        .passes = speedup_passes[i],
                                        .renders = speedup_renders[i],
                                        .sensor_columns = small_columns,
                                        .threads = threads,
                                        .pairs = pairs}};
        st = bench_fork(bench_job_speedup, &jj, &spd[i], sizeof spd[i], NULL, &err);
        if (st != THZ_OK)
            goto fail;
    }
    json_object_set_new(
        root, "integrator_speedups",
        bench_report_speedups(integrators, spd, 3, series_channel, threads, load_spd));

    const char *conv_names[2] = {"path", "final-gather"};
    const double conv_limit_s[2] = {1.0, 5.0};
    double conv_worst[2] = {0.0, 0.0};
    json_t *jconv = json_object();
    for (int i = 0; i < 2; i++) {
        bench_converge cv;
        bench_converge_job jc = {.scene = scene,
                                 .integrator = conv_names[i],
                                 .photons = i == 1 ? conv_fg_photons : 0,
                                 .estimates = {conv_estimates[i][0], conv_estimates[i][1]},
                                 .sensor_columns = small_columns,
                                 .threads = threads,
                                 .target_k = converged_k,
                                 .max_confirm = conv_max_confirm[i]};
        double l = bench_load1();
        st = bench_fork(bench_job_converge, &jc, &cv, sizeof cv, NULL, &err);
        if (st != THZ_OK)
            goto fail;
        json_object_set_new(jconv, conv_names[i],
                            bench_report_converge(conv_names[i], &cv, converged_k, conv_limit_s[i],
                                                  l, &conv_worst[i]));
    }
    json_object_set_new(root, "converged_image", jconv);

    /* Targets: issue 19's first, then the older ones of issue 6. */
    printf("\nTargets%s\n", small ? " (--small: not meaningful)" : "");
    bench_targets t = {.list = json_array()};
    double total = e2e ? e2e_pm.s_total : paper.s_total;
    bench_target(&t,
                 e2e ? "paper's case (photon-map) end to end, thz_simulate"
                     : "paper's case (photon-map) end to end, stage by stage",
                 total, "<=", 10, "s", true);
    bench_target(&t, "photon phase / raw Embree, same rays (bounces incl.)", ratio_phase, "<=", 2,
                 "x", true);
    printf("  (the same in %d rounds, channel %zu, %.3g M photons, each round's phase and probe "
           "one after the other: %.3f x, rounds %.2f-%.2f x)\n",
           th.phase.n, series_channel + 1, 1e-6 * (double)th.photons, across[0], across[1],
           across[2]);
    /* The speed-ups are issue 19's for 2 threads: with another count they are measured
     * but do not show the target. */
    char name[128];
    snprintf(name, sizeof name, "photon phase speed-up, %d threads against 1", threads);
    bench_target(&t, name, speedup, ">=", 1.85, "x", threads == 2);
    for (int i = 0; i < 3; i++) {
        double x = bench_pairs_speedup(&spd[i].runs);
        snprintf(name, sizeof name, "render speed-up, %d threads against 1: %s", threads,
                 integrators[i]);
        bench_target(&t, name, x, ">=", 1.85, "x", threads == 2);
    }
    printf("  (not a target: pure arithmetic, the machine's own ceiling, %.3f x; fastest over "
           "fastest %.3f x)\n",
           bench_pairs_speedup(&ceiling), bench_pairs_speedup_fastest(&ceiling));
    for (int i = 0; i < 2; i++) {
        snprintf(name, sizeof name, "%s: s per channel to %g K objects' RMS (worst of all run)",
                 conv_names[i], converged_k);
        bench_target(&t, name, conv_worst[i], "<=", conv_limit_s[i], "s", true);
    }
    bench_target(&t, "bytes per stored photon (record, index, directory)", bpp, "<=", 32, "B",
                 true);
    /* Flatness and triangle growth from the CPU time per photon: the wall time of a point
     * also counts the time slices other processes took, which on a shared machine varies
     * from point to point; CPU time does not (both are in the table and the JSON). The
     * flatness is each point's CPU time per photon over the mean of the two reference runs
     * (the first point's count) around each of its runs, the median over its runs: the
     * VM's speed drifts over the minutes a series takes, so points compared with each
     * other compare machine speeds too (the points' medians against each other are
     * printed below it). It is shown only over the whole 1 M..100 M. */
    double dev = 0, lo = 0, hi = 0, first = 0;
    for (int k = 0; k < sp.n; k++) {
        double r = sp.p[k].cpu_vs_reference;
        dev = fabs(r - 1) > dev ? fabs(r - 1) : dev;
        double ns = bench_ratio(sp.p[k].cpu_photons, (double)sp.p[k].photons);
        if (k == 0)
            first = lo = hi = ns;
        lo = ns < lo ? ns : lo;
        hi = ns > hi ? ns : hi;
    }
    double dev_points = first > 0 ? (hi - first > first - lo ? hi / first - 1 : 1 - lo / first) : 0;
    snprintf(name, sizeof name, "CPU time per photon, %.3g M..%.3g M: largest deviation",
             sp.n ? 1e-6 * (double)sp.p[0].photons : 0.0,
             sp.n ? 1e-6 * (double)sp.p[sp.n - 1].photons : 0.0);
    bool whole = sp.n > 0 && sp.p[0].photons <= 1000000 && sp.p[sp.n - 1].photons >= 100000000;
    bench_target(&t, name, 100 * dev, "<=", 20, "%", whole);
    printf("  (each point against its own reference runs; the points' medians against each "
           "other, runs minutes apart: %.1f %%)\n",
           100 * dev_points);
    json_object_set_new(root, "flatness_between_points_percent", bench_real(100 * dev_points));
    double peak_ratio = bench_ratio((double)paper_peak, (double)paper.largest_map_bytes);
    bench_target(&t, "peak memory / photon map (issue 6)", peak_ratio, "<=", 1.5, "x", true);
    double tri_ratio =
        tri.n ? bench_ratio(
                    bench_ratio(tri.p[tri.n - 1].cpu_photons, (double)tri.p[tri.n - 1].photons),
                    bench_ratio(tri.p[0].cpu_photons, (double)tri.p[0].photons))
              : 0;
    bench_target(&t, "CPU time per photon, 1 k..1 M triangles (issue 6)", tri_ratio, "<=", 3, "x",
                 true);
    double render_share = bench_ratio(paper.s_render, paper.s_total);
    bench_target(&t, "rendering share of the paper's case (issue 6)", 100 * render_share, "<=", 20,
                 "%", true);
    json_object_set_new(root, "targets", t.list);
    json_object_set_new(root, "targets_met", json_integer(t.met));
    json_object_set_new(root, "load_average_end", bench_real(bench_load1()));
    printf("%d of %d targets met; results in %s\n", t.met, t.total, json_path);

    if (json_dump_file(root, json_path, JSON_INDENT(2)) != 0) {
        fprintf(stderr, "thzbench: cannot write %s\n", json_path);
        json_decref(root);
        return 1;
    }
    json_decref(root);
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (system(cmd) != 0)
        fprintf(stderr, "thzbench: could not remove %s\n", tmp);
    return 0;
fail:
    fprintf(stderr, "thzbench: %s\n", err.message);
    json_decref(root);
    return 1;
}
