/* The up-front time estimate of a run (run_estimate.h). */
#include "run/run_estimate.h"

#include <math.h>
#include <string.h>

#include "core/clock.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "run/run.h"
#include "run/run_noise.h"
#include "sensor/images.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"
#include "sensor/truth.h"

/* A merge's time per photon against the photon phase's index build per photon: the copy
 * of the records and their index built again, over arrays far larger than a pass's.
 * Measured on the walkthrough's room with photon-map and no count (2 channels, 1 M
 * photons a pass, 2 threads, an idle machine): to the memory stop at 202 and 204 passes
 * the run took 205 s, which a ratio of 1.8 estimated; at 182 and 183 passes 211 s, a
 * ratio of 2.5 (the machine's speed moves by 10-15 % from hour to hour); without the
 * merges the estimate said 68 s. */
#define RUN_ESTIMATE_MERGE_PER_INDEX 2.2

/* Samples one pass of sensor s renders: pixels x oversampling^2. */
static double estimate_samples(const thz_sensor *s)
{
    return (double)s->columns * s->rows * s->oversampling * s->oversampling;
}

/* Estimates one pass of sensor s gives, the noise's unit: samples x paths (path) or x
 * gather rays (final-gather). */
static double estimate_estimates(const thz_scene *scene, const thz_sensor *s)
{
    return estimate_samples(s) * render_estimates_per_pass(scene);
}

