/* The benchmark's printed table and its JSON: see bench_report.h. */
#include "bench_report.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

double bench_ratio(double a, double b)
{
    return b > 0.0 ? a / b : 0.0;
}

json_t *bench_real(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

void bench_target(bench_targets *t, const char *name, double value, const char *op, double limit,
                  const char *unit, bool shown)
{
    bool met = strcmp(op, ">=") == 0 ? value >= limit : value <= limit;
    bench_verdict v = !shown ? BENCH_NOT_SHOWN : met ? BENCH_MET : BENCH_NOT_MET;
    const char *word = v == BENCH_MET ? "met" : v == BENCH_NOT_MET ? "NOT met" : "not shown";
    printf("  %-66s %10.3f %s %-6g %-3s %s\n", name, value, op, limit, unit, word);
    json_t *o = json_object();
    json_object_set_new(o, "target", json_string(name));
    json_object_set_new(o, "value", bench_real(value));
    json_object_set_new(o, "limit", bench_real(limit));
    json_object_set_new(o, "comparison", json_string(op));
    json_object_set_new(o, "unit", json_string(unit));
    json_object_set_new(o, "met", json_boolean(v == BENCH_MET));
    json_object_set_new(o, "verdict",
                        json_string(v == BENCH_MET       ? "met"
                                    : v == BENCH_NOT_MET ? "not met"
                                                         : "not shown"));
    json_array_append_new(t->list, o);
    t->met += v == BENCH_MET;
    t->total++;
}

void bench_report_point_runs(json_t *o, const bench_point *p)
{
    json_object_set_new(o, "runs", json_integer(p->runs));
    json_object_set_new(o, "cpu_ns_per_photon",
                        bench_real(1e9 * bench_ratio(p->cpu_photons, (double)p->photons)));
    json_object_set_new(o, "seconds_fastest", bench_real(p->s_photons_fastest));
    json_object_set_new(o, "cpu_ns_per_photon_fastest",
                        bench_real(1e9 * bench_ratio(p->cpu_photons_fastest, (double)p->photons)));
    if (p->cpu_vs_reference > 0.0)
        json_object_set_new(o, "cpu_vs_reference", bench_real(p->cpu_vs_reference));
}

json_t *bench_report_paper(const bench_paper *paper, const bench_usage *use, double load,
                           double *bytes_per_photon)
{
    const uint64_t peak = use->peak_bytes;
    /* a stored photon's memory: its record, its share of the index's offsets and cubes,
     * and of the directory the renderers build over the map */
    double bpp =
        bench_ratio((double)(paper->largest_map_bytes + paper->largest_map_directory_bytes),
                    (double)paper->largest_map_stored);
    *bytes_per_photon = bpp;
    printf("\n1. Paper's case: %llu photons x %llu channels, %llux%llu pixels, oversampling %llu "
           "(load average %.2f)\n",
           (unsigned long long)paper->photons_per_channel, (unsigned long long)paper->channels,
           (unsigned long long)paper->columns, (unsigned long long)paper->rows,
           (unsigned long long)paper->oversampling, load);
    printf("  %-22s %9s %7s\n", "phase", "seconds", "share");
    const char *names[] = {"load",        "ray-casting build", "emission table", "tracing",
                           "index build", "rendering",         "output",         "total"};
    double secs[] = {paper->s_load,  paper->s_accel,  paper->s_emission_table, paper->s_tracing,
                     paper->s_index, paper->s_render, paper->s_output,         paper->s_total};
    for (int i = 0; i < 8; i++)
        printf("  %-22s %9.3f %6.1f %%\n", names[i], secs[i],
               100.0 * bench_ratio(secs[i], paper->s_total));
    double pps = bench_ratio((double)paper->fired, paper->s_photons);
    printf("  photon phase %.3f s: %.3g photons/s, %llu stored (%.3f per photon), %llu rays\n",
           paper->s_photons, pps, (unsigned long long)paper->stored,
           bench_ratio((double)paper->stored, (double)paper->fired),
           (unsigned long long)paper->rays);
    printf("  %.1f CPU s over %.1f s wall: %.2f cores on average\n", use->cpu_s, paper->s_total,
           bench_ratio(use->cpu_s, paper->s_total));
    printf("  largest photon map %.1f MB and its renderers' directory %.1f MB: %.3f bytes per "
           "stored photon; peak memory %.1f MB (%.2f x the map without its directory)\n",
           (double)paper->largest_map_bytes / 1e6, (double)paper->largest_map_directory_bytes / 1e6,
           bpp, (double)peak / 1e6, bench_ratio((double)peak, (double)paper->largest_map_bytes));
    json_t *jpaper = json_object();
    json_object_set_new(jpaper, "photons_per_channel",
                        json_integer((json_int_t)paper->photons_per_channel));
    json_object_set_new(jpaper, "channels", json_integer((json_int_t)paper->channels));
    json_object_set_new(jpaper, "resolution",
                        json_pack("[I, I]", (json_int_t)paper->columns, (json_int_t)paper->rows));
    json_object_set_new(jpaper, "oversampling", json_integer((json_int_t)paper->oversampling));
    json_t *jsec = json_object();
    const char *keys[] = {"load",  "accel",  "emission_table", "tracing",
                          "index", "render", "output",         "total"};
    for (int i = 0; i < 8; i++)
        json_object_set_new(jsec, keys[i], bench_real(secs[i]));
    json_object_set_new(jsec, "photon_phase", bench_real(paper->s_photons));
    json_object_set_new(jpaper, "seconds", jsec);
    json_object_set_new(jpaper, "photons_fired", json_integer((json_int_t)paper->fired));
    json_object_set_new(jpaper, "photons_stored", json_integer((json_int_t)paper->stored));
    json_object_set_new(jpaper, "rays", json_integer((json_int_t)paper->rays));
    json_object_set_new(jpaper, "photons_per_s", bench_real(pps));
    json_object_set_new(jpaper, "largest_map_bytes",
                        json_integer((json_int_t)paper->largest_map_bytes));
    json_object_set_new(jpaper, "largest_map_stored",
                        json_integer((json_int_t)paper->largest_map_stored));
    json_object_set_new(jpaper, "largest_map_directory_bytes",
                        json_integer((json_int_t)paper->largest_map_directory_bytes));
    json_object_set_new(jpaper, "bytes_per_stored_photon", bench_real(bpp));
    json_object_set_new(jpaper, "peak_memory_bytes", json_integer((json_int_t)peak));
    json_object_set_new(jpaper, "peak_memory_over_map",
                        bench_real(bench_ratio((double)peak, (double)paper->largest_map_bytes)));
    json_object_set_new(jpaper, "load_average", bench_real(load));
    json_object_set_new(jpaper, "cpu_seconds", bench_real(use->cpu_s));
    return jpaper;
}

json_t *bench_report_probe(const bench_probe_out *probe, const bench_paper *paper, double load,
                           double *phase_over_raw)
{
    double ratio_phase = bench_ratio(paper->s_photons, probe->seconds);
    double ratio_trace = bench_ratio(paper->s_tracing, probe->seconds);
    printf("\n2. Tracing limit: raw Embree, %llu rays (%.4f hit) in %.3f s = %.3g rays/s "
           "(load average %.2f)\n",
           (unsigned long long)probe->rays, bench_ratio((double)probe->hits, (double)probe->rays),
           probe->seconds, bench_ratio((double)probe->rays, probe->seconds), load);
    printf("  photon phase / raw trace = %.2f x (tracing alone: %.2f x)\n", ratio_phase,
           ratio_trace);
    json_t *jt = json_object();
    json_object_set_new(jt, "rays", json_integer((json_int_t)probe->rays));
    json_object_set_new(jt, "hit_fraction",
                        bench_real(bench_ratio((double)probe->hits, (double)probe->rays)));
    json_object_set_new(jt, "seconds", bench_real(probe->seconds));
    json_object_set_new(jt, "rays_per_s",
                        bench_real(bench_ratio((double)probe->rays, probe->seconds)));
    json_object_set_new(jt, "photon_phase_over_raw", bench_real(ratio_phase));
    json_object_set_new(jt, "tracing_over_raw", bench_real(ratio_trace));
    json_object_set_new(jt, "load_average", bench_real(load));
    *phase_over_raw = ratio_phase;
    return jt;
}

json_t *bench_report_photons(const bench_series *sp, size_t channel, double load)
{
    printf("\n3. Scaling in photons (channel %zu of the paper's case; load average %.2f): each "
           "point the median of its runs; each run between two reference runs of %llu photons\n",
           channel + 1, load, (unsigned long long)sp->ref_photons);
    printf("  %12s %12s %5s %10s %10s %16s %16s %14s %22s %10s\n", "photons", "stored", "runs",
           "phase s", "ns/photon", "trace ns/photon", "index ns/photon", "CPU ns/photon",
           "fastest CPU ns/photon", "CPU vs ref");
    json_t *jsp = json_array();
    for (int k = 0; k < sp->n; k++) {
        const bench_point *p = &sp->p[k];
        double ns = 1e9 * bench_ratio(p->s_photons, (double)p->photons);
        printf("  %12llu %12llu %5d %10.3f %10.1f %16.1f %16.1f %14.1f %22.1f %8.3f x\n",
               (unsigned long long)p->photons, (unsigned long long)p->stored, p->runs, p->s_photons,
               ns, 1e9 * bench_ratio(p->s_tracing, (double)p->photons),
               1e9 * bench_ratio(p->s_index, (double)p->photons),
               1e9 * bench_ratio(p->cpu_photons, (double)p->photons),
               1e9 * bench_ratio(p->cpu_photons_fastest, (double)p->photons), p->cpu_vs_reference);
        json_t *o = json_object();
        json_object_set_new(o, "photons", json_integer((json_int_t)p->photons));
        json_object_set_new(o, "stored", json_integer((json_int_t)p->stored));
        json_object_set_new(o, "seconds", bench_real(p->s_photons));
        json_object_set_new(o, "seconds_tracing", bench_real(p->s_tracing));
        json_object_set_new(o, "seconds_index", bench_real(p->s_index));
        json_object_set_new(o, "ns_per_photon", bench_real(ns));
        bench_report_point_runs(o, p);
        json_array_append_new(jsp, o);
    }
    return jsp;
}

void bench_report_triangles_head(uint64_t photons, double load)
{
    printf(
        "\n   Scaling in triangles (enclosure + 4 icospheres, %llu photons; load average %.2f)\n",
        (unsigned long long)photons, load);
    printf("  %12s %5s %10s %10s %12s %12s %12s\n", "triangles", "runs", "phase s", "ns/photon",
           "raw ns/ray", "phase/raw", "CPU ns/ph.");
}

json_t *bench_report_triangles_row(const bench_point *p)
{
    double ns = 1e9 * bench_ratio(p->s_photons, (double)p->photons);
    printf("  %12llu %5d %10.3f %10.1f %12.1f %10.2f x %12.1f\n", (unsigned long long)p->triangles,
           p->runs, p->s_photons, ns, 1e9 * bench_ratio(p->s_probe, (double)p->rays),
           bench_ratio(p->s_photons, p->s_probe),
           1e9 * bench_ratio(p->cpu_photons, (double)p->photons));
    json_t *o = json_object();
    json_object_set_new(o, "triangles", json_integer((json_int_t)p->triangles));
    json_object_set_new(o, "photons", json_integer((json_int_t)p->photons));
    json_object_set_new(o, "seconds", bench_real(p->s_photons));
    json_object_set_new(o, "ns_per_photon", bench_real(ns));
    json_object_set_new(o, "raw_seconds", bench_real(p->s_probe));
    bench_report_point_runs(o, p);
    json_object_set_new(o, "raw_ns_per_ray",
                        bench_real(1e9 * bench_ratio(p->s_probe, (double)p->rays)));
    return o;
}

json_t *bench_report_threads(const bench_threads *th, const bench_pairs *ceiling, size_t channel,
                             int threads, int pairs, double load, double across[3])
{
    printf("\n   Threads (%llu photons, channel %zu; %d pairs of runs on 1 and %d threads, "
           "alternating; load average %.2f): speed-up the median of the pairs' ratios\n",
           (unsigned long long)th->photons, channel + 1, pairs, threads, load);
    json_t *jth = json_object();
    json_object_set_new(jth, "photons", json_integer((json_int_t)th->photons));
    json_object_set_new(jth, "rays", json_integer((json_int_t)th->rays));
    json_object_set_new(jth, "threads", json_integer(threads));
    json_object_set_new(jth, "speedup", bench_real(bench_pairs_speedup(&th->phase)));
    json_object_set_new(jth, "raw_speedup", bench_real(bench_pairs_speedup(&th->probe)));
    json_object_set_new(jth, "photon_phase", bench_report_pairs("photon phase", &th->phase));
    json_object_set_new(jth, "raw_probe", bench_report_pairs("raw Embree probe", &th->probe));
    json_object_set_new(jth, "ceiling",
                        bench_report_pairs("pure arithmetic (the machine)", ceiling));
    across[0] = bench_pairs_across(&th->phase, &th->probe, &across[1], &across[2]);
    printf("     photon phase / raw Embree probe, %d threads, round by round: %.2f x (rounds "
           "%.2f-%.2f x)\n",
           threads, across[0], across[1], across[2]);
    json_t *jacross = json_object();
    json_object_set_new(jacross, "median", bench_real(across[0]));
    json_object_set_new(jacross, "round_min", bench_real(across[1]));
    json_object_set_new(jacross, "round_max", bench_real(across[2]));
    json_object_set_new(jth, "photon_phase_over_raw", jacross);
    json_object_set_new(jth, "load_average", bench_real(load));
    return jth;
}

json_t *bench_report_rendering(const bench_series *sp, size_t channel)
{
    printf("\n4. Rendering (channel %zu of the paper's case)\n", channel + 1);
    printf("  %12s %14s %10s %12s %12s\n", "stored", "photons/pixel", "render s", "gathers/s",
           "us/pixel");
    json_t *jren = json_array();
    for (int k = 0; k < sp->n; k++) {
        const bench_point *p = &sp->p[k];
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
    return jren;
}

json_t *bench_report_e2e(const char *label, const bench_e2e *e, const bench_usage *use, double load)
{
    char target[64] = "no noise target";
    if (e->target_noise_k > 0.0)
        snprintf(target, sizeof target, "noise target %g K (p95 over pixels)", e->target_noise_k);
    printf("  end to end, %s\n    %s: %.3f s (load %.3f s); %llu photons fired, %llu stored; "
           "passes per channel up to %u, %s, worst p95 %.3f K;\n    peak memory %.1f MB, %.1f "
           "CPU s (%.2f cores on average; load average %.2f)\n    its estimate before the "
           "work %.3f s, %.2f x the run\n",
           label, e->integrator, e->s_total, e->s_load, (unsigned long long)e->fired,
           (unsigned long long)e->stored, (unsigned)e->max_passes, target, e->worst_p95_stderr_k,
           (double)use->peak_bytes / 1e6, use->cpu_s, bench_ratio(use->cpu_s, e->s_total), load,
           e->s_estimate, bench_ratio(e->s_estimate, e->s_run));
    json_t *je = json_object();
    json_object_set_new(je, "integrator", json_string(e->integrator));
    json_object_set_new(je, "seconds", bench_real(e->s_total));
    json_object_set_new(je, "seconds_load", bench_real(e->s_load));
    json_object_set_new(je, "seconds_run", bench_real(e->s_run));
    json_object_set_new(je, "photons_fired", json_integer((json_int_t)e->fired));
    json_object_set_new(je, "photons_stored", json_integer((json_int_t)e->stored));
    json_object_set_new(je, "max_passes", json_integer((json_int_t)e->max_passes));
    json_object_set_new(je, "target_noise_k",
                        e->target_noise_k > 0.0 ? bench_real(e->target_noise_k) : json_null());
    json_object_set_new(je, "worst_p95_stderr_k", bench_real(e->worst_p95_stderr_k));
    json_object_set_new(je, "peak_memory_bytes", json_integer((json_int_t)use->peak_bytes));
    json_object_set_new(je, "cpu_seconds", bench_real(use->cpu_s));
    json_object_set_new(je, "load_average", bench_real(load));
    json_object_set_new(je, "estimate_seconds", bench_real(e->s_estimate));
    return je;
}

static json_t *bench_reals(const double *v, size_t n);

json_t *bench_report_pairs(const char *label, const bench_pairs *p)
{
    double lo, hi;
    bench_pairs_range(p, &lo, &hi);
    double s1, sa, c1, ca;
    bench_pairs_median_pair(p, &s1, &sa, &c1, &ca);
    if (label)
        printf("     %-30s speed-up %.2f x (pairs %.2f-%.2f x; fastest over fastest %.2f "
               "x); median pair %.3f s / %.3f s, CPU %.2f s / %.2f s\n",
               label, bench_pairs_speedup(p), lo, hi, bench_pairs_speedup_fastest(p), s1, sa, c1,
               ca);
    json_t *o = json_object();
    json_object_set_new(o, "speedup", bench_real(bench_pairs_speedup(p)));
    json_object_set_new(o, "speedup_fastest", bench_real(bench_pairs_speedup_fastest(p)));
    json_object_set_new(o, "pair_min", bench_real(lo));
    json_object_set_new(o, "pair_max", bench_real(hi));
    json_object_set_new(o, "seconds_1", bench_reals(p->s_1, (size_t)p->n));
    json_object_set_new(o, "seconds_all", bench_reals(p->s_all, (size_t)p->n));
    json_object_set_new(o, "cpu_seconds_1", bench_reals(p->cpu_1, (size_t)p->n));
    json_object_set_new(o, "cpu_seconds_all", bench_reals(p->cpu_all, (size_t)p->n));
    return o;
}

json_t *bench_report_speedups(const char *const *names, const bench_speedup *r, int n,
                              size_t channel, int threads, double load)
{
    printf("\n5. Integrators: the render stage on 1 thread against %d (channel %zu of the "
           "paper's case; one map built once per integrator; alternating pairs of runs, the "
           "speed-up the median of their ratios; load average %.2f)\n",
           threads, channel + 1, load);
    printf("  %-13s %11s %9s %7s %8s %9s %6s %10s %10s %9s %13s %8s %13s\n", "integrator",
           "map photons", "est./pass", "passes", "renders", "samples", "pairs", "1 thread s",
           "all s", "speed-up", "pair range", "fastest", "CPU s 1 / all");
    json_t *arr = json_array();
    for (int i = 0; i < n; i++) {
        const bench_speedup *p = &r[i];
        double sp = bench_pairs_speedup(&p->runs), lo, hi;
        bench_pairs_range(&p->runs, &lo, &hi);
        double s1, sa, c1, ca;
        bench_pairs_median_pair(&p->runs, &s1, &sa, &c1, &ca);
        char range[48];
        snprintf(range, sizeof range, "%.2f-%.2f x", lo, hi);
        printf("  %-13s %11llu %9u %7u %8u %9llu %6d %10.3f %10.3f %7.2f x %13s %6.2f x %6.2f / "
               "%5.2f\n",
               names[i], (unsigned long long)p->photons, (unsigned)p->estimates,
               (unsigned)p->passes, (unsigned)p->renders, (unsigned long long)p->samples, p->runs.n,
               s1, sa, sp, range, bench_pairs_speedup_fastest(&p->runs), c1, ca);
        json_t *o = json_object();
        json_object_set_new(o, "integrator", json_string(names[i]));
        json_object_set_new(o, "map_photons", json_integer((json_int_t)p->photons));
        json_object_set_new(o, "map_stored", json_integer((json_int_t)p->stored));
        json_object_set_new(o, "map_seconds", bench_real(p->s_map));
        json_object_set_new(o, "estimates_per_pass", json_integer(p->estimates));
        json_object_set_new(o, "passes", json_integer(p->passes));
        json_object_set_new(o, "renders", json_integer(p->renders));
        json_object_set_new(o, "samples", json_integer((json_int_t)p->samples));
        json_object_set_new(o, "seconds_1", bench_real(s1));
        json_object_set_new(o, "seconds_all", bench_real(sa));
        json_object_set_new(o, "speedup", bench_real(sp));
        json_object_set_new(o, "cpu_seconds_1", bench_real(c1));
        json_object_set_new(o, "cpu_seconds_all", bench_real(ca));
        json_object_set_new(o, "runs", bench_report_pairs(NULL, &p->runs));
        json_array_append_new(arr, o);
    }
    printf("  (samples: sample rays of one timed run; seconds and CPU seconds of the median "
           "pair; CPU s below threads x wall s means the run did not get its cores)\n");
    json_t *root = json_object();
    json_object_set_new(root, "channel", json_integer((json_int_t)channel + 1));
    json_object_set_new(root, "threads", json_integer(threads));
    json_object_set_new(root, "integrators", arr);
    json_object_set_new(root, "load_average", bench_real(load));
    return root;
}

static json_t *bench_reals(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(a, bench_real(v[i]));
    return a;
}

json_t *bench_report_converge(const char *integrator, const bench_converge *cv, double target_k,
                              double limit_s, double load, double *worst_s)
{
    const bench_converge_point *a = &cv->pt[0], *b = &cv->pt[1];
    printf("\n6. Time to a converged image, %s (%llu photons per channel; load average %.2f)\n",
           integrator, (unsigned long long)cv->photons, load);
    printf("  noise: RMS over the objects' pixels of the per-pixel standard error of Tb; "
           "objects' pixels: truth object neither nothing nor the enclosure '%s' (the object "
           "whose box holds all others), %llu of %llu pixels\n",
           cv->enclosure, (unsigned long long)cv->object_pixels, (unsigned long long)cv->pixels);
    printf("  %-9s | %-28s | %-28s | %8s %11s %8s\n", "", "", "", "", "extrapolated", "");
    printf("  %-9s | J=%-4u %7s %8s %8s | J=%-4u %7s %8s %8s | %8s %11s %8s\n", "channel",
           (unsigned)a->estimates, "RMS K", "phot. s", "render s", (unsigned)b->estimates, "RMS K",
           "phot. s", "render s", "exponent", "s to target", "/ limit");
    json_t *chans = json_array();
    *worst_s = 0.0;
    for (size_t c = 0; c < cv->channels; c++) {
        double s = bench_converge_seconds(cv, c, target_k);
        double k = bench_converge_exponent(cv, c);
        *worst_s = s > *worst_s ? s : *worst_s;
        printf("  %5.3f THz | %-6s %7.4f %8.3f %8.3f | %-6s %7.4f %8.3f %8.3f | %8.2f %11.3f %6.2f "
               "x\n",
               cv->freq_thz[c], "", a->rms_k[c], a->s_photons[c], a->s_render[c], "", b->rms_k[c],
               b->s_photons[c], b->s_render[c], k, s, bench_ratio(s, limit_s));
        json_t *o = json_object();
        json_object_set_new(o, "frequency_thz", bench_real(cv->freq_thz[c]));
        json_object_set_new(o, "seconds_to_target", bench_real(s));
        json_object_set_new(o, "ratio_to_limit", bench_real(bench_ratio(s, limit_s)));
        json_object_set_new(o, "exponent", bench_real(k));
        json_array_append_new(chans, o);
    }
    printf("  seconds to %g K per channel extrapolated, not run: the J=%u run's render time x "
           "(RMS / %g K)^2, plus its photon phase (noise proportional to 1/sqrt(render "
           "time): exponent -0.5; the exponent column is the two runs' own)\n",
           target_k, (unsigned)b->estimates, target_k);
    json_t *jconf = json_null();
    if (cv->confirmed) {
        /* every channel run at the target: their runs replace the extrapolations */
        const bench_converge_point *p = &cv->confirm;
        *worst_s = 0.0;
        jconf = json_array();
        for (size_t w = 0; w < cv->channels; w++) {
            double confirmed = bench_converge_confirmed_seconds(cv, w, target_k);
            *worst_s = confirmed > *worst_s ? confirmed : *worst_s;
            if (cv->refined[w])
                printf("  run at the target: %5.3f THz alone with J=%u: RMS %.4f K, above the "
                       "target; the fit through the J=%u run and this one asked for J=%u, run "
                       "next\n",
                       cv->freq_thz[w], (unsigned)cv->first_estimates[w], cv->first_rms_k[w],
                       (unsigned)b->estimates, (unsigned)cv->confirm_estimates[w]);
            printf("  run at the target: %5.3f THz alone with J=%u: RMS %.4f K, photon phase "
                   "%.3f s, render %.3f s; to %g K %.3f s (its render time, x (RMS / %g K)^2 = "
                   "%.3f if that is above 1, plus its photon phase), %.2f x the limit\n",
                   cv->freq_thz[w], (unsigned)cv->confirm_estimates[w], p->rms_k[w],
                   p->s_photons[w], p->s_render[w], target_k, confirmed, target_k,
                   (p->rms_k[w] / target_k) * (p->rms_k[w] / target_k),
                   bench_ratio(confirmed, limit_s));
            json_t *o = json_object();
            json_object_set_new(o, "frequency_thz", bench_real(cv->freq_thz[w]));
            json_object_set_new(o, "estimates_per_pass", json_integer(cv->confirm_estimates[w]));
            json_object_set_new(o, "rms_stderr_k", bench_real(p->rms_k[w]));
            json_object_set_new(o, "seconds_photons", bench_real(p->s_photons[w]));
            json_object_set_new(o, "seconds_render", bench_real(p->s_render[w]));
            json_object_set_new(o, "seconds_to_target", bench_real(confirmed));
            json_object_set_new(o, "first_estimates_per_pass",
                                cv->refined[w] ? json_integer(cv->first_estimates[w])
                                               : json_null());
            json_object_set_new(o, "first_rms_stderr_k",
                                cv->refined[w] ? bench_real(cv->first_rms_k[w]) : json_null());
            double a_k2, floor2, need;
            if (bench_converge_floor(cv, w, target_k, &a_k2, &floor2, &need)) {
                printf("    through the J=%u run and this one, RMS^2 = %.4g K^2 / J + floor^2 ",
                       (unsigned)b->estimates, a_k2);
                if (floor2 < 0.0) /* no floor is a negative K: the two runs' noise, not one */
                    printf("with no floor (the fit's floor^2 < 0)");
                else
                    printf("with a floor %.4f K (what more estimates do not lower)", sqrt(floor2));
                if (need > 0.0)
                    printf(": %g K needs J = %.0f\n", target_k, need);
                else
                    printf(": %g K cannot be reached by more estimates\n", target_k);
                json_object_set_new(o, "floor_k", bench_real(copysign(sqrt(fabs(floor2)), floor2)));
                json_object_set_new(o, "estimates_for_target",
                                    need > 0.0 ? bench_real(need) : json_null());
            }
            json_array_append_new(jconf, o);
        }
    }
    printf("  worst channel %.3f s against %g s: %.2f x the limit%s\n", *worst_s, limit_s,
           bench_ratio(*worst_s, limit_s),
           cv->confirmed ? " (every channel run at the target)" : " (extrapolated)");
    json_t *runs = json_array();
    for (int k = 0; k < 2; k++) {
        const bench_converge_point *p = &cv->pt[k];
        json_t *o = json_object();
        json_object_set_new(o, "estimates_per_pass", json_integer(p->estimates));
        json_object_set_new(o, "passes", json_integer(1));
        json_object_set_new(o, "seconds_wall", bench_real(p->s_wall));
        json_object_set_new(o, "rms_stderr_k", bench_reals(p->rms_k, cv->channels));
        json_object_set_new(o, "seconds_photons", bench_reals(p->s_photons, cv->channels));
        json_object_set_new(o, "seconds_render", bench_reals(p->s_render, cv->channels));
        json_array_append_new(runs, o);
    }
    json_t *root = json_object();
    json_object_set_new(root, "integrator", json_string(integrator));
    json_object_set_new(root, "photons_per_channel", json_integer((json_int_t)cv->photons));
    json_object_set_new(root, "target_k", bench_real(target_k));
    json_object_set_new(root, "limit_seconds_per_channel", bench_real(limit_s));
    json_object_set_new(root, "enclosure", json_string(cv->enclosure));
    json_object_set_new(root, "pixels", json_integer((json_int_t)cv->pixels));
    json_object_set_new(root, "object_pixels", json_integer((json_int_t)cv->object_pixels));
    json_object_set_new(root, "method",
                        json_string("extrapolated: render time x (rms / target)^2 from the "
                                    "larger run, plus its photon phase; then every channel "
                                    "run alone at the estimates that predicts "
                                    "(runs_at_target), whose figures the worst is taken "
                                    "from"));
    json_object_set_new(root, "runs", runs);
    json_object_set_new(root, "runs_at_target", jconf);
    json_object_set_new(root, "channels", chans);
    json_object_set_new(root, "worst_seconds_to_target", bench_real(*worst_s));
    json_object_set_new(root, "worst_ratio_to_limit", bench_real(bench_ratio(*worst_s, limit_s)));
    json_object_set_new(root, "load_average", bench_real(load));
    return root;
}
