/* The files of one sensor (scene-format.md "Outputs"): the ENVI cubes and truth
 * images, the visual PNG, a brightness-temperature preview per channel and the
 * per-object spectra figure.
 */
#include "io/output.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/path.h"
#include "io/envi.h"
#include "io/plot.h"
#include "io/png_image.h"
#include "sensor/measure.h"

/* Descriptions and titles: text only, a long sensor or scene name may cut them. */
enum { OUT_TEXT = 1024 };

/* float32 holds every integer up to 2^24 exactly: the most objects S.object_id can
 * index (scene-format.md: every ENVI image is float32). */
#define OUT_MAX_OBJECTS (1u << 24)

bool output_file_name(char *buf, size_t size, const char *sensor, const char *quantity,
                      const char *ext)
{
    int n = snprintf(buf, size, "%s.%s%s", sensor, quantity, ext);
    if (n < 0 || (size_t)n >= size)
        return false;
    for (char *p = buf; *p; p++)
        *p = sensor_file_char(*p);
    return true;
}

const char *output_plane_name(thz_plane plane)
{
    static const char *const names[THZ_PLANE_COUNT] = {
        [THZ_PLANE_RADIANCE] = "radiance",
        [THZ_PLANE_RADIANCE_STDERR] = "radiance_stderr",
        [THZ_PLANE_POWER] = "power",
        [THZ_PLANE_BRIGHTNESS_TEMPERATURE] = "brightness_temperature",
        [THZ_PLANE_NORMALIZED] = "normalized",
        [THZ_PLANE_TEMPERATURE] = "temperature",
        [THZ_PLANE_DISTANCE] = "distance",
        [THZ_PLANE_OBJECT_ID] = "object_id",
        [THZ_PLANE_VISUAL_RGB] = "visual",
        [THZ_PLANE_MEASURED_RADIANCE] = "measured_radiance",
        [THZ_PLANE_MEASURED_BRIGHTNESS_TEMPERATURE] = "measured_brightness_temperature"};
    return (unsigned)plane < THZ_PLANE_COUNT ? names[plane] : NULL;
}

/* "<prefix>NN.png" as output_write_sensor numbers a channel's figure (band-%02zu): two
 * digits, or more without a leading 0; "band-1.png" or "band-007.png" is a user's */
static bool out_numbered_png(const char *s, const char *prefix)
{
    size_t n = strlen(prefix);
    if (strncmp(s, prefix, n) != 0)
        return false;
    s += n;
    size_t digits = strspn(s, "0123456789");
    return (digits == 2 || (digits > 2 && s[0] != '0')) && !strcmp(s + digits, ".png");
}

bool output_sensor_file(const char *stem, const char *name)
{
    size_t n = strlen(stem);
    if (strncmp(name, stem, n) != 0)
        return false;
    const char *q = name + n;
    if (!strcmp(q, "visual.png") || !strcmp(q, "spectra.png") || out_numbered_png(q, "band-") ||
        out_numbered_png(q, "measured-band-"))
        return true;
    const char *dot = strrchr(q, '.');
    if (!dot || (strcmp(dot, ".hdr") != 0 && strcmp(dot, ".img") != 0))
        return false;
    for (int p = 0; p < THZ_PLANE_COUNT; p++) { /* S.visual is a PNG, not a cube */
        const char *cube = output_plane_name((thz_plane)p);
        if (p != THZ_PLANE_VISUAL_RGB && strlen(cube) == (size_t)(dot - q) &&
            !strncmp(q, cube, (size_t)(dot - q)))
            return true;
    }
    return false;
}

static thz_status out_file_name(char *buf, size_t size, const char *sensor, const char *quantity,
                                const char *ext, thz_error *err)
{
    if (!output_file_name(buf, size, sensor, quantity, ext))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "sensor %s: file name longer than the limit of %zu bytes: %s%s",
                             sensor, size - 1, quantity, ext);
    return THZ_OK;
}

/* Everything the images of one sensor share. */
typedef struct out_context {
    const char *dir;
    const thz_scene *scene;
    const thz_sensor *sensor;
    const sensor_images *images;
    const char **channel_names; /* n_channels */
    double *center_ghz;
    double *fwhm_ghz;
    const char **object_names; /* n_objects */
    plot_batch *figures;       /* the PNG figures, drawn together at the end */
} out_context;

