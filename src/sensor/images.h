/* The images one sensor produces: the per-channel cubes and the truth images
 * (scene-format.md "Outputs"). Row 0 is the top of the picture (the `up` side),
 * column 0 the left. Cubes are band-sequential: value(c, row, col) is at
 * [(c * rows + row) * columns + col].
 */
#ifndef THZ_SENSOR_IMAGES_H
#define THZ_SENSOR_IMAGES_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* The truth images' value where nothing is hit: no temperature (0 K is a valid object
 * temperature) or distance can be negative, and object_id's -1 is the same number, so
 * one `data ignore value` covers all three. */
#define SENSOR_NOTHING_HIT (-1.0f)

typedef struct sensor_images {
    uint32_t columns, rows;
    size_t n_channels;
    float *radiance;               /* L_c, W m^-2 sr^-1 Hz^-1 */
    float *radiance_stderr;        /* standard error of L_c (NULL when not estimated) */
    float *power;                  /* P_c, W */
    float *brightness_temperature; /* Tb_c, K */
    float *normalized;             /* N_c, 1 */
    float *temperature_k; /* 1 band: temperature of the surface seen, K (SENSOR_NOTHING_HIT) */
    float *distance_m;    /* 1 band: distance to the surface seen, m (SENSOR_NOTHING_HIT) */
    int32_t *object_id;   /* 1 band: index into scene objects, -1: nothing hit */
    float *visual_rgb;    /* rows x columns x 3, shaded colours 0..1 */
    /* The sensor as built (sensor/measure.h): the noise-free radiance through the PSF,
     * plus noise; NULL when the sensor has neither (psf none, no noise). */
    float *measured_radiance;               /* W m^-2 sr^-1 Hz^-1 */
    float *measured_brightness_temperature; /* K */
    uint64_t noise_seed;                    /* the seed the noise was drawn with */
} sensor_images;

/* Allocates all arrays, the cubes zeroed and the truth images at "nothing hit" (-1);
 * radiance_stderr only when with_stderr. */
thz_status sensor_images_init(sensor_images *img, uint32_t columns, uint32_t rows,
                              size_t n_channels, int with_stderr, thz_error *err);
/* sensor_images_init without writing the truth images, for a caller that fills every
 * pixel of them (render_sensor_truth): a large image's memory is then first touched in
 * that cancellable loop, not here (first touch costs seconds per GB on some machines). */
thz_status sensor_images_alloc(sensor_images *img, uint32_t columns, uint32_t rows,
                               size_t n_channels, int with_stderr, thz_error *err);
void sensor_images_fini(sensor_images *img);

/* Each object's mean of cube (one of img's, n_channels bands) over the pixels that see it:
 * count[o] its pixels and mean[o * n_channels + c] channel c's mean (0 where count[o] is
 * 0), for objects 0 to n_objects - 1 (object_id outside them is nothing hit). */
void sensor_images_object_means(const sensor_images *img, const float *cube, size_t n_objects,
                                uint64_t *count, double *mean);

/* Bytes the images of a sensor take (to refuse runs that would not fit). */
uint64_t sensor_images_bytes(uint32_t columns, uint32_t rows, size_t n_channels);

#endif
