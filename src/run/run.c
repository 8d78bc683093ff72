/* Orchestration of simulate and render runs: memory check (run_memory.c), photon
 * phase, rendering, outputs through the atomic staging directory. */
#include "run/run.h"

#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "core/alloc.h"
#include "core/clock.h"
#include "core/path.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "photon/photon_stats.h"
#include "run/run_estimate.h"
#include "run/run_noise.h"
#include "physics/planck.h"
#include "sensor/images.h"
#include "sensor/measure.h"
#include "sensor/render.h"
#include "sensor/render_tiles.h"
#include "sensor/truth.h"

/* A noise target stops here at the latest (with a run warning). */
#define RUN_MAX_PASSES 100000u
/* final-gather stops at its photon map's floor from this pass on (run_at_map_floor): the
 * floor's estimate from one pass of 32 gather rays was within 2 % of its value after 11
 * on the paper's scene. */
#define RUN_FLOOR_PASSES 2u

thz_status run_check_options(const run_options *opt, thz_error *err)
{
    if (opt->target_noise_k < 0.0 || !isfinite(opt->target_noise_k))
        return thz_error_set(err, THZ_ERR_INPUT, "the noise target must be > 0 K, got %g K",
                             opt->target_noise_k);
    if (opt->max_seconds < 0.0 || !isfinite(opt->max_seconds))
        return thz_error_set(err, THZ_ERR_INPUT, "the time limit must be > 0 s, got %g s",
                             opt->max_seconds);
    return THZ_OK;
}

void run_apply_overrides(thz_scene *scene, const run_overrides *ov)
{
    if (!ov)
        return;
    if (ov->photons) {
        scene->photons.per_channel = ov->photons;
        scene->photons.per_channel_given = true;
    }
    if (ov->has_seed)
        scene->photons.seed = ov->seed;
    if (ov->has_integrator)
        scene->render.integrator = ov->integrator;
}

double run_target_noise_k(const thz_scene *scene, const run_options *opt, bool render,
                          const char **source)
{
    thz_integrator in = scene->render.integrator;
    /* render's photon-map is deterministic given its map: no passes, no target */
    bool can = !render || render_integrator_has_passes(in);
    const char *from = NULL;
    double t = 0.0;
    if (opt->target_noise_k > 0.0) {
        t = opt->target_noise_k, from = "command line";
    } else if (can && scene->render.target_noise_k > 0.0) {
        t = scene->render.target_noise_k, from = "scene";
    } else if (can) {
        bool given = in == INTEGRATOR_PATH ? scene->render.paths_per_sample_given
                                           : scene->photons.per_channel_given;
        if (!given)
            t = RUN_DEFAULT_TARGET_NOISE_K, from = "default";
    }
    if (source)
        *source = from;
    return t;
}

