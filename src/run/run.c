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
#include "physics/planck.h"
#include "run/run_estimate.h"
#include "run/run_noise.h"
#include "sensor/images.h"
#include "sensor/measure.h"
#include "sensor/psf.h"
#include "sensor/render.h"
#include "sensor/render_tiles.h"
#include "sensor/truth.h"

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

thz_status run_add_warning(run_state *rs, thz_error *err, const char *fmt, ...)
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
    emission_reach_fini(&rs->reach);
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
    /* a limit on passes that no target asks for: said, not silently dropped */
    if (rs->max_seconds > 0.0 && !(rs->target_noise_k > 0.0)) {
        thz_status st = run_add_warning(
            rs, err,
            "max_seconds %g s is not used: it limits the passes towards a noise target, and "
            "this run has none (%s)",
            rs->max_seconds,
            strcmp(command, "render") == 0 &&
                    !render_integrator_has_passes(scene->render.integrator)
                ? "photon-map renders from its map in one pass"
                : "each channel runs one pass of the count given; set --target-noise-k or "
                  "render.target_noise_k for passes");
        if (st != THZ_OK)
            return st;
    }
    /* photon-map's density estimate weighs each photon by the lobe: a narrow one catches
     * few photons or none, and the standard error cannot show what none brought (a
     * furnace's sphere of alpha 0.001 read half its radiance at a standard error of
     * 0.008 K) */
    for (size_t i = 0; i < scene->n_materials && scene->render.integrator == INTEGRATOR_PHOTON_MAP;
         i++) {
        const thz_material *m = &scene->materials[i];
        double alpha = fmin(m->ward_alpha[0], m->ward_alpha[1]);
        bool used = false; /* a material no object uses shapes no image */
        for (size_t j = 0; j < scene->n_objects && !used; j++)
            used = scene->objects[j].material == i;
        if (!used || m->reflection != REFLECTION_WARD || !(alpha < RUN_WARD_ALPHA_PHOTON_MAP))
            continue;
        thz_status st = run_add_warning(
            rs, err,
            "material \"%s\": photon-map cannot resolve its glossy lobe (alpha %g, below %g): "
            "the photons it weighs are too few, or none, and its standard error does not show "
            "what they miss; use final-gather or path, or \"reflection\": \"specular\"",
            m->name, alpha, RUN_WARD_ALPHA_PHOTON_MAP);
        if (st != THZ_OK)
            return st;
    }
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
        for (size_t c = 0; c < rs->scene->n_channels; c++)
            render_stats_add_counts(sum, &rs->last[c * rs->n_selected + i]);
        rs->back_face[rs->selected[i]] = sum->back_face_samples;
    }
    thz_status st = THZ_OK;
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
        const render_stats *r = &rs->render_sum[i];
        const char *name = rs->scene->sensors[rs->selected[i]].name;
        /* a sensor inside a solid or outside the enclosure has its own scene warning:
         * then the normals are not to blame */
        bool misplaced = rs->scene->sensors[rs->selected[i]].misplaced;
        if (r->back_face_samples) {
            /* the objects: one, or the first and last by index of several */
            const thz_object *lo = &rs->scene->objects[r->back_face_object_lo];
            const thz_object *hi = &rs->scene->objects[r->back_face_object_hi];
            bool one = lo == hi;
            st = run_add_warning(
                rs, err,
                "sensor '%s': %llu of %llu samples saw the back side of %s '%s'%s%s%s "
                "(radiance 0); %s",
                name, (unsigned long long)r->back_face_samples, (unsigned long long)r->samples,
                one ? "one-sided solid" : "one-sided solids, among them", lo->name,
                one ? "" : " and '", one ? "" : hi->name, one ? "" : "'",
                misplaced ? "the sensor is inside a solid or outside the "
                            "enclosure (see the scene warning)"
                : one     ? "check its mesh normals"
                          : "check their mesh normals");
        }
        if (st == THZ_OK && r->starved_gathers)
            st = run_add_warning(rs, err,
                                 "sensor '%s': %llu samples hit objects holding fewer photons "
                                 "than a density estimate needs (gather_min_photons; "
                                 "final-gather's secondary hits at least %d) and took their "
                                 "reflected radiance as 0%s; raise photons.per_channel",
                                 name, (unsigned long long)r->starved_gathers, RENDER_SECONDARY_K,
                                 rs->scene->render.integrator == INTEGRATOR_PHOTON_MAP
                                     ? ": their pixels' standard error is unknown (NaN in "
                                       "radiance_stderr, starved_pixels in summary.json)"
                                     : "");
        if (st == THZ_OK && r->truncated_paths)
            st = run_add_warning(rs, err,
                                 "sensor '%s': %llu samples were cut short: after %d straight "
                                 "shells and mirror reflections in a row (what lies beyond "
                                 "was dropped) or, with path, after %d hits (the rest taken "
                                 "as B(T0))",
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

/* The rendered sensors' PSF kernels can be built (psf_sensor_check), before the work
 * rather than at its outputs. (A scene loaded through the API has passed it already:
 * this holds for a scene made otherwise, as the unit tests make theirs.) */
static thz_status run_check_psfs(const run_state *rs, thz_error *err)
{
    thz_status st = THZ_OK;
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++)
        st = psf_sensor_check(rs->scene, rs->selected[i], err);
    return st;
}