static uint64_t estimate_min(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

void run_estimate_pilot(const thz_scene *scene, const thz_sensor *sensor, thz_scene *pilot,
                        thz_sensor *cam)
{
    *cam = *sensor;
    /* no larger than the run: a 2 x 2 camera's pilot at 32 x 32 took 1.4 s before a
     * render of 5 ms (a cavity of mirrors, paths of 10 000 hits) */
    cam->columns = (uint32_t)estimate_min(cam->columns, RUN_PILOT_SIDE);
    cam->rows = (uint32_t)estimate_min(cam->rows, RUN_PILOT_SIDE);
    cam->oversampling = 1;
    *pilot = *scene;
    pilot->sensors = cam;
    pilot->n_sensors = 1;
    pilot->n_warnings = 0;
    pilot->photons.per_channel = estimate_min(scene->photons.per_channel, RUN_PILOT_PHOTONS);
    /* at least 2: one a sample gives each pixel one estimate, whose spread (the noise a
     * target's passes are counted from) is unknown; the run then renders at least two
     * passes (run_passes.c) */
    thz_render_settings *r = &pilot->render;
    r->paths_per_sample = (uint32_t)estimate_min(r->paths_per_sample, RUN_PILOT_ESTIMATES);
    r->gather_rays = (uint32_t)estimate_min(r->gather_rays, RUN_PILOT_ESTIMATES);
    r->paths_per_sample = r->paths_per_sample < 2 ? 2 : r->paths_per_sample;
    r->gather_rays = r->gather_rays < 2 ? 2 : r->gather_rays;
}

/* The pilot of channel c: its photon phase's time for the run's photons (0 without
 * photons), its render time per sample (at the run's paths or gather rays), and the 95th
 * percentile of its pixels' standard error of Tb_c (K). */
static thz_status estimate_channel(const run_estimate_input *in, thz_scene *pilot, thz_sensor *cam,
                                   size_t c, double *seconds_photons, double *merge_per_photon,
                                   double *per_sample, double *p95_k, thz_error *err)
{
    const thz_scene *scene = in->scene;
    bool photons = render_integrator_needs_photons(scene->render.integrator);
    photon_map *map = NULL;
    thz_status st = THZ_OK;
    *seconds_photons = 0.0;
    *merge_per_photon = 0.0;
    if (photons) {
        const uint64_t pilot_photons = pilot->photons.per_channel;
        photon_phase_options po = {.threads = in->threads,
                                   .reference_temperature_k =
                                       scene->render.integrator == INTEGRATOR_FINAL_GATHER
                                           ? scene_reference_temperature_k(scene, c)
                                           : 0.0,
                                   .reach = in->reach};
        photon_stats ps;
        st = photon_phase_run(pilot, in->accel, c, &po, &map, &ps, err);
        if (st != THZ_OK)
            return st;
        /* The emission table is built once per channel, whatever the photon count: timed
         * per photon with the pilot's, it made a final-gather run's estimate 4 x its time
         * (its frequency-dependent table 32 ms against 12 ms for 20 000 photons). The back
         * sides' reach shares are the run's, computed before (photon_phase_prepare). */
        double per_photon = (ps.seconds_tracing + ps.seconds_index) / (double)pilot_photons;
        *seconds_photons =
            ps.seconds_emission_table + per_photon * (double)scene->photons.per_channel;
        /* a merge of photon passes copies the records and builds their index again */
        *merge_per_photon = RUN_ESTIMATE_MERGE_PER_INDEX * ps.seconds_index / (double)pilot_photons;
    }
    sensor_images img;
    render_accum acc;
    memset(&acc, 0, sizeof acc);
    st = sensor_images_init(&img, cam->columns, cam->rows, scene->n_channels, 1, err);
    if (st == THZ_OK)
        st = render_accum_init(&acc, (size_t)cam->columns * cam->rows, err);
    render_options ro = {.threads = in->threads};
    render_stats rst;
    if (st == THZ_OK)
        st = render_sensor_truth(pilot, in->accel, 0, &img, &ro, err);
    /* pass 0 warms up (threads, caches, the channel's tables); it is then timed afresh
     * (photon-map has one pass only), and its noise taken */
    if (st == THZ_OK)
        st = render_sensor_channel_pass(pilot, in->accel, map, c, 0, 0, &acc, &ro, &rst, err);
    if (st == THZ_OK) {
        render_accum_fini(&acc);
        st = render_accum_init(&acc, (size_t)cam->columns * cam->rows, err);
    }
    double t0 = thz_now_s();
    if (st == THZ_OK)
        st = render_sensor_channel_pass(pilot, in->accel, map, c, 0, 0, &acc, &ro, &rst, err);
    /* per path or gather ray where the pilot casts fewer than the run (RUN_PILOT_ESTIMATES):
     * it also counts the camera ray and first hit that a sample's paths share, so a run
     * of many more is estimated high by that share (a 32 x 24 sensor in a box: about 14
     * paths' worth against the pilot's 64; 1.3 x measured for 1 000 and 30 000 paths) */
    *per_sample = (thz_now_s() - t0) / estimate_samples(cam) * render_estimates_per_pass(scene) /
                  render_estimates_per_pass(pilot);
    if (st == THZ_OK)
        st = render_accum_write(pilot, c, 0, &acc, &img, err);
    run_noise noise = {0};
    if (st == THZ_OK)
        st = run_noise_channel(&img, 1, c, scene->channels[c].center_hz, 0, &noise, NULL, err);
    *p95_k = noise.p95_k;
    render_accum_fini(&acc);
    sensor_images_fini(&img);
    photon_map_destroy(map);
    return st;
}

/* photon-map's passes of channel c: their count capped at what the memory they may hold
 * allows (run_photon_passes stops there), and the bytes they then hold. */
static thz_status estimate_photon_passes(const run_estimate_input *in, size_t c, uint32_t *passes,
                                         run_estimate *out, thz_error *err)
{
    uint64_t map_bytes = 0; /* one pass's map (T0 = 0: the paper's map) */
    thz_status st =
        photon_phase_estimate_bytes(in->scene, in->accel, c, 0.0, in->reach, &map_bytes, err);
    if (st != THZ_OK)
        return st;
    double per_pass = RUN_PASSES_MAP_FACTOR * (double)map_bytes;
    double limit = run_passes_memory_limit_bytes();
    if (limit > 0.0 && per_pass * (double)*passes > limit) {
        *passes = (uint32_t)fmax(floor(limit / per_pass), 1.0);
        out->memory_stop = true;
    }
    double held = per_pass * (double)*passes;
    if (held > (double)out->passes_bytes)
        out->passes_bytes = (uint64_t)held;
    return THZ_OK;
}

thz_status run_estimate_time(const run_estimate_input *in, run_estimate *out, thz_error *err)
{
    const thz_scene *scene = in->scene;
    *out = (run_estimate){.passes = 1};
    /* the pilot scene: the same objects, K photons and one small sensor */
    thz_scene pilot;
    thz_sensor cam;
    run_estimate_pilot(scene, &scene->sensors[in->selected[0]], &pilot, &cam);
    bool paper_map = scene->render.integrator == INTEGRATOR_PHOTON_MAP;
    /* photon-map towards a target: with RUN_PILOT_PHOTONS the disks were widened to the
     * k-th nearest photon, where the noise hardly falls with more photons, and 1/sqrt
     * from there was far short: the spec's example room with photon-map, no count
     * (2 channels, 16 x 12 pixels) was estimated at 111 passes of 10^6 photons and 78 s;
     * 4 x 10^6 photons' noise asks for about 1 700 passes, and the run stopped at the
     * memory after 196, in 431 s. A pass's photons put the pilot past the widening. Its
     * pixels are larger than the sensor's (RUN_PILOT_SIDE), so their disks hold more
     * photons: the noise, 1/sqrt of a disk's photons, scales with the pixel pitch. */
    double pitch_ratio = 1.0;
    if (paper_map && in->target_noise_k > 0.0) {
        uint64_t k = scene->photons.per_channel;
        pilot.photons.per_channel = k < RUN_PILOT_PHOTONS_PASSES ? k : RUN_PILOT_PHOTONS_PASSES;
        pitch_ratio = (double)scene->sensors[in->selected[0]].columns / (double)cam.columns;
    }
    double samples = 0.0, estimates = 0.0, pixels = 0.0;
    for (size_t i = 0; i < in->n_selected; i++) {
        const thz_sensor *s = &scene->sensors[in->selected[i]];
        samples += estimate_samples(s);
        estimates += estimate_estimates(scene, s);
        pixels += (double)s->columns * s->rows;
    }
    const double per_pixel = estimates / pixels; /* estimates per pixel in one pass */
    /* the pilot's, with its paths or gather rays (RUN_PILOT_ESTIMATES at most) */
    const double pilot_per_pixel =
        estimate_estimates(&pilot, &cam) / (double)(cam.columns * cam.rows);
    /* With a noise target every channel gets its own pilot: their noise differs (the
     * paper's scene, final-gather's pilot: p95 0.24 K at 0.2 THz, 0.14-0.16 K at 1.0-1.2
     * THz), and channel 0's for all made `path`'s estimate twice its run (6.9 s against
     * 3.3 s; now 4.6 s against 3.5 s). Without a target, channel 0's stands for all. */
    size_t piloted = in->target_noise_k > 0.0 ? scene->n_channels : 1;
    for (size_t c = 0; c < piloted; c++) {
        double photons_s, merge_per_photon, per_sample, p95_k;
        thz_status st = estimate_channel(in, &pilot, &cam, c, &photons_s, &merge_per_photon,
                                         &per_sample, &p95_k, err);
        if (st != THZ_OK)
            return st;
        uint32_t passes_c = 1;
        p95_k *= pitch_ratio;
        if (in->target_noise_k > 0.0 && p95_k > in->target_noise_k) {
            /* the standard error falls as 1/sqrt(estimates) (photon-map: of photons, the
             * same law; final-gather's map noise does not fall with its gather rays, so a
             * run of more than the pilot's is estimated at too few passes where it
             * dominates) */
            double need = pilot_per_pixel * pow(p95_k / in->target_noise_k, 2.0);
            double p = ceil(paper_map ? need / pilot_per_pixel * (double)pilot.photons.per_channel /
                                            (double)scene->photons.per_channel
                                      : need / per_pixel);
            passes_c = (uint32_t)fmin(fmax(p, 1.0), 100000.0);
            if (paper_map) {
                st = estimate_photon_passes(in, c, &passes_c, out, err);
                if (st != THZ_OK)
                    return st;
            }
        }
        double channels = piloted == 1 ? (double)scene->n_channels : 1.0;
        out->passes = passes_c > out->passes ? passes_c : out->passes;
        /* photon-map's passes render at checks only (run_photon_passes) */
        double renders = paper_map ? (double)run_photon_checks(passes_c) : (double)passes_c;
        out->seconds_render += per_sample * samples * renders * channels;
        double merges = paper_map ? merge_per_photon * (double)scene->photons.per_channel *
                                        run_photon_merged_passes(passes_c)
                                  : 0.0;
        out->seconds_photons +=
            ((paper_map ? photons_s * passes_c : photons_s) + merges) * channels;
    }
    return THZ_OK;
}