static thz_status run_add_warning(run_state *rs, thz_error *err, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static thz_status run_add_warning(run_state *rs, thz_error *err, const char *fmt, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    char **w = thz_realloc_array(rs->warnings, rs->n_warnings + 1, sizeof *w);
    if (!w)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for run warnings");
    rs->warnings = w;
    w[rs->n_warnings] = thz_strdup(buf);
    if (!w[rs->n_warnings])
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for run warnings");
    rs->n_warnings++;
    if (rs->opt->warning)
        rs->opt->warning(rs->opt->warning_user, buf);
    return THZ_OK;
}

void run_state_fini(run_state *rs)
{
    if (rs->images)
        for (size_t i = 0; i < rs->n_selected; i++)
            sensor_images_fini(&rs->images[i]);
    free(rs->images);
    free(rs->selected);
    free(rs->back_face);
    free(rs->render_sum);
    free(rs->last);
    if (rs->maps)
        for (size_t c = 0; c < rs->scene->n_channels; c++)
            photon_map_destroy(rs->maps[c]);
    free(rs->maps);
    photon_map_pool_fini(&rs->pool);
    free(rs->stats);
    free(rs->noise);
    free(rs->object_noise);
    free(rs->passes);
    free(rs->seconds_channel);
    for (size_t i = 0; i < rs->n_warnings; i++)
        free(rs->warnings[i]);
    free(rs->warnings);
    accel_destroy(rs->accel);
    memset(rs, 0, sizeof *rs);
}

/* Chooses the sensors (all, or the one named) and allocates the per-run arrays. */
static thz_status run_state_init(run_state *rs, const thz_scene *scene, const run_options *opt,
                                 const char *command, thz_error *err)
{
    memset(rs, 0, sizeof *rs);
    rs->scene = scene;
    rs->options = *opt;
    rs->opt = &rs->options;
    rs->command = command;
    rs->seed = scene->photons.seed;
    rs->photons_per_channel = render_integrator_needs_photons(scene->render.integrator)
                                  ? scene->photons.per_channel
                                  : 0; /* path fires none */
    rs->target_noise_k =
        run_target_noise_k(scene, opt, strcmp(command, "render") == 0, &rs->target_source);
    rs->max_seconds = opt->max_seconds > 0.0 ? opt->max_seconds : scene->render.max_seconds;
    size_t nc = scene->n_channels, ns = scene->n_sensors;
    rs->selected = thz_calloc(ns, sizeof *rs->selected);
    rs->maps = thz_calloc(nc, sizeof *rs->maps);
    rs->stats = thz_calloc(nc, sizeof *rs->stats);
    rs->noise = thz_calloc(nc, sizeof *rs->noise);
    rs->object_noise =
        thz_calloc(nc * (scene->n_objects ? scene->n_objects : 1), sizeof *rs->object_noise);
    rs->passes = thz_calloc(nc, sizeof *rs->passes);
    rs->seconds_channel = thz_calloc(nc, sizeof *rs->seconds_channel);
    if (!rs->selected || !rs->maps || !rs->stats || !rs->noise || !rs->object_noise ||
        !rs->passes || !rs->seconds_channel)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t s = 0; s < ns; s++)
        if (!opt->sensor_name || strcmp(opt->sensor_name, scene->sensors[s].name) == 0)
            rs->selected[rs->n_selected++] = s;
    if (rs->n_selected == 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: the scene has no sensor named '%s'", command,
                             opt->sensor_name ? opt->sensor_name : "");
    rs->images = thz_calloc(rs->n_selected, sizeof *rs->images);
    rs->back_face = thz_calloc(ns, sizeof *rs->back_face); /* summary.json: per scene sensor */
    rs->render_sum = thz_calloc(rs->n_selected, sizeof *rs->render_sum);
    rs->last = thz_calloc(nc * rs->n_selected, sizeof *rs->last);
    if (!rs->images || !rs->back_face || !rs->render_sum || !rs->last)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    return THZ_OK;
}

/* T0 of channel c's photon map in simulate: final-gather fires the deviation map of
 * L - B(T0) (photon_map.h), T0 the scene's reference temperature (also path's control
 * variate); photon-map keeps the paper's map. */
double run_photon_t0_k(const thz_scene *scene, size_t c)
{
    return scene->render.integrator == INTEGRATOR_FINAL_GATHER
               ? scene_reference_temperature_k(scene, c)
               : 0.0;
}

