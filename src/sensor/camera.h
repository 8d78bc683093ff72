/* The sensor's camera model (physics.md "Rendering phase"): a pinhole at position_m
 * looking along `direction`, with `up` orthogonalised against it, a horizontal field of
 * view, square pixels (the vertical field follows from the resolution), and n x n
 * regular oversampling with sample centres at (i + 0.5)/n within the pixel.
 *
 * Image-plane coordinates: the plane at unit distance in front of the pinhole, x to the
 * right (right = direction x up, right-handed), y up. Column 0 is the left edge, row 0
 * the top (the `up` side). Pixel (col, row) covers
 *   x in [-W + col*s, -W + (col+1)*s],  y in [H - (row+1)*s, H - row*s]
 * with s = 2W/columns the pixel pitch, W = tan(fov/2) and H = rows*s/2.
 */
#ifndef THZ_SENSOR_CAMERA_H
#define THZ_SENSOR_CAMERA_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec3.h"
#include "scene/scene.h"

typedef struct camera {
    vec3 position_m;
    vec3 forward, right, up; /* orthonormal; right = forward x up */
    double half_width;       /* W = tan(fov/2), on the unit-distance image plane */
    double half_height;      /* H = W * rows / columns */
    double pixel_pitch;      /* s = 2W / columns (square pixels) */
    uint32_t columns, rows, oversampling;
} camera;

/* Sets up the camera of `sensor`. THZ_ERR_INPUT if the direction is zero or parallel
 * to up, the field of view is outside (0, 180) degrees or the resolution is 0. */
thz_status camera_init(camera *cam, const thz_sensor *sensor, thz_error *err);

/* Unit direction through the image-plane point (x, y). */
vec3 camera_plane_dir(const camera *cam, double x, double y);

/* Unit direction of sample (i, j) (i across, j down, 0..n-1) of pixel (col, row). */
vec3 camera_sample_dir(const camera *cam, uint32_t col, uint32_t row, uint32_t i, uint32_t j);

/* Unit direction through the centre of pixel (col, row). */
vec3 camera_pixel_center_dir(const camera *cam, uint32_t col, uint32_t row);

/* Exact solid angle (sr) of pixel (col, row): Omega_S. */
double camera_pixel_solid_angle(const camera *cam, uint32_t col, uint32_t row);

/* Exact solid angle (sr) of the image-plane rectangle [x0, x1] x [y0, y1] (x0 < x1,
 * y0 < y1) seen from the pinhole at unit distance: the Van Oosterom-Strackee formula
 * on its two triangles, with the triple product taken from the planar area so that it
 * stays accurate for tiny pixels. */
double camera_rectangle_solid_angle(double x0, double x1, double y0, double y1);

/* Solid angle (sr) of the whole image, 4 asin(sin a sin b) with a, b the horizontal and
 * vertical half-angles. */
double camera_image_solid_angle(const camera *cam);

#endif
