/* The integrators' measurements: see bench_render.h. */
#include "bench_render.h"
#include "bench_measure.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <jansson.h>

#include "accel/accel.h"
#include "core/alloc.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "scene/scene.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"
#include "thzmap/thzmap.h"

/* Sets the integrator by name and its estimates per pass (0: keep the scene's); one pass
 * per channel unless told otherwise (no noise target from the scene). */
static thz_status bench_set_integrator(thz_scene *s, const char *name, uint32_t estimates,
                                       thz_error *err)
{
    if (!render_integrator_parse(name, &s->render.integrator))
        return thz_error_set(err, THZ_ERR_INPUT, "bench: unknown integrator '%s'", name);
    if (estimates && s->render.integrator == INTEGRATOR_PATH) {
        s->render.paths_per_sample = estimates;
        s->render.paths_per_sample_given = true;
    } else if (estimates) {
        s->render.gather_rays = estimates;
    }
    s->render.target_noise_k = 0.0;
    s->render.max_seconds = 0.0;
    return THZ_OK;
}

/* --small: every sensor `columns` wide (rows in proportion), one sample per pixel. */
static void bench_shrink_sensors(thz_scene *s, uint32_t columns)
{
    for (size_t i = 0; columns && i < s->n_sensors; i++) {
        thz_sensor *se = &s->sensors[i];
        uint64_t rows = (uint64_t)se->rows * columns / se->columns;
        se->rows = rows > 0 ? (uint32_t)rows : 1;
        se->columns = columns;
        se->oversampling = 1;
    }
}

/* ---- 2-thread speed-ups ------------------------------------------------------------- */

/* One timed run: `renders` times the channel's render context and its passes for every
 * sensor, into fresh pixel statistics. */
static thz_status bench_render_run(const thz_scene *s, const accel *acc, const photon_map *map,
                                   const bench_speedup_config *cfg, int threads, uint64_t *samples,
                                   thz_error *err)
{
    render_options ro = {.threads = threads};
    thz_status st = THZ_OK;
    *samples = 0;
    for (uint32_t r = 0; st == THZ_OK && r < cfg->renders; r++) {
        render_context *ctx = NULL;
        st = render_context_create(s, acc, map, cfg->channel, &ro, &ctx, err);
        for (size_t i = 0; st == THZ_OK && i < s->n_sensors; i++) {
            render_accum ra;
            st = render_accum_init(&ra, (size_t)s->sensors[i].columns * s->sensors[i].rows, err);
            for (uint32_t p = 0; st == THZ_OK && p < cfg->passes; p++) {
                render_stats rs;
                st = render_context_pass(ctx, i, p, &ra, &ro, &rs, err);
                *samples += rs.samples;
            }
            render_accum_fini(&ra);
        }
        render_context_destroy(ctx);
    }
    return st;
}

thz_status bench_measure_speedup(const char *scene_path, const bench_speedup_config *cfg,
                                 bench_speedup *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    accel *acc = NULL;
    photon_map *map = NULL;
    thz_status st = thz_scene_load(scene_path, &s, err);
    if (st != THZ_OK)
        return st;
    bench_shrink_sensors(s, cfg->sensor_columns);
    st = bench_set_integrator(s, cfg->integrator, cfg->estimates, err);
    if (st == THZ_OK && cfg->channel >= s->n_channels)
        st = thz_error_set(err, THZ_ERR_INPUT, "bench: the scene has no channel %zu",
                           cfg->channel + 1);
    if (st == THZ_OK)
        st = accel_create(s, &acc, err);
    if (st == THZ_OK && render_integrator_needs_photons(s->render.integrator)) {
        s->photons.per_channel = cfg->photons;
        photon_phase_options po = {.threads = cfg->threads};
        if (s->render.integrator == INTEGRATOR_FINAL_GATHER)
            po.reference_temperature_k = scene_reference_temperature_k(s, cfg->channel);
        photon_stats ps;
        memset(&ps, 0, sizeof ps);
        double t = bench_now_s();
        st = photon_phase_run(s, acc, cfg->channel, &po, &map, &ps, err);
        out->s_map = bench_now_s() - t;
        out->photons = st == THZ_OK ? ps.fired : 0;
        out->stored = st == THZ_OK ? ps.stored : 0;
    }
    out->estimates = render_estimates_per_pass(s);
    out->passes = cfg->passes;
    out->renders = cfg->renders;
    /* alternating pairs (bench_pairs.h) */
    double t1 = 0.0, c1 = 0.0;
    for (int k = 0; st == THZ_OK && k < 2 * (cfg->pairs > 0 ? cfg->pairs : 1); k++) {
        int threads = k % 2 == 0 ? 1 : cfg->threads;
        double t = bench_now_s(), c = bench_cpu_s();
        st = bench_render_run(s, acc, map, cfg, threads, &out->samples, err);
        double dt = bench_now_s() - t, dc = bench_cpu_s() - c;
        if (k % 2 == 0) {
            t1 = dt;
            c1 = dc;
        } else if (st == THZ_OK) {
            bench_pairs_add(&out->runs, t1, dt, c1, dc);
        }
    }
    photon_map_destroy(map);
    accel_destroy(acc);
    thz_scene_destroy(s);
    return st;
}