static thz_status run_init_images(run_state *rs, thz_error *err)
{
    render_options ro = {.threads = rs->opt->threads,
                         .progress = rs->opt->progress,
                         .progress_user = rs->opt->progress_user};
    for (size_t i = 0; i < rs->n_selected; i++) {
        const thz_sensor *s = &rs->scene->sensors[rs->selected[i]];
        thz_status st =
            sensor_images_alloc(&rs->images[i], s->columns, s->rows, rs->scene->n_channels, 1, err);
        if (st != THZ_OK)
            return st;
        st = render_sensor_truth(rs->scene, rs->accel, rs->selected[i], &rs->images[i], &ro, err);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}

/* The 95th percentile over the rendered pixels of channel c (all selected sensors) of
 * the standard error of Tb_c in K (run_noise.h): what a noise target aims at. A
 * negative value (never below a target) on allocation failure: the caller stops. */
static double run_channel_p95_stderr_k(const run_state *rs, size_t c)
{
    run_noise all;
    thz_error ignored;
    if (run_noise_channel(rs->images, rs->n_selected, c, rs->scene->channels[c].center_hz, 0, &all,
                          NULL, &ignored) != THZ_OK)
        return -1.0;
    return all.p95_k;
}

/* final-gather: whether the photon map's own noise (run_noise_map_floor_k) keeps channel
 * c's 95th percentile at or above the target: more gather rays from the same map cannot
 * lower it, so the passes stop there, with a warning that says what would (*st: THZ_OK,
 * or the warning's failure). */
static bool run_at_map_floor(run_state *rs, size_t c, const render_accum *acc, double target,
                             thz_status *st, thz_error *err)
{
    double floor_k =
        run_noise_map_floor_k(acc, rs->images, rs->n_selected, c, rs->scene->channels[c].center_hz);
    if (floor_k < target) /* below, or no batches (0), or out of memory (-1): go on */
        return false;
    bool render = strcmp(rs->command, "render") == 0;
    *st = run_add_warning(
        rs, err,
        "channel %zu: final-gather's photon map alone leaves %.3g K at the 95th percentile, "
        "at or above the noise target of %g K, which more gather rays cannot lower: stopped "
        "after %u passes. A map of more photons lowers it (%s %llu per channel), and the "
        "path integrator has no such floor",
        c, floor_k, target, rs->passes[c], render ? "the map read has" : "now",
        (unsigned long long)rs->photons_per_channel);
    return true;
}

/* Renders channel c of every selected sensor: one pass, or, with a noise target and an
 * integrator with passes, passes until the channel's median standard error reaches it
 * or the time limit passes. */
static thz_status run_render_channel(run_state *rs, size_t c, const photon_map *map, thz_error *err)
{
    render_options ro = {.threads = rs->opt->threads,
                         .use_seed = true,
                         .seed = rs->seed, /* the photon map's, for render */
                         .progress = rs->opt->progress,
                         .progress_user = rs->opt->progress_user};
    const render_team *team = rs->opt->render_team;
    if (team) /* this process renders its tiles, the others theirs */
        ro.members = team->members;
    double t0 = thz_now_s();
    double target =
        render_integrator_has_passes(rs->scene->render.integrator) ? rs->target_noise_k : 0.0;
    render_accum *acc = thz_calloc(rs->n_selected, sizeof *acc);
    thz_status st = THZ_OK;
    if (!acc)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the pixel statistics");
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
        const thz_sensor *s = &rs->scene->sensors[rs->selected[i]];
        st = render_accum_init(&acc[i], (size_t)s->columns * s->rows, err);
    }
    /* the channel's tables, built once for all its passes and sensors */
    render_context *ctx = NULL;
    if (st == THZ_OK && team) {
        render_channel_request rq = {.channel = c, .use_seed = ro.use_seed, .seed = ro.seed};
        st = team->channel_begin(team->impl, &rq, map, err);
    }
    if (st == THZ_OK)
        st = render_context_create(rs->scene, rs->accel, map, c, &ro, &ctx, err);
    for (uint32_t pass = 0; st == THZ_OK; pass++) {
        for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
            render_stats rst;
            if (team)
                st = team->pass_start(team->impl, rs->selected[i], pass, err);
            if (st == THZ_OK)
                st = render_context_pass(ctx, rs->selected[i], pass, &acc[i], &ro, &rst, err);
            if (st == THZ_OK && team)
                st = team->pass_gather(team->impl, &acc[i],
                                       rs->scene->sensors[rs->selected[i]].columns, &rst, err);
            if (st != THZ_OK)
                break;
            rs->last[c * rs->n_selected + i] = rst;
            st = render_accum_write(rs->scene, c, rs->selected[i], &acc[i], &rs->images[i], err);
        }
        if (st != THZ_OK)
            break;
        rs->passes[c] = pass + 1;
        if (!(target > 0.0))
            break;
        if (run_channel_p95_stderr_k(rs, c) <= target)
            break;
        if (pass + 1 >= RUN_FLOOR_PASSES && run_at_map_floor(rs, c, acc, target, &st, err))
            break;
        if (rs->max_seconds > 0.0 && thz_now_s() - t0 >= rs->max_seconds)
            break;
        if (pass + 1 >= RUN_MAX_PASSES) {
            st = run_add_warning(rs, err,
                                 "channel %zu: stopped after %u passes above the noise target "
                                 "of %g K",
                                 c, (unsigned)RUN_MAX_PASSES, target);
            break;
        }
    }
    if (st == THZ_OK && team)
        st = team->channel_end(team->impl, err);
    render_context_destroy(ctx);
    if (acc)
        for (size_t i = 0; i < rs->n_selected; i++)
            render_accum_fini(&acc[i]);
    free(acc);
    double seconds = thz_now_s() - t0;
    rs->seconds_channel[c] += seconds; /* photon-map's photon passes render again */
    rs->seconds_render += seconds;
    return st;
}