/* The common start: integrator check, sensors, PSFs, accel. */
static thz_status run_begin(run_state *rs, const thz_scene *scene, const run_options *opt,
                            const char *command, thz_error *err)
{
    thz_status st = run_state_init(rs, scene, opt, command, err);
    if (st == THZ_OK)
        st = render_integrator_check(scene->render.integrator, err);
    if (st == THZ_OK)
        st = run_check_options(opt, err);
    if (st == THZ_OK)
        st = run_check_psfs(rs, err);
    if (st != THZ_OK)
        return st;
    double t0 = thz_now_s();
    st = accel_create(scene, &rs->accel, err);
    rs->seconds_accel = thz_now_s() - t0;
    return st;
}

/* The back sides' reach shares of the run's deviation maps (photon_phase_prepare), before
 * the estimates' pilots need them: computed once, with the run's threads, and stoppable. */
thz_status run_prepare_reach(const thz_scene *scene, const accel *acc, size_t only,
                             const photon_phase_options *po, thz_error *err)
{
    for (size_t c = 0; c < scene->n_channels; c++)
        if ((only == SIZE_MAX || c == only) && run_photon_t0_k(scene, c) > 0.0)
            return photon_phase_prepare(scene, acc, po, err);
    return THZ_OK;
}

static thz_status run_prepare_photons(run_state *rs, thz_error *err)
{
    photon_phase_options po = {.threads = rs->opt->threads,
                               .reach = &rs->reach,
                               .progress = rs->opt->progress,
                               .progress_user = rs->opt->progress_user};
    thz_status st = run_prepare_reach(rs->scene, rs->accel, SIZE_MAX, &po, err);
    rs->seconds_photons += rs->reach.seconds; /* summary.json's timings_s.photons */
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
                             .threads = rs->opt->threads,
                             .reach = &rs->reach};
    run_estimate e;
    thz_status st = run_estimate_time(&in, &e, err);
    if (st != THZ_OK)
        return st;
    /* photon-map's passes hold every pass's map until the channel ends */
    run_plan plan = {.seconds_photons = fires_photons ? e.seconds_photons : 0.0,
                     .seconds_render = e.seconds_render,
                     .passes = e.passes,
                     .memory_bytes = e.passes_bytes > UINT64_MAX - rs->memory_bytes
                                         ? UINT64_MAX
                                         : rs->memory_bytes + e.passes_bytes,
                     .available_bytes = thz_memory_limit_bytes(),
                     .memory_stop = e.memory_stop,
                     .target_noise_k = rs->target_noise_k,
                     .target_source = rs->target_source};
    if (st == THZ_OK)
        rs->opt->plan(rs->opt->plan_user, &plan);
    return st;
}

/* Photon maps to keep from an integrator that fires none: refused, as the CLI's
 * --save-photon-map and the server's save_photon_map are (Python's keep_photons=True
 * gave a run without a map, and a later save said keep_photons had not been given). */
static thz_status run_check_keep(const thz_scene *scene, const run_options *opt, thz_error *err)
{
    if (!opt->keep_photon_maps || render_integrator_needs_photons(scene->render.integrator))
        return THZ_OK;
    return thz_error_set(err, THZ_ERR_INPUT,
                         "keep_photons: the %s integrator fires no photons, so there is no "
                         "photon map to keep (choose final-gather or photon-map)",
                         render_integrator_name(scene->render.integrator));
}

thz_status run_check_simulate(const thz_scene *scene, const run_options *opt, thz_error *err)
{
    run_state rs;
    memset(&rs, 0, sizeof rs);
    thz_status st = run_check_keep(scene, opt, err);
    if (st == THZ_OK)
        st = run_begin(&rs, scene, opt, "simulate", err);
    bool photons = render_integrator_needs_photons(scene->render.integrator);
    if (st == THZ_OK && photons)
        st = run_prepare_photons(&rs, err);
    if (st == THZ_OK)
        st = run_check_run_memory(&rs, photons, 0, 0, err);
    run_state_fini(&rs);
    return st;
}

thz_status run_simulate(const thz_scene *scene, const run_options *opt, run_state *rs,
                        thz_error *err)
{
    double t_start = thz_now_s();
    thz_status st = run_check_keep(scene, opt, err);
    if (st == THZ_OK)
        st = run_begin(rs, scene, opt, "simulate", err);
    bool photons = render_integrator_needs_photons(scene->render.integrator);
    if (st == THZ_OK && photons)
        st = run_prepare_photons(rs, err);
    if (st == THZ_OK)
        st = run_check_run_memory(rs, photons, 0, 0, err);
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
                                       .reach = &rs->reach,
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
        st = run_check_run_memory(rs, false, stream ? in->next_map_bytes : 0,
                                  stream ? in->photons_per_channel : 0, err);
    if (st == THZ_OK && in) {
        if (in->stats)
            memcpy(rs->stats, in->stats, scene->n_channels * sizeof *rs->stats);
        /* a render fires no photons: summary.json's photon_phase_s is 0, as for a map
         * read from a file (maps kept in memory carried the time of the run that fired
         * them: a batch frame rendered from its base frame's photons showed the base's) */
        for (size_t c = 0; c < scene->n_channels; c++)
            rs->stats[c].seconds = 0.0;
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
