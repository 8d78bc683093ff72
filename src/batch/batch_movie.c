/* The movies of a batch: per sweep value, sensor and channel, [sweep-NN/]S.band-NN.mp4
 * of the brightness temperature, read back from the frames' S.brightness_temperature
 * cubes (so that a resumed batch, whose earlier frames are only on disk, makes the same
 * movies as an uninterrupted one). One colour scale per sensor and channel: the least
 * and greatest finite Tb over every frame of every sweep value. Movies are made only
 * when every frame has frame 0's sensors and channels (a list of scenes or a sweep may
 * change them): else none, and batch.json and a warning say why; the same for the
 * movies of a sensor too large for the encoder (16384 pixels a side with libx264).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/path.h"
#include "io/output.h"

thz_status batch_read_band(const char *path, uint32_t columns, uint32_t rows, size_t channels,
                           size_t channel, float *out, thz_error *err)
{
    size_t n = (size_t)columns * rows;
    /* a finished frame's file gone or cut short (the frame counts as finished by its
     * frame.json alone): the reason, and how to have the frame computed again */
    static const char again[] = "remove the frame's directory and run the batch again to "
                                "compute the frame anew";
    FILE *f = fopen(path, "rb");
    if (!f)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot open (a frame's cube): %s; %s", path,
                             strerror(errno), again);
    int ok = channel < channels && fseek(f, (long)(channel * n * sizeof(float)), SEEK_SET) == 0 &&
             fread(out, sizeof(float), n, f) == n;
    fclose(f);
    if (!ok)
        return thz_error_set(err, THZ_ERR_IO, "%s: shorter than %u x %u x %zu floats; %s", path,
                             columns, rows, channels, again);
    /* ENVI byte order 0 (little-endian): swap on a big-endian host */
    const uint16_t probe = 1;
    if (*(const unsigned char *)&probe == 0)
        for (size_t i = 0; i < n; i++) {
            unsigned char *b = (unsigned char *)&out[i], t;
            t = b[0], b[0] = b[3], b[3] = t;
            t = b[1], b[1] = b[2], b[2] = t;
        }
    return THZ_OK;
}

/* The sensors of sweep value s (from its first frame's scene). */
typedef struct sweep_sensors {
    size_t n;
    thz_sensor_info *info; /* names borrowed from scene */
    thz_scene *scene;
    size_t n_channels;
} sweep_sensors;

static thz_status batch_cube_path(const thz_sequence *seq, const char *outdir, size_t f,
                                  const char *sensor, char *path, size_t size, thz_error *err)
{
    char name[THZ_PATH_MAX];
    if (!output_file_name(name, sizeof name, sensor, "brightness_temperature", ".img") ||
        snprintf(path, size, "%s/%s/%s", outdir, seq->frame_dir[f], name) >= (int)size)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", outdir);
    return THZ_OK;
}

