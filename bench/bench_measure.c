/* The benchmark's measurements: see bench_measure.h. */
#include "bench_measure.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <jansson.h>

#include "accel/accel.h"
#include "bench_probe.h"
#include "core/alloc.h"
#include "io/output.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "run/run.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "sensor/render.h"
#include "sensor/truth.h"
#include "thzmap/thzmap.h"

double bench_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double bench_cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static thz_status bench_load(const char *path, uint64_t photons, thz_scene **scene, thz_error *err)
{
    thz_status st = thz_scene_load(path, scene, err);
    if (st == THZ_OK && photons)
        (*scene)->photons.per_channel = photons;
    return st;
}

static void bench_images_fini(sensor_images *img, size_t n)
{
    if (!img)
        return;
    for (size_t i = 0; i < n; i++)
        sensor_images_fini(&img[i]);
    free(img);
}

/* Allocates every sensor's images (as run_simulate does: with the standard error). */
static thz_status bench_images_init(const thz_scene *s, sensor_images **out, thz_error *err)
{
    sensor_images *img = thz_calloc(s->n_sensors, sizeof *img);
    if (!img)
        return thz_error_set(err, THZ_ERR_NOMEM, "bench: out of memory");
    for (size_t i = 0; i < s->n_sensors; i++) {
        thz_status st = sensor_images_init(&img[i], s->sensors[i].columns, s->sensors[i].rows,
                                           s->n_channels, 1, err);
        if (st != THZ_OK) {
            bench_images_fini(img, s->n_sensors);
            return st;
        }
    }
    *out = img;
    return THZ_OK;
}

thz_status bench_measure_paper(const char *scene_path, uint64_t photons, int threads,
                               const char *outdir, bench_paper *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    accel *acc = NULL;
    sensor_images *img = NULL;
    output_stage *stage = NULL;
    double t_start = bench_now_s();
    thz_status st = bench_load(scene_path, photons, &s, err);
    if (st != THZ_OK)
        return st;
    double t = bench_now_s();
    out->s_load = t - t_start;
    out->photons_per_channel = s->photons.per_channel;
    out->channels = s->n_channels;
    if (s->n_sensors) {
        out->columns = s->sensors[0].columns;
        out->rows = s->sensors[0].rows;
        out->oversampling = s->sensors[0].oversampling;
    }

    st = accel_create(s, &acc, err);
    out->s_accel = bench_now_s() - t;
    if (st != THZ_OK)
        goto cleanup;

    render_options ro = {.threads = threads};
    t = bench_now_s();
    st = bench_images_init(s, &img, err);
    for (size_t i = 0; st == THZ_OK && i < s->n_sensors; i++)
        st = render_sensor_truth(s, acc, i, &img[i], &ro, err);
    out->s_render += bench_now_s() - t;

    /* as a run does: each channel's map in the memory of the one before */
    photon_map_pool pool = {0};
    photon_phase_options po = {.threads = threads, .pool = &pool};
    for (size_t c = 0; st == THZ_OK && c < s->n_channels; c++) {
        photon_map *map = NULL;
        photon_stats ps;
        memset(&ps, 0, sizeof ps);
        t = bench_now_s();
        st = photon_phase_run(s, acc, c, &po, &map, &ps, err);
        out->s_photons += bench_now_s() - t;
        if (st != THZ_OK)
            break;
        out->s_emission_table += ps.seconds_emission_table;
        out->s_tracing += ps.seconds_tracing;
        out->s_index += ps.seconds_index;
        out->fired += ps.fired;
        out->stored += ps.stored;
        out->rays += ps.rays;
        if (photon_map_bytes(map) > out->largest_map_bytes) {
            out->largest_map_bytes = photon_map_bytes(map);
            out->largest_map_stored = photon_map_count(map);
            /* the directory every render of the map builds (render_context.c), untimed:
             * part of the memory a stored photon costs */
            photon_map_directory *dir = NULL;
            st = photon_map_directory_create(map, threads, &dir, err);
            out->largest_map_directory_bytes = photon_map_directory_bytes(dir);
            photon_map_directory_destroy(dir);
            if (st != THZ_OK) {
                photon_map_destroy(map);
                break;
            }
        }
        t = bench_now_s();
        for (size_t i = 0; st == THZ_OK && i < s->n_sensors; i++)
            st = render_sensor_channel(s, acc, map, c, i, &img[i], &ro, NULL, err);
        out->s_render += bench_now_s() - t;
        photon_map_recycle(map, &pool);
    }
    photon_map_pool_fini(&pool);

    t = bench_now_s();
    if (st == THZ_OK)
        st = output_stage_create(outdir, &stage, err);
    for (size_t i = 0; st == THZ_OK && i < s->n_sensors; i++)
        st = output_write_sensor(output_stage_dir(stage), s, i, &img[i], threads, NULL, err);
    if (st == THZ_OK)
        st = output_stage_commit(stage, err);
    out->s_output = bench_now_s() - t;
    out->s_total = bench_now_s() - t_start;
cleanup:
    output_stage_destroy(stage);
    if (s)
        bench_images_fini(img, s->n_sensors);
    accel_destroy(acc);
    thz_scene_destroy(s);
    return st;
}