/* The noise figures of every channel, overall and per object. */
static thz_status run_noise_figures(run_state *rs, thz_error *err)
{
    const thz_scene *sc = rs->scene;
    thz_status st = THZ_OK;
    for (size_t c = 0; c < sc->n_channels && st == THZ_OK; c++)
        st = run_noise_channel(rs->images, rs->n_selected, c, sc->channels[c].center_hz,
                               sc->n_objects, &rs->noise[c], &rs->object_noise[c * sc->n_objects],
                               err);
    return st;
}

/* Per sensor, the counts of every channel's last render pass (render_sum, and back_face
 * per scene sensor for summary.json), then the warnings they call for. */
static thz_status run_render_warnings(run_state *rs, thz_error *err)
{
    for (size_t i = 0; i < rs->n_selected; i++) {
        render_stats *sum = &rs->render_sum[i];
        memset(sum, 0, sizeof *sum);
        for (size_t c = 0; c < rs->scene->n_channels; c++) {
            const render_stats *l = &rs->last[c * rs->n_selected + i];
            sum->samples += l->samples;
            sum->back_face_samples += l->back_face_samples;
            sum->starved_gathers += l->starved_gathers;
            sum->truncated_paths += l->truncated_paths;
        }
        rs->back_face[rs->selected[i]] = sum->back_face_samples;
    }
    thz_status st = THZ_OK;
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
        const render_stats *r = &rs->render_sum[i];
        const char *name = rs->scene->sensors[rs->selected[i]].name;
        /* a sensor inside a solid or outside the enclosure has its own scene warning:
         * then the normals are not to blame */
        bool misplaced = rs->scene->sensors[rs->selected[i]].misplaced;
        if (r->back_face_samples)
            st = run_add_warning(rs, err,
                                 "sensor '%s': %llu of %llu samples saw the back side of a "
                                 "one-sided solid (radiance 0); %s",
                                 name, (unsigned long long)r->back_face_samples,
                                 (unsigned long long)r->samples,
                                 misplaced ? "the sensor is inside a solid or outside the "
                                             "enclosure (see the scene warning)"
                                           : "check the mesh normals");
        if (st == THZ_OK && r->starved_gathers)
            st = run_add_warning(rs, err,
                                 "sensor '%s': %llu samples hit objects holding fewer photons "
                                 "than a density estimate needs (gather_min_photons; "
                                 "final-gather's secondary hits at least %d) and took their "
                                 "reflected radiance as 0; raise photons.per_channel",
                                 name, (unsigned long long)r->starved_gathers, RENDER_SECONDARY_K);
        if (st == THZ_OK && r->truncated_paths)
            st = run_add_warning(rs, err,
                                 "sensor '%s': %llu samples were cut short: after %d straight "
                                 "shells (what lies behind was dropped) or, with path, after %d "
                                 "hits (the rest taken as B(T0))",
                                 name, (unsigned long long)r->truncated_paths, RENDER_MAX_CROSSINGS,
                                 RENDER_MAX_BOUNCES);
    }
    return st;
}

