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
#include "io/envi.h"
#include "io/plot.h"
#include "io/png_image.h"

enum { OUT_NAME = 1024 };

/* The file stem "S.<quantity>", with '/' in the sensor name replaced so that every
 * file lands in dir. */
static void out_stem(char *buf, size_t size, const char *sensor, const char *quantity)
{
    snprintf(buf, size, "%s.%s", sensor, quantity);
    for (char *p = buf; *p; p++)
        if (*p == '/')
            *p = '_';
}

/* Everything the cubes of one sensor share. */
typedef struct out_context {
    const char *dir;
    const thz_scene *scene;
    const thz_sensor *sensor;
    const sensor_images *images;
    const char **channel_names; /* n_channels */
    double *center_ghz;
    double *fwhm_ghz;
} out_context;

static thz_status out_cube(const out_context *ctx, const char *quantity, const float *data,
                           const char *what, const char *units, thz_error *err)
{
    char stem[OUT_NAME], description[OUT_NAME];
    out_stem(stem, sizeof stem, ctx->sensor->name, quantity);
    snprintf(description, sizeof description, "thzmap %s: %s [%s]; sensor %s; scene %s",
             THZ_VERSION_STRING, what, units, ctx->sensor->name, ctx->scene->name);
    envi_info info = {
        .description = description,
        .data_units = units,
        .samples = ctx->images->columns,
        .lines = ctx->images->rows,
        .bands = ctx->images->n_channels,
        .band_names = ctx->channel_names,
        .wavelength_ghz = ctx->center_ghz,
        .fwhm_ghz = ctx->fwhm_ghz,
    };
    return envi_write_float32(ctx->dir, stem, &info, data, err);
}

static thz_status out_truth(const out_context *ctx, const char *quantity, const float *data,
                            const char *what, const char *units, thz_error *err)
{
    char stem[OUT_NAME], description[OUT_NAME];
    out_stem(stem, sizeof stem, ctx->sensor->name, quantity);
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
    return envi_write_float32(ctx->dir, stem, &info, data, err);
}

static thz_status out_object_id(const out_context *ctx, thz_error *err)
{
    char stem[OUT_NAME], description[OUT_NAME];
    out_stem(stem, sizeof stem, ctx->sensor->name, "object_id");
    snprintf(description, sizeof description,
             "thzmap %s: index of the object seen into the scene's objects (see object "
             "names); -1 where nothing is hit; sensor %s; scene %s",
             THZ_VERSION_STRING, ctx->sensor->name, ctx->scene->name);
    const char *band_names[] = {"object_id"};
    const thz_scene *scene = ctx->scene;
    const char **names = thz_calloc(scene->n_objects, sizeof *names);
    if (!names)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < scene->n_objects; i++)
        names[i] = scene->objects[i].name;
    envi_info info = {
        .description = description,
        .data_units = "index",
        .samples = ctx->images->columns,
        .lines = ctx->images->rows,
        .bands = 1,
        .band_names = band_names,
        .has_ignore_value = 1,
        .ignore_value = -1.0,
        .object_names = names,
        .n_object_names = scene->n_objects,
    };
    thz_status status = envi_write_int32(ctx->dir, stem, &info, ctx->images->object_id, err);
    free(names);
    return status;
}

/* S.band-NN.png: brightness temperature of channel c, the quantity a user reads in
 * kelvin without knowing T_ref. */
static thz_status out_band_preview(const out_context *ctx, size_t c, thz_error *err)
{
    char quantity[64], stem[OUT_NAME], path[OUT_NAME * 2], title[OUT_NAME];
    snprintf(quantity, sizeof quantity, "band-%02zu", c + 1);
    out_stem(stem, sizeof stem, ctx->sensor->name, quantity);
    snprintf(path, sizeof path, "%s/%s.png", ctx->dir, stem);
    const thz_channel *ch = &ctx->scene->channels[c];
    snprintf(title, sizeof title, "%s: channel %zu, %s (%.4g GHz)", ctx->sensor->name, c + 1,
             ch->name, ch->center_hz / 1e9);
    size_t pixels = (size_t)ctx->images->columns * ctx->images->rows;
    return plot_image(path, ctx->images->brightness_temperature + c * pixels, ctx->images->columns,
                      ctx->images->rows, title, "brightness temperature T#db#u (K)", err);
}

/* S.spectra.png: for each object in view, the mean normalised radiance N_c of its
 * pixels against the channel centres (the paper's Fig. 6). */