static thz_status batch_one_movie(const thz_sequence *seq, const char *outdir, size_t s,
                                  const thz_sensor_info *si, size_t c, double lo, double hi,
                                  float *band, json_t *movies, thz_error *err)
{
    char path[THZ_PATH_MAX], name[512], cube[THZ_PATH_MAX], quantity[32];
    snprintf(quantity, sizeof quantity, "band-%02zu", c + 1);
    if (!output_file_name(name, sizeof name, si->name, quantity, ".mp4"))
        return thz_error_set(err, THZ_ERR_IO, "%s: a movie's name too long", si->name);
    char sub[40] = "";
    if (seq->has_sweep) {
        batch_sweep_dir(seq, s, sub, sizeof sub - 1);
        strcat(sub, "/");
    }
    if (snprintf(path, sizeof path, "%s/%s%s", outdir, sub, name) >= (int)sizeof path)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", outdir);
    double movie_fps = fmin(fmax(seq->fps, MOVIE_FPS_MIN), MOVIE_FPS_MAX);
    movie_spec spec = {.path = path,
                       .columns = si->columns,
                       .rows = si->rows,
                       .fps = movie_fps,
                       .frame_interval_s = 1.0 / seq->fps,
                       .tb_min_k = lo,
                       .tb_max_k = hi};
    movie_writer *m = NULL;
    thz_status st = movie_open(&spec, &m, err);
    for (size_t i = 0; st == THZ_OK && i < seq->frames; i++) {
        size_t f = s * seq->frames + i;
        st = batch_cube_path(seq, outdir, f, si->name, cube, sizeof cube, err);
        if (st == THZ_OK)
            st = batch_read_band(cube, si->columns, si->rows, si->channels, c, band, err);
        if (st == THZ_OK)
            st = movie_add_frame(m, band, (double)i / seq->fps, err);
    }
    if (st == THZ_OK)
        st = movie_finish(m, err);
    char codec[32];
    snprintf(codec, sizeof codec, "%s", movie_codec(m));
    movie_destroy(m);
    if (st != THZ_OK)
        return st;
    movie_layout l;
    movie_layout_of(si->columns, si->rows, &l);
    json_t *e = json_object(), *scale = json_object(), *layout = json_object();
    char file[600];
    snprintf(file, sizeof file, "%s%s", sub, name);
    json_object_set_new(e, "file", thz_json_text(file));
    json_object_set_new(e, "sensor", json_string(si->name));
    json_object_set_new(e, "band", json_integer((json_int_t)(c + 1)));
    json_object_set_new(e, "sweep", json_integer((json_int_t)s));
    json_object_set_new(e, "quantity", json_string("brightness_temperature"));
    json_object_set_new(e, "frames", json_integer((json_int_t)seq->frames));
    json_object_set_new(e, "fps", json_real(movie_fps));
    json_object_set_new(e, "codec", json_string(codec));
    json_object_set_new(scale, "min_k", json_real(lo));
    json_object_set_new(scale, "max_k", json_real(hi));
    json_object_set_new(scale, "colour_map", json_string("viridis"));
    json_object_set_new(e, "colour_scale", scale);
    json_object_set_new(layout, "image_x_px", json_integer(l.image_x));
    json_object_set_new(layout, "image_y_px", json_integer(l.image_y));
    json_object_set_new(layout, "pixel_px", json_integer(l.pixel));
    json_object_set_new(layout, "width_px", json_integer(l.width));
    json_object_set_new(layout, "height_px", json_integer(l.height));
    json_object_set_new(e, "layout", layout);
    json_array_append_new(movies, e);
    return THZ_OK;
}

/* Whether scene b has the sensors (names, sizes) and channels (centres, widths) of a;
 * if not, why, in why. */
static int batch_same_frame_shape(const thz_scene *a, const thz_scene *b, char *why, size_t size)
{
    size_t ns = thz_scene_sensor_count(a), nc = thz_scene_channel_count(a);
    if (thz_scene_sensor_count(b) != ns || thz_scene_channel_count(b) != nc) {
        snprintf(why, size, "it has %zu sensors and %zu channels, frame 0 %zu and %zu",
                 thz_scene_sensor_count(b), thz_scene_channel_count(b), ns, nc);
        return 0;
    }
    for (size_t k = 0; k < ns; k++) {
        thz_sensor_info x, y;
        thz_scene_sensor(a, k, &x);
        thz_scene_sensor(b, k, &y);
        if (strcmp(x.name, y.name) || x.columns != y.columns || x.rows != y.rows) {
            snprintf(why, size,
                     "its sensor %zu is \"%s\" of %u x %u pixels, frame 0's \"%s\" of %u x %u",
                     k + 1, y.name, y.columns, y.rows, x.name, x.columns, x.rows);
            return 0;
        }
    }
    for (size_t c = 0; c < nc; c++) {
        thz_channel_info x, y;
        thz_scene_channel(a, c, &x);
        thz_scene_channel(b, c, &y);
        if (x.frequency_hz != y.frequency_hz || x.bandwidth_hz != y.bandwidth_hz) {
            snprintf(why, size,
                     "its channel %zu is at %g THz, frame 0's at %g THz (or their widths differ)",
                     c + 1, y.frequency_thz, x.frequency_thz);
            return 0;
        }
    }
    return 1;
}

int batch_movie_sizes(const thz_scene *scene, char *why, size_t size)
{
    why[0] = '\0';
    size_t len = 0;
    for (size_t k = 0; k < thz_scene_sensor_count(scene); k++) {
        thz_sensor_info si;
        movie_limit lim;
        thz_scene_sensor(scene, k, &si);
        if (movie_fits(si.columns, si.rows, &lim))
            continue;
        int n = snprintf(why + len, size - len,
                         "%sno movies of sensor \"%s\": its %u x %u pixels make movie frames of "
                         "%u x %u pixels, and %s takes at most %u x %u",
                         len ? "; " : "", si.name, si.columns, si.rows, lim.width, lim.height,
                         lim.codec, lim.max_side, lim.max_side);
        len = n > 0 && (size_t)n < size - len ? len + (size_t)n : size - 1;
    }
    return why[0] == '\0';
}