/* The end of a successful run: the noise figures and warnings of what was rendered, the
 * totals; the ray-casting structure is no longer needed. */
static thz_status run_finish(run_state *rs, double t_start, thz_error *err)
{
    accel_destroy(rs->accel);
    rs->accel = NULL;
    thz_status st = THZ_OK;
    /* the sensor as built, from the finished noise-free cubes (measure.h) */
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++)
        st = sensor_measure(rs->scene, rs->selected[i], rs->seed, &rs->images[i], rs->opt->threads,
                            err);
    if (st == THZ_OK)
        st = run_noise_figures(rs, err);
    if (st == THZ_OK)
        st = run_render_warnings(rs, err);
    if (st != THZ_OK)
        return st;
    run_result *result = &rs->result;
    memset(result, 0, sizeof *result);
    result->n_channels = rs->scene->n_channels;
    result->n_sensors = rs->n_selected;
    /* render fires no photons: the stats it read describe the saved map */
    for (size_t c = 0; c < rs->scene->n_channels && strcmp(rs->command, "simulate") == 0; c++) {
        result->photons_fired += rs->stats[c].fired;
        result->photons_stored += rs->stats[c].stored;
    }
    for (size_t i = 0; i < rs->n_selected; i++)
        result->back_face_samples += rs->back_face[rs->selected[i]];
    result->n_warnings = rs->n_warnings;
    size_t no = rs->scene->n_objects;
    result->worst_object = SIZE_MAX;
    for (size_t c = 0; c < rs->scene->n_channels; c++) {
        result->worst_median_stderr_k = fmax(result->worst_median_stderr_k, rs->noise[c].median_k);
        result->worst_p95_stderr_k = fmax(result->worst_p95_stderr_k, rs->noise[c].p95_k);
        for (size_t o = 0; o < no; o++) {
            const run_noise *n = &rs->object_noise[c * no + o];
            if (n->pixels > 0 && (result->worst_object == SIZE_MAX ||
                                  n->p95_k > result->worst_object_p95_stderr_k)) {
                result->worst_object = o;
                result->worst_object_channel = c;
                result->worst_object_p95_stderr_k = n->p95_k;
            }
        }
        if (rs->passes[c] > result->max_passes)
            result->max_passes = rs->passes[c];
    }
    result->seconds = thz_now_s() - t_start;
    return THZ_OK;
}

/* The common start: integrator check, sensors, accel. */
static thz_status run_begin(run_state *rs, const thz_scene *scene, const run_options *opt,
                            const char *command, thz_error *err)
{
    thz_status st = run_state_init(rs, scene, opt, command, err);
    if (st == THZ_OK)
        st = render_integrator_check(scene->render.integrator, err);
    if (st == THZ_OK)
        st = run_check_options(opt, err);
    if (st != THZ_OK)
        return st;
    double t0 = thz_now_s();
    st = accel_create(scene, &rs->accel, err);
    rs->seconds_accel = thz_now_s() - t0;
    return st;
}

/* photon-map with a noise target (it cannot add render passes: it is deterministic given
 * its map): photon passes instead. Pass p fires photons p K .. (p + 1) K - 1 of the
 * channel, and the channel is rendered from the merge of all passes' photons
 * (photon_map_merge: (p + 1) K photons), until the median standard error reaches the
 * target, the time limit passes, or the next merge would not fit in half the memory.
 * *out_map is the merged map; the passes are bit-identical for any thread count. */
