/* Whole runs in memory (simulate, render from photons), their images, and writing them
 * through an atomic output directory. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "core/alloc.h"
#include "io/output.h"
#include "io/photon_map_file.h"
#include "run/run_pack.h"
#include "scene/scene_hash.h"

/* ---- images ------------------------------------------------------------------------- */

thz_status api_image_init_borrowed(thz_image *image, const thz_scene *scene, size_t sensor,
                                   const sensor_images *img, thz_error *err)
{
    memset(image, 0, sizeof *image);
    image->scene = scene;
    image->sensor = sensor;
    image->img = img;
    image->sensor_name = thz_strdup(scene->sensors[sensor].name);
    if (!image->sensor_name)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the sensor's name");
    size_t pixels = (size_t)img->columns * img->rows;
    image->object_id = thz_malloc_array(pixels ? pixels : 1, sizeof *image->object_id);
    if (!image->object_id)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the object_id plane");
    for (size_t p = 0; p < pixels; p++)
        image->object_id[p] = (float)img->object_id[p]; /* exact: at most 2^24 objects */
    return THZ_OK;
}

void api_image_fini(thz_image *image)
{
    free(image->object_id);
    image->object_id = NULL;
    free(image->sensor_name);
    image->sensor_name = NULL;
}

void thz_image_destroy(thz_image *image)
{
    if (!image || !image->run) /* a run's image belongs to the run */
        return;
    thz_run_destroy(image->run);
    free(image);
}

uint32_t thz_image_columns(const thz_image *image)
{
    return image ? image->img->columns : 0;
}

uint32_t thz_image_rows(const thz_image *image)
{
    return image ? image->img->rows : 0;
}

size_t thz_image_channel_count(const thz_image *image)
{
    return image ? image->img->n_channels : 0;
}

size_t thz_image_sensor(const thz_image *image)
{
    return image ? image->sensor : 0;
}

const char *thz_image_sensor_name(const thz_image *image)
{
    return image ? image->sensor_name : NULL;
}

const float *thz_image_plane(const thz_image *image, thz_plane plane, size_t *n_bands)
{
    const float *data = NULL;
    size_t bands = 1;
    if (image) {
        const sensor_images *img = image->img;
        switch (plane) {
        case THZ_PLANE_RADIANCE:
            data = img->radiance;
            bands = img->n_channels;
            break;
        case THZ_PLANE_RADIANCE_STDERR:
            data = img->radiance_stderr;
            bands = img->n_channels;
            break;
        case THZ_PLANE_POWER:
            data = img->power;
            bands = img->n_channels;
            break;
        case THZ_PLANE_BRIGHTNESS_TEMPERATURE:
            data = img->brightness_temperature;
            bands = img->n_channels;
            break;
        case THZ_PLANE_NORMALIZED:
            data = img->normalized;
            bands = img->n_channels;
            break;
        case THZ_PLANE_TEMPERATURE:
            data = img->temperature_k;
            break;
        case THZ_PLANE_DISTANCE:
            data = img->distance_m;
            break;
        case THZ_PLANE_OBJECT_ID:
            data = image->object_id;
            break;
        case THZ_PLANE_VISUAL_RGB:
            data = img->visual_rgb;
            bands = 3;
            break;
        case THZ_PLANE_MEASURED_RADIANCE:
            data = img->measured_radiance;
            bands = img->n_channels;
            break;
        case THZ_PLANE_MEASURED_BRIGHTNESS_TEMPERATURE:
            data = img->measured_brightness_temperature;
            bands = img->n_channels;
            break;
        case THZ_PLANE_COUNT:
            break;
        }
    }
    if (n_bands)
        *n_bands = data ? bands : 0;
    return data;
}

const char *thz_plane_name(thz_plane plane)
{
    return output_plane_name(plane);
}

/* ---- runs ----------------------------------------------------------------------------- */

void thz_run_destroy(thz_run *run)
{
    if (!run)
        return;
    for (size_t i = 0; run->images && i < run->rs.n_selected; i++)
        api_image_fini(&run->images[i]);
    free(run->images);
    free(run->photons.spans);
    free(run->summary);
    run_state_fini(&run->rs);
    free(run);
}

