/* thzbench: the benchmark harness (issue 6). One command runs every measurement,
 * prints a table and writes it as JSON:
 *
 *   1. the paper's case (examples/teraeye) at full size, stage by stage, and end to end
 *      through run_simulate: wall times, photons/s, bytes per stored photon, peak memory;
 *   2. the tracing limit: a raw Embree probe casting as many rays as that photon phase;
 *   3. scaling in photons (1, 3, 10, 30, 100 M in one channel, as memory allows), in
 *      triangles (about 1 k to 1 M, a tessellated mesh scene) and in threads (1 against
 *      all);
 *   4. rendering: gathers/s and time per pixel as the photons per pixel grow.
 *
 * Every measurement runs in a child process of its own (fork), so the peak memory the
 * OS reports for it (wait4's rusage) is that measurement's alone and no OpenMP state is
 * shared across measurements. --small shrinks every count so that the whole run takes
 * seconds (the CI test); it asserts nothing about speed.
 *
 * Usage: thzbench [--small] [--json PATH] [--threads N] [--scene PATH] [--no-e2e]
 */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <jansson.h>

#include "bench_measure.h"

#ifndef THZ_SOURCE_DIR
#define THZ_SOURCE_DIR "."
#endif

/* ---- Memory ------------------------------------------------------------------------- */

/* Bytes the OS says are available (MemAvailable), or 0 if unknown. */
static double bench_mem_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    if (!f)
        return 0.0;
    char line[256];
    double kb = 0.0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
            break;
    fclose(f);
    return 1024.0 * kb;
}

/* The peak of a photon phase of n photons of the paper's case, with margin: 1.3 stored
 * records per photon (1.25 measured) of 32 bytes, their 8-byte Morton codes during the
 * index build, the per-thread buffers and the render: 48 bytes per record, times 1.3. */
static double bench_bytes_needed(uint64_t photons)
{
    return (double)photons * 1.3 * 48.0 * 1.3;
}

static bool bench_fits(uint64_t photons)
{
    double avail = bench_mem_available();
    return avail <= 0.0 || bench_bytes_needed(photons) <= avail;
}

/* ---- Child processes ----------------------------------------------------------------- */

typedef thz_status (*bench_job_fn)(const void *arg, void *out, thz_error *err);

typedef struct bench_child_header {
    int status;
    thz_error err;
} bench_child_header;

static bool bench_write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n > 0) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return false;
        p += k;
        n -= (size_t)k;
    }
    return true;
}

static bool bench_read_all(int fd, void *buf, size_t n)
{
    char *p = buf;
    while (n > 0) {
        ssize_t k = read(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return false;
        p += k;
        n -= (size_t)k;
    }
    return true;
}

/* What the OS reports for a child: its peak resident memory and CPU time (user +
 * system, all threads: against wall time it shows how many cores the child got). */
typedef struct bench_usage {
    uint64_t peak_bytes;
    double cpu_s;
} bench_usage;

/* Runs fn(arg, out) in a child; out (size bytes) comes back through a pipe. */
static thz_status bench_fork(bench_job_fn fn, const void *arg, void *out, size_t size,
                             bench_usage *usage, thz_error *err)
{
    int fds[2];
    if (pipe(fds) != 0)
        return thz_error_set(err, THZ_ERR_IO, "bench: pipe: %s", strerror(errno));
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return thz_error_set(err, THZ_ERR_IO, "bench: fork: %s", strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        bench_child_header h;
        memset(&h, 0, sizeof h);
        memset(out, 0, size);
        h.status = (int)fn(arg, out, &h.err);
        bool ok = bench_write_all(fds[1], &h, sizeof h) && bench_write_all(fds[1], out, size);
        close(fds[1]);
        _exit(ok ? 0 : 1);
    }
    close(fds[1]);
    bench_child_header h;
    bool ok = bench_read_all(fds[0], &h, sizeof h) && bench_read_all(fds[0], out, size);
    close(fds[0]);
    int wstatus = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &wstatus, 0, &ru) < 0 && errno == EINTR) {
    }
    if (usage) {
        usage->peak_bytes = (uint64_t)ru.ru_maxrss * 1024u; /* Linux: kilobytes */
        usage->cpu_s = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                       (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    }
    if (!ok || !WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "bench: a measurement process failed");
    if (h.status != THZ_OK) {
        if (err)
            *err = h.err;
        return (thz_status)h.status;
    }
    return THZ_OK;
}