static thz_status run_photon_passes(run_state *rs, size_t c, photon_map **out_map, thz_error *err)
{
    const thz_scene *scene = rs->scene;
    const run_options *opt = rs->opt;
    double target = rs->target_noise_k, t_start = thz_now_s();
    size_t cap = 16, n = 0;
    photon_map **maps = thz_calloc(cap, sizeof *maps);
    photon_map *merged = NULL;
    thz_status st = THZ_OK;
    if (!maps)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon passes");
    uint64_t k = scene->photons.per_channel;
    double limit = 0.5 * (double)thz_physical_memory_bytes();
    while (st == THZ_OK) {
        if (n == cap) {
            photon_map **m = thz_realloc_array(maps, 2 * cap, sizeof *m);
            if (!m) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon passes");
                break;
            }
            maps = m;
            cap *= 2;
        }
        photon_phase_options po = {.threads = opt->threads,
                                   .reference_temperature_k = run_photon_t0_k(scene, c),
                                   .first_photon = (uint64_t)n * k,
                                   .team = opt->team,
                                   .pool = &rs->pool,
                                   .progress = opt->progress,
                                   .progress_user = opt->progress_user};
        photon_stats ps;
        double t0 = thz_now_s();
        st = photon_phase_run(scene, rs->accel, c, &po, &maps[n], &ps, err);
        if (st != THZ_OK)
            break;
        n++;
        photon_map_destroy(merged);
        merged = NULL;
        if (n > 1)
            st = photon_map_merge((const photon_map *const *)maps, n, scene->n_objects,
                                  opt->threads, &merged, err);
        rs->seconds_photons += thz_now_s() - t0;
        photon_stats_merge(&rs->stats[c], &ps, (uint32_t)n);
        if (st != THZ_OK)
            break;
        const photon_map *map = n > 1 ? merged : maps[0];
        rs->stats[c].stored = photon_map_count(map);
        st = run_render_channel(rs, c, map, err);
        rs->passes[c] = (uint32_t)n;
        if (st != THZ_OK || run_channel_p95_stderr_k(rs, c) <= target)
            break;
        if (rs->max_seconds > 0.0 && thz_now_s() - t_start >= rs->max_seconds)
            break;
        /* the passes' maps and the next merge: twice the records, and their indexes */
        double next = 2.2 * (double)photon_map_bytes(map) * (double)(n + 1) / (double)n;
        if (limit > 0.0 && next > limit) { /* 0: the machine's memory is unknown */
            st = run_add_warning(rs, err,
                                 "channel %zu: stopped after %zu photon passes (%llu photons) "
                                 "above the noise target of %g K: the next would need %.2f GiB "
                                 "of memory",
                                 c, n, (unsigned long long)(n * k), target, next / 1073741824.0);
            break;
        }
        if (n >= RUN_MAX_PASSES) {
            st = run_add_warning(rs, err,
                                 "channel %zu: stopped after %u passes above the noise target "
                                 "of %g K",
                                 c, (unsigned)RUN_MAX_PASSES, target);
            break;
        }
    }
    if (st == THZ_OK && n > 0) {
        if (n > 1) {
            *out_map = merged;
            merged = NULL;
        } else {
            *out_map = maps[0];
            maps[0] = NULL;
        }
    }
    photon_map_destroy(merged);
    for (size_t i = 0; maps && i < n; i++)
        photon_map_destroy(maps[i]);
    free(maps);
    return st;
}

/* Estimates the run's time (a pilot) and tells opt->plan; render fires no photons. */
static thz_status run_tell_plan(run_state *rs, bool fires_photons, thz_error *err)
{
    run_estimate_input in = {.scene = rs->scene,
                             .accel = rs->accel,
                             .selected = rs->selected,
                             .n_selected = rs->n_selected,
                             .target_noise_k = rs->target_noise_k,
                             .threads = rs->opt->threads};
    run_plan plan = {.memory_bytes = rs->memory_bytes,
                     .available_bytes = thz_physical_memory_bytes(),
                     .target_noise_k = rs->target_noise_k,
                     .target_source = rs->target_source};
    thz_status st =
        run_estimate_time(&in, &plan.seconds_photons, &plan.seconds_render, &plan.passes, err);
    if (!fires_photons)
        plan.seconds_photons = 0.0;
    if (st == THZ_OK)
        rs->opt->plan(rs->opt->plan_user, &plan);
    return st;
}