/* "dir/S.<quantity>.png" into path (THZ_PATH_MAX bytes). */
static thz_status out_png_path(char *path, const out_context *ctx, const char *quantity,
                               thz_error *err)
{
    char name[THZ_PATH_MAX];
    thz_status status = out_file_name(name, sizeof name, ctx->sensor->name, quantity, ".png", err);
    if (status != THZ_OK)
        return status;
    return thz_path_join(path, THZ_PATH_MAX, ctx->dir, name, err);
}

/* What an image's bands are, and so what its header says about them. */
typedef enum out_kind {
    OUT_CHANNELS, /* one band per channel: band names, wavelength and fwhm in GHz */
    OUT_TRUTH,    /* one band, named after the quantity; `data ignore value` is
                     SENSOR_NOTHING_HIT */
    OUT_INDEX     /* a truth image of object indices: also `object names` */
} out_kind;

/* The ENVI image S.<quantity>; `what` and `units` go into its description. */
static thz_status out_image(const out_context *ctx, out_kind kind, const char *quantity,
                            const float *data, const char *what, const char *units, thz_error *err)
{
    char stem[THZ_PATH_MAX], description[OUT_TEXT];
    thz_status status = out_file_name(stem, sizeof stem, ctx->sensor->name, quantity, "", err);
    if (status != THZ_OK)
        return status;
    snprintf(description, sizeof description, "thzmap %s: %s [%s]; sensor %s; scene %s",
             THZ_VERSION_STRING, what, units, ctx->sensor->name, ctx->scene->name);
    const char *band_names[] = {quantity};
    envi_info info = {
        .description = description,
        .data_units = units,
        .samples = ctx->images->columns,
        .lines = ctx->images->rows,
        .bands = 1,
        .band_names = band_names,
    };
    if (kind == OUT_CHANNELS) {
        info.bands = ctx->images->n_channels;
        info.band_names = ctx->channel_names;
        info.wavelength_ghz = ctx->center_ghz;
        info.fwhm_ghz = ctx->fwhm_ghz;
    } else {
        info.has_ignore_value = 1;
        info.ignore_value = SENSOR_NOTHING_HIT;
    }
    if (kind == OUT_INDEX) {
        info.object_names = ctx->object_names;
        info.n_object_names = ctx->scene->n_objects;
    }
    return envi_write_float32(ctx->dir, stem, &info, data, err);
}

/* S.object_id: the indices as float32 like every ENVI image (exact, the scene having at
 * most OUT_MAX_OBJECTS objects), -1.0 (SENSOR_NOTHING_HIT) where nothing is hit. */
static thz_status out_object_id(const out_context *ctx, thz_error *err)
{
    size_t pixels = (size_t)ctx->images->columns * ctx->images->rows;
    float *ids = thz_malloc_array(pixels, sizeof *ids);
    if (!ids)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t p = 0; p < pixels; p++)
        ids[p] = (float)ctx->images->object_id[p];
    thz_status status =
        out_image(ctx, OUT_INDEX, "object_id", ids,
                  "index of the object seen into the scene's objects (see object names); -1 where "
                  "nothing is hit",
                  "1", err);
    free(ids);
    return status;
}

/* S.band-NN.png: brightness temperature of channel c, the quantity a user reads in
 * kelvin without knowing T_ref. */
static thz_status out_band_preview(const out_context *ctx, size_t c, thz_error *err)
{
    char quantity[64], path[THZ_PATH_MAX], title[OUT_TEXT];
    snprintf(quantity, sizeof quantity, "band-%02zu", c + 1);
    thz_status status = out_png_path(path, ctx, quantity, err);
    if (status != THZ_OK)
        return status;
    const thz_channel *ch = &ctx->scene->channels[c];
    snprintf(title, sizeof title, "%s: channel %zu, %s (%.4g GHz)", ctx->sensor->name, c + 1,
             ch->name, ch->center_hz / 1e9);
    size_t pixels = (size_t)ctx->images->columns * ctx->images->rows;
    return plot_batch_image(ctx->figures, path, ctx->images->brightness_temperature + c * pixels,
                            ctx->images->columns, ctx->images->rows, title,
                            "brightness temperature T#db#u (K)", err);
}

/* S.measured-band-NN.png: the measured brightness temperature of channel c, its title
 * naming the sensor model that made it. */