static thz_status out_spectra(const out_context *ctx, thz_error *err)
{
    const thz_scene *scene = ctx->scene;
    const sensor_images *img = ctx->images;
    size_t n_obj = scene->n_objects, n_ch = img->n_channels;
    size_t pixels = (size_t)img->columns * img->rows;
    thz_status status = THZ_OK;
    uint64_t *count = thz_calloc(n_obj, sizeof *count);
    double *sum = thz_calloc(n_obj * n_ch, sizeof *sum);
    double *y = thz_calloc(n_obj * n_ch, sizeof *y);
    double *x = thz_calloc(n_ch, sizeof *x);
    const char **names = thz_calloc(n_obj, sizeof *names);
    if (!count || !sum || !y || !x || !names) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t p = 0; p < pixels; p++) {
        int32_t id = img->object_id[p];
        if (id < 0 || (size_t)id >= n_obj)
            continue;
        count[id]++;
        for (size_t c = 0; c < n_ch; c++)
            sum[(size_t)id * n_ch + c] += img->normalized[c * pixels + p];
    }
    size_t n_lines = 0;
    for (size_t o = 0; o < n_obj; o++) {
        if (!count[o])
            continue;
        names[n_lines] = scene->objects[o].name;
        for (size_t c = 0; c < n_ch; c++)
            y[n_lines * n_ch + c] = sum[o * n_ch + c] / (double)count[o];
        n_lines++;
    }
    for (size_t c = 0; c < n_ch; c++)
        x[c] = scene->channels[c].center_hz / 1e12;
    char stem[OUT_NAME], path[OUT_NAME * 2], title[OUT_NAME], y_label[OUT_NAME];
    out_stem(stem, sizeof stem, ctx->sensor->name, "spectra");
    snprintf(path, sizeof path, "%s/%s.png", ctx->dir, stem);
    snprintf(title, sizeof title, "%s: mean normalised radiance of each object in view",
             ctx->sensor->name);
    snprintf(y_label, sizeof y_label, "L / B(T#dref#u = %.6g K) (1)", ctx->sensor->normalize_to_k);
    status = plot_lines(path, n_ch, x, n_lines, names, y, title, "frequency (THz)", y_label, err);
cleanup:
    free(count);
    free(sum);
    free(y);
    free(x);
    free(names);
    return status;
}

thz_status output_write_sensor(const char *dir, const thz_scene *scene, size_t sensor,
                               const sensor_images *images, thz_error *err)
{
    if (sensor >= scene->n_sensors || images->n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "output_write_sensor: sensor %zu or channel count out of range",
                             sensor);
    thz_status status = plot_check_device(err);
    if (status != THZ_OK)
        return status;
    size_t n_ch = scene->n_channels;
    out_context ctx = {
        .dir = dir, .scene = scene, .sensor = &scene->sensors[sensor], .images = images};
    ctx.channel_names = thz_calloc(n_ch, sizeof *ctx.channel_names);
    ctx.center_ghz = thz_calloc(n_ch, sizeof *ctx.center_ghz);
    ctx.fwhm_ghz = thz_calloc(n_ch, sizeof *ctx.fwhm_ghz);
    if (!ctx.channel_names || !ctx.center_ghz || !ctx.fwhm_ghz) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t c = 0; c < n_ch; c++) {
        const thz_channel *ch = &scene->channels[c];
        ctx.channel_names[c] = ch->name;
        ctx.center_ghz[c] = ch->center_hz / 1e9;
        ctx.fwhm_ghz[c] = ch->relative_width * ch->center_hz / 1e9;
    }

    status = out_cube(&ctx, "radiance", images->radiance, "band-mean spectral radiance L_c",
                      "W m-2 sr-1 Hz-1", err);
    if (status == THZ_OK && images->radiance_stderr)
        status = out_cube(&ctx, "radiance_stderr", images->radiance_stderr, "standard error of L_c",
                          "W m-2 sr-1 Hz-1", err);
    if (status == THZ_OK)
        status = out_cube(&ctx, "power", images->power, "power on the pixel P_c", "W", err);
    if (status == THZ_OK)
        status = out_cube(&ctx, "brightness_temperature", images->brightness_temperature,
                          "brightness temperature Tb_c", "K", err);
    if (status == THZ_OK) {
        char what[256];
        snprintf(what, sizeof what, "normalised radiance N_c = L_c / B(T_ref = %.6g K)",
                 ctx.sensor->normalize_to_k);
        status = out_cube(&ctx, "normalized", images->normalized, what, "1", err);
    }
    if (status == THZ_OK)
        status = out_truth(&ctx, "temperature", images->temperature_k,
                           "temperature of the surface seen (0: nothing hit)", "K", err);
    if (status == THZ_OK)
        status = out_truth(&ctx, "distance", images->distance_m,
                           "distance to the surface seen (0: nothing hit)", "m", err);
    if (status == THZ_OK)
        status = out_object_id(&ctx, err);
    if (status == THZ_OK) {
        char stem[OUT_NAME], path[OUT_NAME * 2];
        out_stem(stem, sizeof stem, ctx.sensor->name, "visual");
        snprintf(path, sizeof path, "%s/%s.png", dir, stem);
        status =
            png_image_write_srgb8(path, images->visual_rgb, images->columns, images->rows, err);
    }
    for (size_t c = 0; c < n_ch && status == THZ_OK; c++)
        status = out_band_preview(&ctx, c, err);
    if (status == THZ_OK)
        status = out_spectra(&ctx, err);
cleanup:
    free(ctx.channel_names);
    free(ctx.center_ghz);
    free(ctx.fwhm_ghz);
    return status;
}