typedef struct bench_job {
    const char *scene;
    const char *outdir;
    uint64_t photons;
    uint64_t rays;
    int threads;
    size_t channel;
    const uint64_t *series;
    int n_series;
    int render, probe;
    int repeats;
} bench_job;

static thz_status bench_job_paper(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_paper(j->scene, j->photons, j->threads, j->outdir, out, err);
}

static thz_status bench_job_e2e(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_e2e(j->scene, j->photons, j->threads, j->outdir, out, err);
}

static thz_status bench_job_probe(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_probe(j->scene, j->rays, j->threads, j->repeats, out, err);
}

static thz_status bench_job_series(const void *arg, void *out, thz_error *err)
{
    const bench_job *j = arg;
    return bench_measure_series(j->scene, j->channel, j->series, j->n_series, j->threads, j->render,
                                j->probe, j->repeats, out, err);
}

/* ---- Reporting ------------------------------------------------------------------------ */

static double bench_load1(void)
{
    double l[3];
    return getloadavg(l, 3) >= 1 ? l[0] : -1.0;
}

static double bench_ratio(double a, double b)
{
    return b > 0.0 ? a / b : 0.0;
}

static json_t *bench_real(double v)
{
    return json_real(v == v ? v : 0.0);
}

typedef struct bench_targets {
    json_t *list;
    int met, total;
} bench_targets;

static void bench_target(bench_targets *t, const char *name, double value, const char *op,
                         double limit, bool met, const char *unit)
{
    printf("  %-56s %10.3f %s %-6g %-3s %s\n", name, value, op, limit, unit,
           met ? "met" : "NOT met");
    json_t *o = json_object();
    json_object_set_new(o, "target", json_string(name));
    json_object_set_new(o, "value", bench_real(value));
    json_object_set_new(o, "limit", bench_real(limit));
    json_object_set_new(o, "comparison", json_string(op));
    json_object_set_new(o, "unit", json_string(unit));
    json_object_set_new(o, "met", json_boolean(met));
    json_array_append_new(t->list, o);
    t->met += met;
    t->total++;
}