/* ---- time to a converged image ------------------------------------------------------- */

/* The enclosure: the object whose bounding box holds every other object's and every
 * sensor's position (the largest such box if several); -1 when there is none. */
static long bench_enclosure(const thz_scene *s)
{
    long best = -1;
    double best_volume = 0.0;
    size_t n = thz_scene_object_count(s), ns = thz_scene_sensor_count(s);
    for (size_t i = 0; i < n; i++) {
        thz_object_info a;
        thz_scene_object(s, i, &a);
        bool holds = true;
        for (size_t j = 0; holds && j < n; j++) {
            thz_object_info b;
            thz_scene_object(s, j, &b);
            for (int d = 0; d < 3; d++)
                holds = holds && b.bbox_min_m[d] >= a.bbox_min_m[d] &&
                        b.bbox_max_m[d] <= a.bbox_max_m[d];
        }
        for (size_t j = 0; holds && j < ns; j++) {
            thz_sensor_info si;
            thz_scene_sensor(s, j, &si);
            for (int d = 0; d < 3; d++)
                holds = holds && si.position_m[d] >= a.bbox_min_m[d] &&
                        si.position_m[d] <= a.bbox_max_m[d];
        }
        double volume = (a.bbox_max_m[0] - a.bbox_min_m[0]) * (a.bbox_max_m[1] - a.bbox_min_m[1]) *
                        (a.bbox_max_m[2] - a.bbox_min_m[2]);
        if (holds && (best < 0 || volume > best_volume)) {
            best = (long)i;
            best_volume = volume;
        }
    }
    return best;
}

/* Per channel the RMS over the objects' pixels of the standard error of Tb, from the
 * run's images; the pixel counts into out. */
static thz_status bench_objects_rms(const thz_scene *s, const thz_run *run, long enclosure,
                                    bench_converge *out, bench_converge_point *pt, thz_error *err)
{
    size_t nc = out->channels;
    double sum[BENCH_MAX_CHANNELS] = {0}, freq_hz[BENCH_MAX_CHANNELS] = {0};
    for (size_t c = 0; c < nc; c++) {
        thz_channel_info ci;
        thz_scene_channel(s, c, &ci);
        freq_hz[c] = ci.frequency_hz;
    }
    uint64_t pixels = 0, objects = 0;
    for (size_t i = 0; i < thz_run_image_count(run); i++) {
        const thz_image *im = thz_run_image(run, i);
        size_t np = (size_t)thz_image_columns(im) * thz_image_rows(im);
        const float *tb = thz_image_plane(im, THZ_PLANE_BRIGHTNESS_TEMPERATURE, NULL);
        const float *se = thz_image_plane(im, THZ_PLANE_RADIANCE_STDERR, NULL);
        const float *id = thz_image_plane(im, THZ_PLANE_OBJECT_ID, NULL);
        if (!tb || !se || !id)
            return thz_error_set(err, THZ_ERR_INTERNAL,
                                 "bench: sensor '%s' has no standard error or truth plane",
                                 thz_image_sensor_name(im));
        for (size_t p = 0; p < np; p++) {
            pixels++;
            long obj = (long)id[p];
            if (obj < 0 || obj == enclosure)
                continue;
            objects++;
            for (size_t c = 0; c < nc; c++) {
                double k = thz_brightness_temperature_stderr(freq_hz[c], (double)tb[c * np + p],
                                                             (double)se[c * np + p]);
                sum[c] += k * k;
            }
        }
    }
    if (objects == 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "bench: no sensor sees an object other than "
                             "the enclosure");
    for (size_t c = 0; c < nc; c++)
        pt->rms_k[c] = sqrt(sum[c] / (double)objects);
    out->pixels = pixels;
    out->object_pixels = objects;
    return THZ_OK;
}

/* Per channel the photon-phase and render seconds of the run's summary.json. */
static thz_status bench_channel_seconds(const thz_run *run, size_t nc, bench_converge_point *pt,
                                        thz_error *err)
{
    const char *text = thz_run_summary_json(run);
    json_t *root = text ? json_loads(text, 0, NULL) : NULL;
    json_t *ch = json_object_get(root, "channels");
    thz_status st = THZ_OK;
    if (!json_is_array(ch) || json_array_size(ch) != nc)
        st = thz_error_set(err, THZ_ERR_INTERNAL, "bench: the run's summary has no channels");
    for (size_t c = 0; st == THZ_OK && c < nc; c++) {
        json_t *o = json_array_get(ch, c);
        pt->s_photons[c] = json_number_value(json_object_get(o, "photon_phase_s"));
        pt->s_render[c] = json_number_value(json_object_get(o, "render_s"));
    }
    json_decref(root);
    return st;
}