/* thz_run_settings.plan: the estimate `thzmap simulate` prints before the work. */
static void bench_e2e_plan(void *user, const thz_run_plan *plan)
{
    *(double *)user = plan->seconds_photons + plan->seconds_render;
}

thz_status bench_measure_e2e(const char *scene_path, const char *integrator, uint64_t photons,
                             double target_noise_k, int threads, const char *outdir, bench_e2e *out,
                             thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    double t0 = bench_now_s();
    thz_status st = thz_scene_load(scene_path, &s, err);
    if (st != THZ_OK)
        return st;
    double t1 = bench_now_s();
    /* through the public API, as `thzmap simulate` runs */
    thz_context *ctx = thz_context_create();
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.seconds_load = t1 - t0;
    settings.integrator = integrator;
    settings.photons_per_channel = photons;
    settings.target_noise_k = target_noise_k;
    settings.plan = bench_e2e_plan;
    settings.plan_user = &out->s_estimate;
    thz_run *run = NULL;
    if (!ctx)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_context_set_threads(ctx, threads);
    if (st == THZ_OK)
        st = thz_simulate(ctx, s, &settings, &run, err);
    if (st == THZ_OK)
        st = thz_run_write(ctx, run, outdir, NULL, err);
    double t2 = bench_now_s();
    thz_run_totals res;
    memset(&res, 0, sizeof res);
    if (st == THZ_OK)
        thz_run_get_totals(run, &res);
    thz_scene_info info;
    if (thz_scene_get_info(s, &info) == THZ_OK)
        snprintf(out->integrator, sizeof out->integrator, "%s",
                 integrator ? integrator : info.integrator);
    out->s_load = t1 - t0;
    out->s_run = t2 - t1;
    out->s_total = t2 - t0;
    out->fired = res.photons_fired;
    out->stored = res.photons_stored;
    out->max_passes = res.max_passes;
    out->worst_p95_stderr_k = res.worst_p95_stderr_k;
    if (st == THZ_OK) { /* the target the run took (summary.json; null: none) */
        const char *text = thz_run_summary_json(run);
        json_t *sum = text ? json_loads(text, 0, NULL) : NULL;
        out->target_noise_k = json_number_value(json_object_get(sum, "target_noise_k"));
        json_decref(sum);
    }
    thz_run_destroy(run);
    thz_context_destroy(ctx);
    thz_scene_destroy(s);
    return st;
}