static void bench_print_usage(FILE *f)
{
    fprintf(f, "usage: thzbench [--small] [--json PATH] [--threads N] [--scene PATH] [--no-e2e]\n"
               "  --small      counts shrunk to seconds (CI); speed targets are not meaningful\n"
               "  --json PATH  where the results go (default: thzbench.json)\n"
               "  --threads N  threads of the 'all threads' runs (default: all cores)\n"
               "  --scene PATH the paper's case (default: examples/teraeye/scene.json)\n"
               "  --no-e2e     skip the end-to-end run through run_simulate\n");
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
    /* The probe, the scaling points and the renders are timed as the fastest of
     * `repeats` runs (the paper's case itself runs once). */
    const int repeats = small ? 1 : 3;

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
    double bpp = bench_ratio((double)paper.largest_map_bytes, (double)paper.largest_map_stored);
    printf("\n1. Paper's case: %llu photons x %llu channels, %llux%llu pixels, oversampling %llu "
           "(load average %.2f)\n",
           (unsigned long long)paper.photons_per_channel, (unsigned long long)paper.channels,
           (unsigned long long)paper.columns, (unsigned long long)paper.rows,
           (unsigned long long)paper.oversampling, load_paper);
    printf("  %-22s %9s %7s\n", "phase", "seconds", "share");
    const char *names[] = {"load",        "ray-casting build", "emission table", "tracing",
                           "index build", "rendering",         "output",         "total"};
    double secs[] = {paper.s_load,  paper.s_accel,  paper.s_emission_table, paper.s_tracing,
                     paper.s_index, paper.s_render, paper.s_output,         paper.s_total};
    for (int i = 0; i < 8; i++)
        printf("  %-22s %9.3f %6.1f %%\n", names[i], secs[i],
               100.0 * bench_ratio(secs[i], paper.s_total));
    double pps = bench_ratio((double)paper.fired, paper.s_photons);
    printf("  photon phase %.3f s: %.3g photons/s, %llu stored (%.3f per photon), %llu rays\n",
           paper.s_photons, pps, (unsigned long long)paper.stored,
           bench_ratio((double)paper.stored, (double)paper.fired), (unsigned long long)paper.rays);
    printf("  %.1f CPU s over %.1f s wall: %.2f cores on average\n", paper_use.cpu_s, paper.s_total,
           bench_ratio(paper_use.cpu_s, paper.s_total));
    printf("  largest photon map %.1f MB, %.2f bytes per stored photon; peak memory %.1f MB "
           "(%.2f x the map)\n",
           (double)paper.largest_map_bytes / 1e6, bpp, (double)paper_peak / 1e6,
           bench_ratio((double)paper_peak, (double)paper.largest_map_bytes));
    json_t *jpaper = json_object();
    json_object_set_new(jpaper, "photons_per_channel",
                        json_integer((json_int_t)paper.photons_per_channel));
    json_object_set_new(jpaper, "channels", json_integer((json_int_t)paper.channels));
    json_object_set_new(jpaper, "resolution",
                        json_pack("[I, I]", (json_int_t)paper.columns, (json_int_t)paper.rows));
    json_object_set_new(jpaper, "oversampling", json_integer((json_int_t)paper.oversampling));
    json_t *jsec = json_object();
    const char *keys[] = {"load",  "accel",  "emission_table", "tracing",
                          "index", "render", "output",         "total"};
    for (int i = 0; i < 8; i++)
        json_object_set_new(jsec, keys[i], bench_real(secs[i]));
    json_object_set_new(jsec, "photon_phase", bench_real(paper.s_photons));
    json_object_set_new(jpaper, "seconds", jsec);
    json_object_set_new(jpaper, "photons_fired", json_integer((json_int_t)paper.fired));
    json_object_set_new(jpaper, "photons_stored", json_integer((json_int_t)paper.stored));
    json_object_set_new(jpaper, "rays", json_integer((json_int_t)paper.rays));
    json_object_set_new(jpaper, "photons_per_s", bench_real(pps));
    json_object_set_new(jpaper, "largest_map_bytes",
                        json_integer((json_int_t)paper.largest_map_bytes));
    json_object_set_new(jpaper, "bytes_per_stored_photon", bench_real(bpp));
    json_object_set_new(jpaper, "peak_memory_bytes", json_integer((json_int_t)paper_peak));
    json_object_set_new(
        jpaper, "peak_memory_over_map",
        bench_real(bench_ratio((double)paper_peak, (double)paper.largest_map_bytes)));
    json_object_set_new(jpaper, "load_average", bench_real(load_paper));
    json_object_set_new(jpaper, "cpu_seconds", bench_real(paper_use.cpu_s));

    bench_e2e e2e_r;
    memset(&e2e_r, 0, sizeof e2e_r);
    bench_usage e2e_use = {0, 0.0};
    if (e2e) {
        double l = bench_load1();
        st = bench_fork(bench_job_e2e, &jp, &e2e_r, sizeof e2e_r, &e2e_use, &err);
        const uint64_t e2e_peak = e2e_use.peak_bytes;
        if (st != THZ_OK)
            goto fail;
        printf("  end to end through run_simulate (thzmap simulate): %.3f s (load %.3f s), peak "
               "memory %.1f MB, %.1f CPU s (load average %.2f)\n",
               e2e_r.s_total, e2e_r.s_load, (double)e2e_peak / 1e6, e2e_use.cpu_s, l);
        json_t *je = json_object();
        json_object_set_new(je, "seconds", bench_real(e2e_r.s_total));
        json_object_set_new(je, "seconds_load", bench_real(e2e_r.s_load));
        json_object_set_new(je, "peak_memory_bytes", json_integer((json_int_t)e2e_peak));
        json_object_set_new(je, "cpu_seconds", bench_real(e2e_use.cpu_s));
        json_object_set_new(je, "photons_stored", json_integer((json_int_t)e2e_r.stored));
        json_object_set_new(je, "load_average", bench_real(l));
        json_object_set_new(jpaper, "run_simulate", je);
    }
    json_object_set_new(root, "paper_case", jpaper);

    /* 2. The tracing limit. */
    bench_probe_out probe;
    bench_job jr = {.scene = scene, .rays = paper.rays, .threads = threads, .repeats = repeats};
    double load_probe = bench_load1();
    st = bench_fork(bench_job_probe, &jr, &probe, sizeof probe, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    double ratio_phase = bench_ratio(paper.s_photons, probe.seconds);
    double ratio_trace = bench_ratio(paper.s_tracing, probe.seconds);
    printf("\n2. Tracing limit: raw Embree, %llu rays (%.4f hit) in %.3f s = %.3g rays/s "
           "(load average %.2f)\n",
           (unsigned long long)probe.rays, bench_ratio((double)probe.hits, (double)probe.rays),
           probe.seconds, bench_ratio((double)probe.rays, probe.seconds), load_probe);
    printf("  photon phase / raw trace = %.2f (tracing alone: %.2f)\n", ratio_phase, ratio_trace);
    json_t *jt = json_object();
    json_object_set_new(jt, "rays", json_integer((json_int_t)probe.rays));
    json_object_set_new(jt, "hit_fraction",
                        bench_real(bench_ratio((double)probe.hits, (double)probe.rays)));
    json_object_set_new(jt, "seconds", bench_real(probe.seconds));
    json_object_set_new(jt, "rays_per_s",
                        bench_real(bench_ratio((double)probe.rays, probe.seconds)));
    json_object_set_new(jt, "photon_phase_over_raw", bench_real(ratio_phase));
    json_object_set_new(jt, "tracing_over_raw", bench_real(ratio_trace));
    json_object_set_new(jt, "load_average", bench_real(load_probe));
    json_object_set_new(root, "tracing_limit", jt);

    /* 3a + 4. Photons per channel, and rendering as photons per pixel grow. */
    bench_series sp;
    bench_job js = {.scene = scene,
                    .threads = threads,
                    .channel = series_channel,
                    .series = series,
                    .n_series = n_series,
                    .render = 1,
                    .repeats = repeats};
    double load_sp = bench_load1();
    st = bench_fork(bench_job_series, &js, &sp, sizeof sp, NULL, &err);
    if (st != THZ_OK)
        goto fail;
    printf("\n3. Scaling in photons (channel %zu of the paper's case; load average %.2f)\n",
           series_channel + 1, load_sp);
    printf("  %12s %12s %10s %10s %10s %10s %12s\n", "photons", "stored", "phase s", "ns/photon",
           "trace ns", "index ns", "CPU ns/ph.");
    json_t *jsp = json_array();
    for (int k = 0; k < sp.n; k++) {
        const bench_point *p = &sp.p[k];
        double ns = 1e9 * bench_ratio(p->s_photons, (double)p->photons);
        printf("  %12llu %12llu %10.3f %10.1f %10.1f %10.1f %12.1f\n",
               (unsigned long long)p->photons, (unsigned long long)p->stored, p->s_photons, ns,
               1e9 * bench_ratio(p->s_tracing, (double)p->photons),
               1e9 * bench_ratio(p->s_index, (double)p->photons),
               1e9 * bench_ratio(p->cpu_photons, (double)p->photons));
        json_t *o = json_object();
        json_object_set_new(o, "photons", json_integer((json_int_t)p->photons));
        json_object_set_new(o, "stored", json_integer((json_int_t)p->stored));
        json_object_set_new(o, "seconds", bench_real(p->s_photons));
        json_object_set_new(o, "seconds_tracing", bench_real(p->s_tracing));
        json_object_set_new(o, "seconds_index", bench_real(p->s_index));
        json_object_set_new(o, "ns_per_photon", bench_real(ns));
        json_object_set_new(o, "cpu_ns_per_photon",
                            bench_real(1e9 * bench_ratio(p->cpu_photons, (double)p->photons)));
        json_array_append_new(jsp, o);
    }
    json_object_set_new(root, "scaling_photons", jsp);

    /* 3b. Triangles. */
    bench_series tri;
    memset(&tri, 0, sizeof tri);
    double load_tri = bench_load1();
    json_t *jtri = json_array();
    printf(
        "\n   Scaling in triangles (enclosure + 4 icospheres, %llu photons; load average %.2f)\n",
        (unsigned long long)mesh_photons, load_tri);
    printf("  %12s %10s %10s %12s %12s %12s\n", "triangles", "phase s", "ns/photon", "raw ns/ray",
           "phase/raw", "CPU ns/ph.");
    for (unsigned sd = subdiv_lo; sd <= subdiv_hi; sd++) {
        char path[4300];
        snprintf(path, sizeof path, "%s-s%u.json", meshdir, sd);
        st = bench_write_mesh_scene(path, sd, mesh_photons, &err);
        if (st != THZ_OK)
            goto fail;
        bench_series one;
        bench_job jm = {.scene = path,
                        .threads = threads,
                        .channel = 0,
                        .series = &mesh_photons,
                        .n_series = 1,
                        .probe = 1,
                        .repeats = repeats};
        st = bench_fork(bench_job_series, &jm, &one, sizeof one, NULL, &err);
        remove(path);
        if (st != THZ_OK)
            goto fail;
        const bench_point *p = &one.p[0];
        tri.p[tri.n++] = *p;
        double ns = 1e9 * bench_ratio(p->s_photons, (double)p->photons);
        printf("  %12llu %10.3f %10.1f %12.1f %12.2f %12.1f\n", (unsigned long long)p->triangles,
               p->s_photons, ns, 1e9 * bench_ratio(p->s_probe, (double)p->rays),
               bench_ratio(p->s_photons, p->s_probe),
               1e9 * bench_ratio(p->cpu_photons, (double)p->photons));
        json_t *o = json_object();
        json_object_set_new(o, "triangles", json_integer((json_int_t)p->triangles));
        json_object_set_new(o, "photons", json_integer((json_int_t)p->photons));
        json_object_set_new(o, "seconds", bench_real(p->s_photons));
        json_object_set_new(o, "ns_per_photon", bench_real(ns));
        json_object_set_new(o, "raw_seconds", bench_real(p->s_probe));
        json_object_set_new(o, "cpu_ns_per_photon",
                            bench_real(1e9 * bench_ratio(p->cpu_photons, (double)p->photons)));
        json_object_set_new(o, "raw_ns_per_ray",
                            bench_real(1e9 * bench_ratio(p->s_probe, (double)p->rays)));
        json_array_append_new(jtri, o);
    }
    json_object_set_new(root, "scaling_triangles", jtri);

    /* 3c. Threads: the photon phase and the raw probe, 1 thread against all. */
    bench_series th1, thn;
    bench_job j1 = {.scene = scene,
                    .threads = 1,
                    .channel = series_channel,
                    .series = &thread_photons,
                    .n_series = 1,
                    .probe = 1,
                    .repeats = repeats};
    bench_job jn = j1;
    jn.threads = threads;
    double load_th = bench_load1();
    bench_usage use1 = {0, 0.0}, usen = {0, 0.0};
    st = bench_fork(bench_job_series, &j1, &th1, sizeof th1, &use1, &err);
    if (st == THZ_OK)
        st = bench_fork(bench_job_series, &jn, &thn, sizeof thn, &usen, &err);
    if (st != THZ_OK)
        goto fail;
    double speedup = bench_ratio(th1.p[0].s_photons, thn.p[0].s_photons);
    double speedup_raw = bench_ratio(th1.p[0].s_probe, thn.p[0].s_probe);
    printf("\n   Threads (%llu photons, channel %zu; load average %.2f): photon phase %.3f s on 1, "
           "%.3f s on %d: speed-up %.2f (raw Embree: %.2f); CPU s of the runs %.2f and %.2f\n",
           (unsigned long long)thread_photons, series_channel + 1, load_th, th1.p[0].s_photons,
           thn.p[0].s_photons, threads, speedup, speedup_raw, use1.cpu_s, usen.cpu_s);
    json_t *jth = json_object();
    json_object_set_new(jth, "photons", json_integer((json_int_t)thread_photons));
    json_object_set_new(jth, "threads", json_integer(threads));
    json_object_set_new(jth, "seconds_1", bench_real(th1.p[0].s_photons));
    json_object_set_new(jth, "seconds_all", bench_real(thn.p[0].s_photons));
    json_object_set_new(jth, "speedup", bench_real(speedup));
    json_object_set_new(jth, "raw_speedup", bench_real(speedup_raw));
    json_object_set_new(jth, "cpu_seconds_1", bench_real(use1.cpu_s));
    json_object_set_new(jth, "cpu_seconds_all", bench_real(usen.cpu_s));
    json_object_set_new(jth, "load_average", bench_real(load_th));
    json_object_set_new(root, "scaling_threads", jth);

    /* 4. Rendering. */
    printf("\n4. Rendering (channel %zu of the paper's case)\n", series_channel + 1);
    printf("  %12s %14s %10s %12s %12s\n", "stored", "photons/pixel", "render s", "gathers/s",
           "us/pixel");
    json_t *jren = json_array();
    for (int k = 0; k < sp.n; k++) {
        const bench_point *p = &sp.p[k];
        double ppp = bench_ratio((double)p->stored, (double)p->pixels);
        double gps = bench_ratio((double)p->samples, p->s_render);
        double upp = 1e6 * bench_ratio(p->s_render, (double)p->pixels);
        printf("  %12llu %14.1f %10.3f %12.3g %12.2f\n", (unsigned long long)p->stored, ppp,
               p->s_render, gps, upp);
        json_t *o = json_object();
        json_object_set_new(o, "photons_stored", json_integer((json_int_t)p->stored));
        json_object_set_new(o, "photons_per_pixel", bench_real(ppp));
        json_object_set_new(o, "gathers", json_integer((json_int_t)p->samples));
        json_object_set_new(o, "seconds", bench_real(p->s_render));
        json_object_set_new(o, "gathers_per_s", bench_real(gps));
        json_object_set_new(o, "us_per_pixel", bench_real(upp));
        json_array_append_new(jren, o);
    }
    json_object_set_new(root, "rendering", jren);

    /* Targets. */
    printf("\nTargets%s\n", small ? " (--small: not meaningful)" : "");
    bench_targets t = {.list = json_array()};
    double total = e2e ? e2e_r.s_total : paper.s_total;
    /* Issue 19's targets first (the older ones of issue 6 after them). */
    bench_target(&t, "paper's case end to end", total, "<=", 10, total <= 10, "s");
    bench_target(&t, "photon phase / raw Embree, same rays (bounces incl.)", ratio_phase, "<=", 2,
                 ratio_phase <= 2, "x");
    bench_target(&t, "bytes per stored photon", bpp, "<=", 32, bpp <= 32.005, "B");
    double peak_ratio = bench_ratio((double)paper_peak, (double)paper.largest_map_bytes);
    bench_target(&t, "peak memory / photon map", peak_ratio, "<=", 1.5, peak_ratio <= 1.5, "x");
    /* Flatness and triangle growth from the CPU time per photon: the wall time of a point
     * also counts the time slices other processes took, which on a shared machine varies
     * from point to point; CPU time does not (both are in the table and the JSON). */
    double lo = 0, hi = 0, first = 0;
    for (int k = 0; k < sp.n; k++) {
        double ns = bench_ratio(sp.p[k].cpu_photons, (double)sp.p[k].photons);
        if (k == 0)
            first = lo = hi = ns;
        lo = ns < lo ? ns : lo;
        hi = ns > hi ? ns : hi;
    }
    double dev = first > 0 ? (hi - first > first - lo ? hi / first - 1 : 1 - lo / first) : 0;
    char flat_name[96];
    snprintf(flat_name, sizeof flat_name, "CPU time per photon, %.3g M..%.3g M: largest deviation",
             sp.n ? 1e-6 * (double)sp.p[0].photons : 0.0,
             sp.n ? 1e-6 * (double)sp.p[sp.n - 1].photons : 0.0);
    bench_target(&t, flat_name, 100 * dev, "<=", 20, dev <= 0.2, "%");
    double tri_ratio =
        tri.n ? bench_ratio(
                    bench_ratio(tri.p[tri.n - 1].cpu_photons, (double)tri.p[tri.n - 1].photons),
                    bench_ratio(tri.p[0].cpu_photons, (double)tri.p[0].photons))
              : 0;
    bench_target(&t, "CPU time per photon, 1 k..1 M triangles", tri_ratio, "<=", 3, tri_ratio <= 3,
                 "x");
    bench_target(&t, "photon phase speed-up on all threads", speedup, ">=", 1.85, speedup >= 1.85,
                 "x");
    double render_share = bench_ratio(paper.s_render, paper.s_total);
    bench_target(&t, "rendering share of the paper's case", 100 * render_share, "<=", 20,
                 render_share <= 0.2, "%");
    /* Issue 19's targets this harness does not measure (said, not hidden). */
    const char *not_measured[] = {
        "2-thread speed-up >= 1.85 x of every integrator (the photon phase's is above)",
        "time to a converged image (RMS over the objects' pixels of the per-pixel noise, "
        "0.05 K): path <= 1 s and final-gather <= 5 s per channel"};
    json_t *jnm = json_array();
    for (size_t k = 0; k < sizeof not_measured / sizeof *not_measured; k++) {
        printf("  not measured here: %s\n", not_measured[k]);
        json_array_append_new(jnm, json_string(not_measured[k]));
    }
    json_object_set_new(root, "targets_not_measured", jnm);
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