/* The handles of a finished run: its images, its kept photons, its summary. */
static thz_status api_run_wrap(thz_run *run, thz_error *err)
{
    run_state *rs = &run->rs;
    run->images = thz_calloc(rs->n_selected ? rs->n_selected : 1, sizeof *run->images);
    if (!run->images)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < rs->n_selected; i++) {
        thz_status st = api_image_init_borrowed(&run->images[i], &run->effective, rs->selected[i],
                                                &rs->images[i], err);
        if (st != THZ_OK)
            return st;
    }
    bool all = rs->maps != NULL;
    for (size_t c = 0; all && c < run->effective.n_channels; c++)
        all = rs->maps[c] != NULL;
    if (all) {
        run->photons = (thz_photons){.scene = run->scene,
                                     .effective = run->effective,
                                     .n_channels = run->effective.n_channels,
                                     .maps = rs->maps,
                                     .stats = rs->stats,
                                     .seed = rs->seed,
                                     .photons_per_channel = rs->photons_per_channel,
                                     .owned = false};
        run->has_photons = true;
        /* a simulation fired photons 0 .. fired - 1 of each channel (over its photon
         * passes too): known, so that a merge refuses them twice (thz_photons_merge) */
        size_t nc = run->effective.n_channels;
        if (!strcmp(rs->command, "simulate")) {
            run->photons.spans = thz_calloc(nc ? nc : 1, sizeof *run->photons.spans);
            if (!run->photons.spans)
                return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            for (size_t c = 0; c < nc; c++)
                run->photons.spans[run->photons.n_spans++] =
                    (api_photon_span){.channel = c, .first = 0, .count = rs->stats[c].fired};
        }
    }
    run->summary = run_summary_text(rs, err);
    return run->summary ? THZ_OK : THZ_ERR_NOMEM;
}

/* A photon-map file read one channel at a time (run_photons.next_map). */
typedef struct api_map_stream {
    photon_map_file_stream *file;
    int threads;
    photon_stats *stats;
    photon_map_file_info info;
} api_map_stream;

static thz_status api_next_map(void *user, photon_map **map, thz_error *err)
{
    api_map_stream *s = user;
    return photon_map_file_next(s->file, s->threads, map, err);
}

/* simulate (photons NULL and !render) or render, from photons or (stream not NULL) a
 * file read a channel at a time. */
static thz_status api_run(thz_context *ctx, const thz_scene *scene, const thz_photons *photons,
                          api_map_stream *stream, bool render, const char *sensor_name,
                          const thz_run_settings *settings, thz_run **out, thz_error *err)
{
    *out = NULL;
    if (!scene)
        return thz_error_set(err, THZ_ERR_INPUT, "no scene");
    thz_status checked = api_check_threads(ctx, render ? "render" : "simulate", err);
    if (checked != THZ_OK)
        return checked;
    if (photons && photons->scene != scene) {
        /* Another handle of a scene that may differ in its sensors alone (another
         * viewpoint): what `thzmap render --photon-map` asks of a file's header. The
         * render reads the photons' maps and statistics, none of their scene. */
        scene_hash made;
        scene_hash_compute(&photons->effective, &made);
        thz_status fit =
            scene_hash_fit(&made, photons->effective.n_objects, photons->n_channels, scene,
                           "the photon map (fired or loaded for another scene handle)",
                           "fire photons for this scene, or simulate it keeping them", err);
        if (fit != THZ_OK)
            return fit;
    }
    thz_run *run = thz_calloc(1, sizeof *run);
    if (!run)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    run->scene = scene;
    thz_status st = api_effective_scene(scene, settings, &run->effective, err);
    run_options opt;
    api_run_options(ctx, settings, &opt);
    opt.sensor_name = sensor_name;
    if (st == THZ_OK && render) {
        opt.keep_photon_maps = false; /* the photons are the caller's */
        run_photons in = {0};
        if (photons)
            in = (run_photons){.maps = photons->maps,
                               .stats = photons->stats,
                               .seed = photons->seed,
                               .photons_per_channel = photons->photons_per_channel};
        if (stream) {
            in = (run_photons){.stats = stream->stats,
                               .seed = stream->info.seed,
                               .photons_per_channel = stream->info.photons_per_channel,
                               .next_map = api_next_map,
                               .next_user = stream,
                               .next_map_bytes = photon_map_file_largest_count(stream->file) *
                                                 (uint64_t)sizeof(photon_record)};
        }
        st = run_render(&run->effective, &opt, photons || stream ? &in : NULL, &run->rs, err);
    } else if (st == THZ_OK) {
        st = run_simulate(&run->effective, &opt, &run->rs, err);
    }
    if (st == THZ_OK)
        st = api_run_wrap(run, err);
    if (st != THZ_OK) {
        thz_run_destroy(run);
        return st;
    }
    *out = run;
    return THZ_OK;
}

thz_status api_run_unpack(const thz_scene *scene, const void *data, size_t size, thz_run **out,
                          thz_error *err)
{
    *out = NULL;
    thz_run *run = thz_calloc(1, sizeof *run);
    if (!run)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    run->scene = scene;
    thz_status st = api_effective_scene(scene, NULL, &run->effective, err);
    if (st == THZ_OK)
        st = run_unpack(&run->effective, data, size, &run->rs, err);
    if (st == THZ_OK)
        st = api_run_wrap(run, err);
    if (st != THZ_OK) {
        thz_run_destroy(run);
        return st;
    }
    *out = run;
    return THZ_OK;
}

thz_status thz_simulate_check(thz_context *ctx, const thz_scene *scene,
                              const thz_run_settings *settings, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!scene)
        return api_done(ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_simulate_check: no scene"),
                        err);
    thz_status st = api_check_threads(ctx, "thz_simulate_check", err);
    thz_scene effective;
    if (st == THZ_OK)
        st = api_effective_scene(scene, settings, &effective, err);
    run_options opt;
    api_run_options(ctx, settings, &opt);
    if (st == THZ_OK)
        st = run_check_simulate(&effective, &opt, err);
    return api_done(ctx, st, err);
}