thz_status run_simulate(const thz_scene *scene, const run_options *opt, run_state *rs,
                        thz_error *err)
{
    double t_start = thz_now_s();
    thz_status st = run_begin(rs, scene, opt, "simulate", err);
    bool photons = render_integrator_needs_photons(scene->render.integrator);
    if (st == THZ_OK)
        st = run_check_run_memory(rs, photons, 0, err);
    if (st == THZ_OK && opt->plan)
        st = run_tell_plan(rs, true, err);
    if (st == THZ_OK)
        st = run_init_images(rs, err);
    bool photon_passes = photons && rs->target_noise_k > 0.0 &&
                         !render_integrator_has_passes(scene->render.integrator);
    for (size_t c = 0; st == THZ_OK && c < scene->n_channels; c++) {
        photon_map *map = NULL;
        if (photon_passes) {
            st = run_photon_passes(rs, c, &map, err);
            if (opt->keep_photon_maps)
                rs->maps[c] = map;
            else
                photon_map_destroy(map);
            continue;
        }
        if (photons) {
            photon_phase_options po = {.threads = opt->threads,
                                       .reference_temperature_k = run_photon_t0_k(scene, c),
                                       .team = opt->team,
                                       .pool = &rs->pool,
                                       .progress = opt->progress,
                                       .progress_user = opt->progress_user};
            double t0 = thz_now_s();
            st = photon_phase_run(scene, rs->accel, c, &po, &map, &rs->stats[c], err);
            rs->seconds_photons += thz_now_s() - t0;
            if (st != THZ_OK)
                break;
        }
        st = run_render_channel(rs, c, map, err);
        if (opt->keep_photon_maps)
            rs->maps[c] = map;
        else
            photon_map_recycle(map, &rs->pool);
    }
    if (st == THZ_OK)
        st = run_finish(rs, t_start, err);
    if (st != THZ_OK)
        run_state_fini(rs);
    return st;
}

thz_status run_render(const thz_scene *scene, const run_options *opt, const run_photons *in,
                      run_state *rs, thz_error *err)
{
    double t_start = thz_now_s();
    memset(rs, 0, sizeof *rs);
    if (opt->keep_photon_maps)
        return thz_error_set(err, THZ_ERR_INPUT, "render: --save-photon-map is for simulate");
    if (opt->target_noise_k > 0.0 && !render_integrator_has_passes(scene->render.integrator))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "render: '%s' is deterministic given its photon map, and render "
                             "fires no photons: a noise target needs simulate (which fires "
                             "photons until it is met) or final-gather or path",
                             render_integrator_name(scene->render.integrator));
    bool photons = render_integrator_needs_photons(scene->render.integrator);
    bool stream = photons && in && !in->maps && in->next_map;
    for (size_t c = 0; photons && !stream && c < scene->n_channels; c++)
        if (!in || !in->maps || !in->maps[c])
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "render: no photon map for channel %zu; only the path "
                                 "integrator renders without one",
                                 c);
    thz_status st = run_begin(rs, scene, opt, "render", err);
    if (st == THZ_OK) /* maps in memory already: the images alone; or one read at a time */
        st = run_check_run_memory(rs, false, stream ? in->next_map_bytes : 0, err);
    if (st == THZ_OK && in) {
        if (in->stats)
            memcpy(rs->stats, in->stats, scene->n_channels * sizeof *rs->stats);
        rs->seed = in->seed;
        rs->photons_per_channel = in->photons_per_channel;
    }
    if (st == THZ_OK && opt->plan) /* a large render must not start without one */
        st = run_tell_plan(rs, false, err);
    if (st == THZ_OK)
        st = run_init_images(rs, err);
    for (size_t c = 0; st == THZ_OK && c < scene->n_channels; c++) {
        photon_map *map = NULL;
        if (stream) { /* reading the file is the render's photon time */
            double t0 = thz_now_s();
            st = in->next_map(in->next_user, &map, err);
            rs->seconds_photons += thz_now_s() - t0;
        }
        if (st == THZ_OK)
            st = run_render_channel(rs, c, !photons ? NULL : stream ? map : in->maps[c], err);
        photon_map_destroy(map);
    }
    if (st == THZ_OK)
        st = run_finish(rs, t_start, err);
    if (st != THZ_OK)
        run_state_fini(rs);
    return st;
}