thz_status bench_measure_probe(const char *scene_path, uint64_t rays, int threads, int repeats,
                               bench_probe_out *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    thz_status st = bench_load(scene_path, 0, &s, err);
    if (st != THZ_OK)
        return st;
    for (int k = 0; st == THZ_OK && k < (repeats > 0 ? repeats : 1); k++) {
        bench_probe_result r;
        st = bench_probe_run(s, rays, threads, &r, err);
        if (k == 0 || r.seconds < out->seconds) {
            out->rays = r.rays;
            out->hits = r.hits;
            out->seconds = r.seconds;
        }
    }
    thz_scene_destroy(s);
    return st;
}

/* A series' reference run (cfg->ref_photons photons; none when 0) and its CPU seconds
 * into *cpu_s, in its own memory (po_ref's pool); the scene's count is left at the
 * reference's. */
static thz_status bench_series_reference(thz_scene *s, const accel *acc, size_t channel,
                                         const bench_series_cfg *cfg,
                                         const photon_phase_options *po_ref, double *cpu_s,
                                         thz_error *err)
{
    *cpu_s = 0.0;
    if (!cfg->ref_photons)
        return THZ_OK;
    s->photons.per_channel = cfg->ref_photons;
    photon_map *m = NULL;
    photon_stats q;
    double c = bench_cpu_s();
    thz_status st = photon_phase_run(s, acc, channel, po_ref, &m, &q, err);
    *cpu_s = bench_cpu_s() - c;
    photon_map_recycle(m, po_ref->pool);
    return st;
}