thz_status thz_simulate(thz_context *ctx, const thz_scene *scene, const thz_run_settings *settings,
                        thz_run **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_simulate: no place for the run"), err);
    return api_done(ctx, api_run(ctx, scene, NULL, NULL, false, NULL, settings, out, err), err);
}

/* The name of sensor `sensor` (NULL for -1: every sensor); THZ_ERR_INPUT when the scene
 * has no such sensor (any other negative index too). */
static thz_status api_sensor_name(const thz_scene *scene, long sensor, const char **name,
                                  thz_error *err)
{
    *name = NULL;
    if (!scene)
        return thz_error_set(err, THZ_ERR_INPUT, "render: no scene");
    if (sensor == -1)
        return THZ_OK;
    if (sensor < -1)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "render: sensor %ld: expected -1 (every sensor) or a sensor's index",
                             sensor);
    if ((size_t)sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INPUT, "render: the scene has no sensor %ld", sensor);
    *name = scene->sensors[sensor].name;
    return THZ_OK;
}

thz_status thz_render_run(thz_context *ctx, const thz_scene *scene, const thz_photons *photons,
                          long sensor, const thz_run_settings *settings, thz_run **out,
                          thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_render_run: no place for the run"), err);
    *out = NULL;
    const char *name;
    thz_status st = api_sensor_name(scene, sensor, &name, err);
    if (st == THZ_OK)
        st = api_run(ctx, scene, photons, NULL, true, name, settings, out, err);
    return api_done(ctx, st, err);
}

thz_status thz_render_file(thz_context *ctx, const thz_scene *scene, const char *path, long sensor,
                           const thz_run_settings *settings, thz_run **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_render_file: no place for the run"), err);
    *out = NULL;
    const char *name;
    thz_status st = api_sensor_name(scene, sensor, &name, err);
    if (st == THZ_OK && (!scene || !path))
        st = thz_error_set(err, THZ_ERR_INPUT, "thz_render_file: no %s", scene ? "path" : "scene");
    if (st == THZ_OK)
        st = api_check_threads(ctx, "render", err);
    size_t nc = scene ? scene->n_channels : 0;
    api_map_stream stream = {.threads = ctx ? ctx->threads : 0,
                             .stats = thz_calloc(nc ? nc : 1, sizeof *stream.stats)};
    if (st == THZ_OK && !stream.stats)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon statistics");
    if (st == THZ_OK)
        st = photon_map_file_open(path, scene, stream.stats, &stream.info, &stream.file, err);
    if (st == THZ_OK)
        st = api_run(ctx, scene, NULL, &stream, true, name, settings, out, err);
    photon_map_file_close(stream.file);
    free(stream.stats);
    return api_done(ctx, st, err);
}

thz_status thz_render_sensor(thz_context *ctx, const thz_scene *scene, const thz_photons *photons,
                             size_t sensor, const thz_run_settings *settings, thz_image **out,
                             thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_render_sensor: no place for the image"),
            err);
    *out = NULL;
    thz_image *image = thz_calloc(1, sizeof *image);
    if (!image)
        return api_done(ctx, thz_error_set(err, THZ_ERR_NOMEM, "out of memory"), err);
    thz_run *run = NULL;
    long index = sensor > (size_t)LONG_MAX ? LONG_MAX : (long)sensor;
    thz_status st = thz_render_run(ctx, scene, photons, index, settings, &run, err);
    if (st != THZ_OK) {
        free(image);
        return st;
    }
    *image = run->images[0];
    image->run = run;
    *out = image;
    return THZ_OK;
}

size_t thz_run_image_count(const thz_run *run)
{
    return run ? run->rs.n_selected : 0;
}

const thz_image *thz_run_image(const thz_run *run, size_t i)
{
    return run && i < run->rs.n_selected ? &run->images[i] : NULL;
}

const thz_photons *thz_run_photons(const thz_run *run)
{
    return run && run->has_photons ? &run->photons : NULL;
}

const char *thz_run_summary_json(const thz_run *run)
{
    return run ? run->summary : NULL;
}

void thz_run_get_totals(const thz_run *run, thz_run_totals *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!run)
        return;
    const run_result *r = &run->rs.result;
    *out =
        (thz_run_totals){.n_channels = r->n_channels,
                         .n_sensors = r->n_sensors,
                         .photons_fired = r->photons_fired,
                         .photons_stored = r->photons_stored,
                         .back_face_samples = r->back_face_samples,
                         .n_warnings = r->n_warnings,
                         .worst_median_stderr_k = r->worst_median_stderr_k,
                         .worst_p95_stderr_k = r->worst_p95_stderr_k,
                         .worst_object = r->worst_object == SIZE_MAX ? -1 : (long)r->worst_object,
                         .worst_object_channel = r->worst_object_channel,
                         .worst_object_p95_stderr_k = r->worst_object_p95_stderr_k,
                         .max_passes = r->max_passes,
                         .seconds = r->seconds};
}