/* One run of the scene through thz_simulate with `estimates` per sample: its noise and
 * its channels' seconds into pt. */
static thz_status bench_converge_run(thz_context *ctx, thz_scene *s, const char *integrator,
                                     uint32_t estimates, uint64_t photons, long enclosure,
                                     bench_converge *out, bench_converge_point *pt, thz_error *err)
{
    thz_status st = bench_set_integrator(s, integrator, estimates, err);
    if (st != THZ_OK)
        return st;
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.integrator = integrator;
    if (render_integrator_needs_photons(s->render.integrator))
        settings.photons_per_channel = photons ? photons : s->photons.per_channel;
    thz_run *run = NULL;
    double t = bench_now_s();
    st = thz_simulate(ctx, s, &settings, &run, err);
    pt->s_wall = bench_now_s() - t;
    pt->estimates = render_estimates_per_pass(s);
    if (st == THZ_OK)
        st = bench_objects_rms(s, run, enclosure, out, pt, err);
    if (st == THZ_OK)
        st = bench_channel_seconds(run, s->n_channels, pt, err);
    out->photons = settings.photons_per_channel;
    thz_run_destroy(run);
    return st;
}

/* Swaps channels a and b of the scene, with the sensors' per-channel NETDs. */
static void bench_swap_channels(thz_scene *s, size_t a, size_t b)
{
    thz_channel t = s->channels[a];
    s->channels[a] = s->channels[b];
    s->channels[b] = t;
    for (size_t i = 0; i < s->n_sensors; i++) {
        double *netd = s->sensors[i].noise.netd_k;
        if (netd) {
            double d = netd[a];
            netd[a] = netd[b];
            netd[b] = d;
        }
    }
}

/* A run at the target: channel w alone (moved to the front, the others hidden from the
 * run, then put back) with j estimates per sample, kept at index w of out->confirm. */
static thz_status bench_converge_confirm_at(thz_context *ctx, thz_scene *s, const char *integrator,
                                            uint64_t photons, long enclosure, size_t w, uint32_t j,
                                            bench_converge *out, thz_error *err)
{
    size_t n = s->n_channels;
    bench_converge_point pt;
    memset(&pt, 0, sizeof pt);
    bench_converge probe = *out; /* pixel counts, which the one channel does not change */
    probe.channels = 1;
    bench_swap_channels(s, 0, w);
    s->n_channels = 1;
    thz_status st = bench_converge_run(ctx, s, integrator, j, photons, enclosure, &probe, &pt, err);
    s->n_channels = n;
    bench_swap_channels(s, 0, w);
    if (st != THZ_OK)
        return st;
    out->confirm.rms_k[w] = pt.rms_k[0];
    out->confirm.s_photons[w] = pt.s_photons[0];
    out->confirm.s_render[w] = pt.s_render[0];
    out->confirm_estimates[w] = pt.estimates;
    return THZ_OK;
}

/* Every channel run with the estimates the larger run says it needs (the worst channel by
 * extrapolation need not be the worst run: final-gather's extrapolation ignores the
 * photon map's floor). Where a run misses the target and the fit through the two
 * (RMS^2 = a / J + floor^2) says more estimates reach it, once more with the fit's J:
 * scaling the miss by (RMS / target)^2 ignores the floor, so it promised less time than a
 * run takes (final-gather, 0.2 THz: 58 gather rays gave 0.0534 K, scaled to 66 where the
 * fit asks for 71). */
static thz_status bench_converge_confirm(thz_context *ctx, thz_scene *s, const char *integrator,
                                         uint64_t photons, long enclosure, double target_k,
                                         uint32_t max_confirm, bench_converge *out, thz_error *err)
{
    thz_status st = THZ_OK;
    out->confirm = (bench_converge_point){0};
    for (size_t w = 0; st == THZ_OK && w < s->n_channels; w++) {
        double scale = out->pt[1].rms_k[w] / target_k;
        double need = ceil((double)out->pt[1].estimates * scale * scale);
        uint32_t j = need > (double)max_confirm ? max_confirm : (uint32_t)need;
        j = j < 2 ? 2 : j;
        st = bench_converge_confirm_at(ctx, s, integrator, photons, enclosure, w, j, out, err);
        double a_k2, floor2, fit_j;
        if (st == THZ_OK && out->confirm.rms_k[w] > target_k &&
            bench_converge_floor(out, w, target_k, &a_k2, &floor2, &fit_j) && fit_j > (double)j &&
            fit_j <= (double)max_confirm) {
            out->first_estimates[w] = out->confirm_estimates[w];
            out->first_rms_k[w] = out->confirm.rms_k[w];
            out->refined[w] = true;
            st = bench_converge_confirm_at(ctx, s, integrator, photons, enclosure, w,
                                           (uint32_t)fit_j, out, err);
        }
    }
    out->confirmed = st == THZ_OK;
    return st;
}