thz_status bench_measure_series(const char *scene_path, const bench_series_cfg *cfg,
                                bench_series *out, thz_error *err)
{
    size_t channel = cfg->channel;
    const int threads = cfg->threads, repeats = cfg->repeats > 0 ? cfg->repeats : 1;
    memset(out, 0, sizeof *out);
    out->ref_photons = cfg->ref_photons;
    thz_scene *s = NULL;
    accel *acc = NULL;
    sensor_images *img = NULL;
    thz_status st = bench_load(scene_path, 0, &s, err);
    if (st != THZ_OK)
        return st;
    if (channel >= s->n_channels)
        channel = s->n_channels - 1;
    uint64_t triangles = 0;
    for (size_t i = 0; i < s->n_objects; i++)
        triangles += s->objects[i].mesh.n_triangles;
    st = accel_create(s, &acc, err);
    if (st == THZ_OK && cfg->render)
        st = bench_images_init(s, &img, err);
    /* Repeats build their maps in the memory of the map before, as a run's channels do
     * (photon_map_pool): a repeat is a run's steady state, not its first channel (only a
     * series' first run pays for new memory, and the median leaves it out). */
    photon_map_pool pool = {0};
    photon_phase_options po = {.threads = threads, .pool = &pool};
    /* The references run in memory of their own: in the point's pool, a reference's small
     * map would take the point's large array and shrink it (phase.c), and the point would
     * then pay for new memory (ef2613c: ~12 us a page here). */
    photon_map_pool ref_pool = {0};
    photon_phase_options po_ref = {.threads = threads, .pool = &ref_pool};
    render_options ro = {.threads = threads};
    for (int k = 0; st == THZ_OK && k < cfg->n && k < BENCH_MAX_POINTS; k++) {
        bench_point *p = &out->p[k];
        photon_map *map = NULL;
        photon_stats ps;
        memset(&ps, 0, sizeof ps);
        double wall[BENCH_MAX_RUNS], cpu[BENCH_MAX_RUNS], rel[BENCH_MAX_RUNS];
        photon_stats runs[BENCH_MAX_RUNS];
        int want = repeats;
        for (int rep = 0; st == THZ_OK && rep < want && rep < BENCH_MAX_RUNS; rep++) {
            photon_map *m = NULL;
            photon_map_recycle(map, &pool); /* one map at a time: the 100 M point's peak */
            map = NULL;
            double ref_before = 0.0, ref_after = 0.0;
            st = bench_series_reference(s, acc, channel, cfg, &po_ref, &ref_before, err);
            if (st != THZ_OK)
                break;
            s->photons.per_channel = cfg->photons[k];
            double t = bench_now_s(), c = bench_cpu_s();
            st = photon_phase_run(s, acc, channel, &po, &m, &runs[rep], err);
            wall[rep] = bench_now_s() - t;
            cpu[rep] = bench_cpu_s() - c;
            if (st != THZ_OK)
                break;
            map = m; /* every run's map is the same (deterministic): the last is kept */
            p->runs = rep + 1;
            st = bench_series_reference(s, acc, channel, cfg, &po_ref, &ref_after, err);
            if (st != THZ_OK)
                break;
            double ref = 0.5 * (ref_before + ref_after) / (double)cfg->ref_photons;
            rel[rep] =
                ref > 0.0 && runs[rep].fired > 0 ? cpu[rep] / (double)runs[rep].fired / ref : 0.0;
            if (rep == 0 && wall[0] > 0.0 && cfg->min_seconds > wall[0] * want) {
                double more = ceil(cfg->min_seconds / wall[0]);
                want = more < BENCH_MAX_RUNS ? (int)more : BENCH_MAX_RUNS;
                want -= want % 2 == 0; /* odd: one median run */
            }
        }
        if (st != THZ_OK)
            break;
        p->s_photons = bench_median(wall, p->runs);
        p->cpu_photons = bench_median(cpu, p->runs);
        p->cpu_vs_reference = cfg->ref_photons ? bench_median(rel, p->runs) : 0.0;
        p->s_photons_fastest = wall[0];
        p->cpu_photons_fastest = cpu[0];
        int median_run = 0;
        for (int rep = 0; rep < p->runs; rep++) {
            p->s_photons_fastest = fmin(p->s_photons_fastest, wall[rep]);
            p->cpu_photons_fastest = fmin(p->cpu_photons_fastest, cpu[rep]);
            if (fabs(wall[rep] - p->s_photons) < fabs(wall[median_run] - p->s_photons))
                median_run = rep;
        }
        ps = runs[median_run]; /* its stage split: the run nearest the median */
        p->photons = ps.fired;
        p->stored = ps.stored;
        p->rays = ps.rays;
        p->triangles = triangles;
        p->s_emission_table = ps.seconds_emission_table;
        p->s_tracing = ps.seconds_tracing;
        p->s_index = ps.seconds_index;
        for (int rep = 0; cfg->render && st == THZ_OK && rep < repeats; rep++) {
            uint64_t samples = 0, pixels = 0;
            double t = bench_now_s();
            for (size_t i = 0; st == THZ_OK && i < s->n_sensors; i++) {
                render_stats rs;
                st = render_sensor_channel(s, acc, map, channel, i, &img[i], &ro, &rs, err);
                samples += rs.samples;
                pixels += (uint64_t)s->sensors[i].columns * s->sensors[i].rows;
            }
            double dt = bench_now_s() - t;
            if (rep == 0 || dt < p->s_render) {
                p->s_render = dt;
                p->samples = samples;
                p->pixels = pixels;
            }
        }
        photon_map_recycle(map, &pool);
        for (int rep = 0; cfg->probe && st == THZ_OK && rep < repeats; rep++) {
            bench_probe_result r;
            st = bench_probe_run(s, ps.rays, threads, &r, err);
            if (rep == 0 || r.seconds < p->s_probe)
                p->s_probe = r.seconds;
        }
        out->n = k + 1;
    }
    photon_map_pool_fini(&pool);
    photon_map_pool_fini(&ref_pool);
    if (s)
        bench_images_fini(img, s->n_sensors);
    accel_destroy(acc);
    thz_scene_destroy(s);
    return st;
}