static thz_status out_measured_preview(const out_context *ctx, size_t c, thz_error *err)
{
    char quantity[64], path[THZ_PATH_MAX], title[OUT_TEXT], model[512];
    snprintf(quantity, sizeof quantity, "measured-band-%02zu", c + 1);
    thz_status status = out_png_path(path, ctx, quantity, err);
    if (status != THZ_OK)
        return status;
    const thz_channel *ch = &ctx->scene->channels[c];
    sensor_model_describe(ctx->sensor, c, ctx->images->n_channels, ctx->images->noise_seed, model,
                          sizeof model);
    snprintf(title, sizeof title, "%s, %.4g GHz: %s", ctx->sensor->name, ch->center_hz / 1e9,
             model);
    size_t pixels = (size_t)ctx->images->columns * ctx->images->rows;
    return plot_batch_image(ctx->figures, path,
                            ctx->images->measured_brightness_temperature + c * pixels,
                            ctx->images->columns, ctx->images->rows, title,
                            "measured brightness temperature T#db#u (K)", err);
}

/* The measured cubes and their previews, when the sensor has a model. */
static thz_status out_measured(const out_context *ctx, thz_error *err)
{
    const sensor_images *img = ctx->images;
    if (!img->measured_radiance)
        return THZ_OK;
    char model[512], what[OUT_TEXT];
    sensor_model_describe(ctx->sensor, SIZE_MAX, img->n_channels, img->noise_seed, model,
                          sizeof model);
    snprintf(what, sizeof what, "measured band-mean spectral radiance L_c (%s)", model);
    thz_status status = out_image(ctx, OUT_CHANNELS, "measured_radiance", img->measured_radiance,
                                  what, "W m-2 sr-1 Hz-1", err);
    snprintf(what, sizeof what, "measured brightness temperature Tb_c (%s)", model);
    if (status == THZ_OK)
        status = out_image(ctx, OUT_CHANNELS, "measured_brightness_temperature",
                           img->measured_brightness_temperature, what, "K", err);
    for (size_t c = 0; c < img->n_channels && status == THZ_OK; c++)
        status = out_measured_preview(ctx, c, err);
    return status;
}

/* S.spectra.png: for each object in view, the mean normalised radiance N_c of its
 * pixels against the channel centres (the paper's Fig. 6). */
static thz_status out_spectra(const out_context *ctx, thz_error *err)
{
    const thz_scene *scene = ctx->scene;
    const sensor_images *img = ctx->images;
    size_t n_obj = scene->n_objects, n_ch = img->n_channels;
    thz_status status = THZ_OK;
    uint64_t *count = thz_calloc(n_obj, sizeof *count);
    double *mean = thz_calloc(n_obj * n_ch, sizeof *mean);
    double *y = thz_calloc(n_obj * n_ch, sizeof *y);
    double *x = thz_calloc(n_ch, sizeof *x);
    const char **names = thz_calloc(n_obj, sizeof *names);
    if (!count || !mean || !y || !x || !names) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    sensor_images_object_means(img, img->normalized, n_obj, count, mean);
    size_t n_lines = 0;
    for (size_t o = 0; o < n_obj; o++) {
        if (!count[o])
            continue;
        names[n_lines] = scene->objects[o].name;
        memcpy(&y[n_lines * n_ch], &mean[o * n_ch], n_ch * sizeof *y);
        n_lines++;
    }
    for (size_t c = 0; c < n_ch; c++)
        x[c] = scene->channels[c].center_hz / 1e12;
    char path[THZ_PATH_MAX], title[OUT_TEXT], y_label[OUT_TEXT];
    status = out_png_path(path, ctx, "spectra", err);
    if (status != THZ_OK)
        goto cleanup;
    snprintf(title, sizeof title, "%s: mean normalised radiance of each object in view",
             ctx->sensor->name);
    snprintf(y_label, sizeof y_label, "L / B(T#dref#u = %.6g K) (1)", ctx->sensor->normalize_to_k);
    status = plot_batch_lines(ctx->figures, path, n_ch, x, n_lines, names, y, title,
                              "frequency (THz)", y_label, err);
cleanup:
    free(count);
    free(mean);
    free(y);
    free(x);
    free(names);
    return status;
}