/* Loads the first frame's scene of every sweep value into sw; checks that every frame
 * has frame 0's sensors and channels (else says why in skipped and returns THZ_OK). */
static thz_status batch_movie_sensors(const thz_sequence *seq, sweep_sensors *sw, char *skipped,
                                      size_t skipped_size, thz_error *err)
{
    for (size_t f = 0; f < seq->n_frames; f++) {
        size_t s = f / seq->frames;
        thz_scene *scene = NULL;
        thz_status st = thz_sequence_frame_scene(seq, f, &scene, err);
        if (st != THZ_OK)
            return st;
        char why[400];
        if (f > 0 && !batch_same_frame_shape(sw[0].scene, scene, why, sizeof why)) {
            snprintf(skipped, skipped_size,
                     "no movies: frame %s has other sensors or channels than frame %s (%s); "
                     "a movie needs the same ones in every frame",
                     seq->frame_dir[f], seq->frame_dir[0], why);
            thz_scene_destroy(scene);
            return THZ_OK;
        }
        if (f % seq->frames == 0)
            sw[s].scene = scene;
        else
            thz_scene_destroy(scene);
    }
    for (size_t s = 0; s < seq->n_sweeps; s++) {
        sw[s].n = thz_scene_sensor_count(sw[s].scene);
        sw[s].n_channels = thz_scene_channel_count(sw[s].scene);
        sw[s].info = thz_calloc(sw[s].n ? sw[s].n : 1, sizeof *sw[s].info);
        if (!sw[s].info)
            return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        for (size_t k = 0; k < sw[s].n; k++)
            thz_scene_sensor(sw[s].scene, k, &sw[s].info[k]);
    }
    return THZ_OK;
}

thz_status batch_movies_write(const thz_sequence *seq, const char *outdir, json_t *movies,
                              char *skipped, size_t skipped_size, thz_error *err)
{
    skipped[0] = '\0';
    sweep_sensors *sw = thz_calloc(seq->n_sweeps, sizeof *sw);
    if (!sw)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    float *band = NULL;
    thz_status st = batch_movie_sensors(seq, sw, skipped, skipped_size, err);
    if (st != THZ_OK || skipped[0])
        goto cleanup;
    size_t max_pixels = 0;
    for (size_t k = 0; st == THZ_OK && k < sw[0].n; k++) {
        size_t px = (size_t)sw[0].info[k].columns * sw[0].info[k].rows;
        max_pixels = px > max_pixels ? px : max_pixels;
    }
    band = thz_malloc_array(max_pixels ? max_pixels : 1, sizeof *band);
    if (!band)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    size_t n_sensors = st == THZ_OK ? sw[0].n : 0, n_channels = st == THZ_OK ? sw[0].n_channels : 0;
    /* a sensor too large for the encoder has no movies; the others have theirs */
    if (st == THZ_OK)
        batch_movie_sizes(sw[0].scene, skipped, skipped_size);
    for (size_t k = 0; st == THZ_OK && k < n_sensors; k++)
        for (size_t c = 0; st == THZ_OK && c < n_channels; c++) {
            movie_limit lim;
            if (!movie_fits(sw[0].info[k].columns, sw[0].info[k].rows, &lim))
                break;
            /* the colour scale over every frame of every sweep value */
            double lo = INFINITY, hi = -INFINITY;
            for (size_t f = 0; st == THZ_OK && f < seq->n_frames; f++) {
                const thz_sensor_info *si = &sw[f / seq->frames].info[k];
                char cube[THZ_PATH_MAX];
                st = batch_cube_path(seq, outdir, f, si->name, cube, sizeof cube, err);
                if (st == THZ_OK)
                    st = batch_read_band(cube, si->columns, si->rows, si->channels, c, band, err);
                for (size_t p = 0; st == THZ_OK && p < (size_t)si->columns * si->rows; p++)
                    if (isfinite(band[p])) {
                        lo = fmin(lo, band[p]);
                        hi = fmax(hi, band[p]);
                    }
            }
            if (!(lo <= hi))
                lo = hi = 0.0;
            for (size_t s = 0; st == THZ_OK && s < seq->n_sweeps; s++)
                st = batch_one_movie(seq, outdir, s, &sw[s].info[k], c, lo, hi, band, movies, err);
        }
cleanup:
    free(band);
    for (size_t s = 0; s < seq->n_sweeps; s++) {
        free(sw[s].info);
        thz_scene_destroy(sw[s].scene);
    }
    free(sw);
    return st;
}