thz_status bench_measure_threads(const char *scene_path, size_t channel, uint64_t photons,
                                 int threads, int pairs, bench_threads *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    accel *acc = NULL;
    thz_status st = bench_load(scene_path, photons, &s, err);
    if (st != THZ_OK)
        return st;
    if (channel >= s->n_channels)
        channel = s->n_channels - 1;
    st = accel_create(s, &acc, err);
    photon_map_pool pool = {0};
    /* Rounds of four runs: the photon phase on 1 thread and on all, then the probe for its
     * rays on 1 and on all. Each speed-up's pairs alternate as before, and round k's
     * all-thread runs of both give the phase over the probe at one machine speed. */
    for (int k = 0; st == THZ_OK && k < pairs; k++) {
        double t[2], c[2];
        for (int side = 0; st == THZ_OK && side < 2; side++) {
            photon_phase_options po = {.threads = side == 0 ? 1 : threads, .pool = &pool};
            photon_map *m = NULL;
            photon_stats q;
            memset(&q, 0, sizeof q);
            double t0 = bench_now_s(), c0 = bench_cpu_s();
            st = photon_phase_run(s, acc, channel, &po, &m, &q, err);
            t[side] = bench_now_s() - t0;
            c[side] = bench_cpu_s() - c0;
            photon_map_recycle(m, &pool);
            out->photons = q.fired;
            out->rays = q.rays;
        }
        if (st != THZ_OK)
            break;
        bench_pairs_add(&out->phase, t[0], t[1], c[0], c[1]);
        for (int side = 0; st == THZ_OK && side < 2; side++) {
            bench_probe_result r;
            double c0 = bench_cpu_s();
            st = bench_probe_run(s, out->rays, side == 0 ? 1 : threads, &r, err);
            t[side] = r.seconds;
            c[side] = bench_cpu_s() - c0;
        }
        if (st == THZ_OK)
            bench_pairs_add(&out->probe, t[0], t[1], c[0], c[1]);
    }
    photon_map_pool_fini(&pool);
    accel_destroy(acc);
    thz_scene_destroy(s);
    return st;
}

thz_status bench_write_mesh_scene(const char *path, unsigned subdivisions, uint64_t photons,
                                  thz_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return thz_error_set(err, THZ_ERR_IO, "bench: cannot write %s", path);
    /* The teraeye room with four spheres in it: well-shaped triangles at every size. */
    fprintf(f,
            "{\n  \"format\": \"thzmap-scene/1\",\n  \"name\": \"mesh-s%u\",\n"
            "  \"channels\": [{\"frequency_thz\": 0.6, \"relative_width\": 0.01}],\n"
            "  \"materials\": {\"wall\": {\"reflectivity\": 0.1},\n"
            "                \"target\": {\"reflectivity\": 0.5}},\n"
            "  \"objects\": [\n"
            "    {\"name\": \"box\", \"type\": \"solid\", \"material\": \"wall\", "
            "\"temperature_k\": 293,\n"
            "     \"shape\": {\"type\": \"box\", \"size_m\": [1, 2, 1], \"inward\": true},\n"
            "     \"transform\": {\"translate_m\": [0, 0, 0.5]}}",
            subdivisions);
    const double xy[4][2] = {{-0.25, 0.3}, {0.25, 0.3}, {-0.25, -0.3}, {0.25, -0.3}};
    for (int i = 0; i < 4; i++)
        fprintf(f,
                ",\n    {\"name\": \"sphere-%d\", \"type\": \"solid\", \"material\": \"target\", "
                "\"temperature_k\": %d,\n     \"shape\": {\"type\": \"sphere\", \"radius_m\": 0.2, "
                "\"subdivisions\": %u},\n     \"transform\": {\"translate_m\": [%g, %g, 0.5]}}",
                i, 300 + 5 * i, subdivisions, xy[i][0], xy[i][1]);
    fprintf(f,
            "\n  ],\n  \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.95, 0.5], "
            "\"look_at_m\": [0, 0, 0.5], \"fov_deg\": 60, \"resolution\": [32, 32]}],\n"
            "  \"photons\": {\"per_channel\": %llu, \"seed\": 1}\n}\n",
            (unsigned long long)photons);
    if (fclose(f) != 0)
        return thz_error_set(err, THZ_ERR_IO, "bench: cannot write %s", path);
    return THZ_OK;
}
