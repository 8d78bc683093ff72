/* Allocation of a sensor's images. */
#include "sensor/images.h"

#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

uint64_t sensor_images_bytes(uint32_t columns, uint32_t rows, size_t n_channels)
{
    uint64_t pixels = (uint64_t)columns * rows;
    /* 5 cubes (with stderr), 3 truth images, 3 visual channels, 4 bytes each */
    return pixels * 4u * (5u * (uint64_t)n_channels + 3u + 3u);
}

thz_status sensor_images_alloc(sensor_images *img, uint32_t columns, uint32_t rows,
                               size_t n_channels, int with_stderr, thz_error *err)
{
    memset(img, 0, sizeof *img);
    img->columns = columns;
    img->rows = rows;
    img->n_channels = n_channels;
    size_t pixels = (size_t)columns * rows;
    size_t cube = pixels * n_channels;
    if (n_channels && cube / n_channels != pixels)
        return thz_error_set(err, THZ_ERR_LIMIT, "sensor image of %u x %u x %zu is too large",
                             columns, rows, n_channels);
    img->radiance = thz_calloc(cube, sizeof(float));
    img->power = thz_calloc(cube, sizeof(float));
    img->brightness_temperature = thz_calloc(cube, sizeof(float));
    img->normalized = thz_calloc(cube, sizeof(float));
    img->radiance_stderr = with_stderr ? thz_calloc(cube, sizeof(float)) : NULL;
    img->temperature_k = thz_malloc_array(pixels, sizeof(float));
    img->distance_m = thz_malloc_array(pixels, sizeof(float));
    img->object_id = thz_malloc_array(pixels, sizeof(int32_t));
    img->visual_rgb = thz_calloc(pixels, 3 * sizeof(float));
    if (!img->radiance || !img->power || !img->brightness_temperature || !img->normalized ||
        (with_stderr && !img->radiance_stderr) || !img->temperature_k || !img->distance_m ||
        !img->object_id || !img->visual_rgb) {
        sensor_images_fini(img);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a %u x %u x %zu image", columns,
                             rows, n_channels);
    }
    return THZ_OK;
}

thz_status sensor_images_init(sensor_images *img, uint32_t columns, uint32_t rows,
                              size_t n_channels, int with_stderr, thz_error *err)
{
    thz_status st = sensor_images_alloc(img, columns, rows, n_channels, with_stderr, err);
    if (st != THZ_OK)
        return st;
    size_t pixels = (size_t)columns * rows;
    for (size_t i = 0; i < pixels; i++) {
        img->temperature_k[i] = SENSOR_NOTHING_HIT;
        img->distance_m[i] = SENSOR_NOTHING_HIT;
        img->object_id[i] = (int32_t)SENSOR_NOTHING_HIT;
    }
    return THZ_OK;
}

void sensor_images_object_means(const sensor_images *img, const float *cube, size_t n_objects,
                                uint64_t *count, double *mean)
{
    size_t n_ch = img->n_channels, pixels = (size_t)img->columns * img->rows;
    memset(count, 0, n_objects * sizeof *count);
    memset(mean, 0, n_objects * n_ch * sizeof *mean);
    for (size_t p = 0; p < pixels; p++) {
        int32_t id = img->object_id[p];
        if (id < 0 || (size_t)id >= n_objects)
            continue;
        count[id]++;
        for (size_t c = 0; c < n_ch; c++)
            mean[(size_t)id * n_ch + c] += cube[c * pixels + p];
    }
    for (size_t o = 0; o < n_objects; o++)
        for (size_t c = 0; count[o] && c < n_ch; c++)
            mean[o * n_ch + c] /= (double)count[o];
}

void sensor_images_fini(sensor_images *img)
{
    free(img->radiance);
    free(img->radiance_stderr);
    free(img->power);
    free(img->brightness_temperature);
    free(img->normalized);
    free(img->temperature_k);
    free(img->distance_m);
    free(img->object_id);
    free(img->visual_rgb);
    free(img->measured_radiance);
    free(img->measured_brightness_temperature);
    memset(img, 0, sizeof *img);
}