thz_status bench_measure_converge(const char *scene_path, const char *integrator, uint64_t photons,
                                  const uint32_t estimates[2], uint32_t sensor_columns, int threads,
                                  double target_k, uint32_t max_confirm, bench_converge *out,
                                  thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_scene *s = NULL;
    thz_context *ctx = thz_context_create();
    if (!ctx)
        return thz_error_set(err, THZ_ERR_NOMEM, "bench: out of memory");
    thz_context_set_threads(ctx, threads);
    thz_status st = thz_scene_load(scene_path, &s, err);
    if (st == THZ_OK && thz_scene_channel_count(s) > BENCH_MAX_CHANNELS)
        st = thz_error_set(err, THZ_ERR_INPUT, "bench: more than %d channels", BENCH_MAX_CHANNELS);
    long enclosure = -1;
    if (st == THZ_OK) {
        bench_shrink_sensors(s, sensor_columns);
        out->channels = thz_scene_channel_count(s);
        for (size_t c = 0; c < out->channels; c++) {
            thz_channel_info ci;
            thz_scene_channel(s, c, &ci);
            out->freq_thz[c] = ci.frequency_thz;
        }
        enclosure = bench_enclosure(s);
        if (enclosure >= 0) {
            thz_object_info oi;
            thz_scene_object(s, (size_t)enclosure, &oi);
            snprintf(out->enclosure, sizeof out->enclosure, "%s", oi.name);
        }
    }
    for (int k = 0; st == THZ_OK && k < 2; k++)
        st = bench_converge_run(ctx, s, integrator, estimates[k], photons, enclosure, out,
                                &out->pt[k], err);
    if (st == THZ_OK && max_confirm > 0)
        st = bench_converge_confirm(ctx, s, integrator, photons, enclosure, target_k, max_confirm,
                                    out, err);
    thz_scene_destroy(s);
    thz_context_destroy(ctx);
    return st;
}

/* Channel c of run p scaled to target_k: its render time x (rms / target_k)^2 (noise
 * proportional to 1/sqrt(render time)) plus its photon phase; with `up_only`, a run below
 * the target keeps its own time (no credit for the part it need not have run). */
static double bench_point_seconds(const bench_converge_point *p, size_t c, double target_k,
                                  bool up_only)
{
    double scale = p->rms_k[c] / target_k;
    double factor = up_only && scale < 1.0 ? 1.0 : scale * scale;
    return p->s_photons[c] + p->s_render[c] * factor;
}

double bench_converge_seconds(const bench_converge *cv, size_t c, double target_k)
{
    return bench_point_seconds(&cv->pt[1], c, target_k, false);
}

double bench_converge_confirmed_seconds(const bench_converge *cv, size_t c, double target_k)
{
    return cv->confirm_estimates[c] ? bench_point_seconds(&cv->confirm, c, target_k, true) : NAN;
}

bool bench_converge_floor(const bench_converge *cv, size_t c, double target_k, double *a_k2,
                          double *floor2, double *need)
{
    size_t w = c;
    const bench_converge_point *b = &cv->pt[1], *p = &cv->confirm;
    double j1 = (double)b->estimates, j2 = (double)cv->confirm_estimates[c];
    if (!cv->confirm_estimates[c] || !(j2 > j1))
        return false;
    double v1 = b->rms_k[w] * b->rms_k[w], v2 = p->rms_k[w] * p->rms_k[w];
    *a_k2 = (v1 - v2) / (1.0 / j1 - 1.0 / j2);
    *floor2 = v2 - *a_k2 / j2;
    double room = target_k * target_k - *floor2;
    *need = room > 0.0 && *a_k2 > 0.0 ? ceil(*a_k2 / room) : 0.0;
    return true;
}

double bench_converge_exponent(const bench_converge *cv, size_t c)
{
    const bench_converge_point *a = &cv->pt[0], *b = &cv->pt[1];
    if (!(a->rms_k[c] > 0.0 && b->rms_k[c] > 0.0 && a->s_render[c] > 0.0 &&
          b->s_render[c] > a->s_render[c]))
        return 0.0;
    return log(b->rms_k[c] / a->rms_k[c]) / log(b->s_render[c] / a->s_render[c]);
}