thz_status output_write_sensor(const char *dir, const thz_scene *scene, size_t sensor,
                               const sensor_images *images, int threads, const cancel_check *cancel,
                               thz_error *err)
{
    if (sensor >= scene->n_sensors || images->n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "output_write_sensor: sensor %zu or channel count out of range",
                             sensor);
    if (scene->n_objects > OUT_MAX_OBJECTS)
        return thz_error_set(err, THZ_ERR_LIMIT,
                             "%zu objects: %s.object_id holds at most %u (float32 indices)",
                             scene->n_objects, scene->sensors[sensor].name, OUT_MAX_OBJECTS);
    thz_status status = plot_check_device(err);
    if (status != THZ_OK)
        return status;
    size_t n_ch = scene->n_channels;
    out_context ctx = {
        .dir = dir, .scene = scene, .sensor = &scene->sensors[sensor], .images = images};
    ctx.channel_names = thz_calloc(n_ch, sizeof *ctx.channel_names);
    ctx.center_ghz = thz_calloc(n_ch, sizeof *ctx.center_ghz);
    ctx.fwhm_ghz = thz_calloc(n_ch, sizeof *ctx.fwhm_ghz);
    ctx.object_names = thz_calloc(scene->n_objects, sizeof *ctx.object_names);
    ctx.figures = plot_batch_create();
    if (!ctx.channel_names || !ctx.center_ghz || !ctx.fwhm_ghz || !ctx.object_names ||
        !ctx.figures) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t c = 0; c < n_ch; c++) {
        const thz_channel *ch = &scene->channels[c];
        ctx.channel_names[c] = ch->name;
        ctx.center_ghz[c] = ch->center_hz / 1e9;
        ctx.fwhm_ghz[c] = channel_fwhm_hz(ch) / 1e9;
    }
    for (size_t i = 0; i < scene->n_objects; i++)
        ctx.object_names[i] = scene->objects[i].name;

    status = out_image(&ctx, OUT_CHANNELS, "radiance", images->radiance,
                       "band-mean spectral radiance L_c", "W m-2 sr-1 Hz-1", err);
    if (status == THZ_OK && images->radiance_stderr)
        status = out_image(&ctx, OUT_CHANNELS, "radiance_stderr", images->radiance_stderr,
                           "standard error of L_c", "W m-2 sr-1 Hz-1", err);
    if (status == THZ_OK)
        status = out_image(&ctx, OUT_CHANNELS, "power", images->power, "power on the pixel P_c",
                           "W", err);
    if (status == THZ_OK)
        status = out_image(&ctx, OUT_CHANNELS, "brightness_temperature",
                           images->brightness_temperature, "brightness temperature Tb_c", "K", err);
    if (status == THZ_OK) {
        char what[256];
        snprintf(what, sizeof what, "normalised radiance N_c = L_c / B(T_ref = %.6g K)",
                 ctx.sensor->normalize_to_k);
        status = out_image(&ctx, OUT_CHANNELS, "normalized", images->normalized, what, "1", err);
    }
    if (status == THZ_OK)
        status = out_image(&ctx, OUT_TRUTH, "temperature", images->temperature_k,
                           "temperature of the surface seen (-1: nothing hit)", "K", err);
    if (status == THZ_OK)
        status = out_image(&ctx, OUT_TRUTH, "distance", images->distance_m,
                           "distance to the surface seen (-1: nothing hit)", "m", err);
    if (status == THZ_OK)
        status = out_object_id(&ctx, err);
    if (status == THZ_OK) {
        char path[THZ_PATH_MAX];
        status = out_png_path(path, &ctx, "visual", err);
        if (status == THZ_OK)
            status =
                png_image_write_srgb8(path, images->visual_rgb, images->columns, images->rows, err);
    }
    for (size_t c = 0; c < n_ch && status == THZ_OK; c++)
        status = out_band_preview(&ctx, c, err);
    if (status == THZ_OK)
        status = out_spectra(&ctx, err);
    if (status == THZ_OK)
        status = out_measured(&ctx, err);
    if (status == THZ_OK)
        status = plot_batch_run(ctx.figures, threads, cancel, err);
cleanup:
    plot_batch_destroy(ctx.figures);
    free(ctx.channel_names);
    free(ctx.center_ghz);
    free(ctx.fwhm_ghz);
    free(ctx.object_names);
    return status;
}
