/* Pinhole camera: ray directions of pixel samples and exact pixel solid angles. */
#include "sensor/camera.h"

#include <math.h>

thz_status camera_init(camera *cam, const thz_sensor *sensor, thz_error *err)
{
    vec3 f = v3_normalize(v3_from_array(sensor->direction));
    vec3 up = v3_normalize(v3_from_array(sensor->up));
    vec3 r = v3_cross(f, up);
    double rl = v3_length(r);
    if (v3_length(f) == 0.0 || rl < 1e-9)
        return thz_error_set(err, THZ_ERR_INPUT, "sensor '%s': direction is zero or parallel to up",
                             sensor->name);
    if (!(sensor->fov_deg > 0.0 && sensor->fov_deg < 180.0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "sensor '%s': fov_deg must lie in (0, 180) deg, got %g deg",
                             sensor->name, sensor->fov_deg);
    if (sensor->columns == 0 || sensor->rows == 0 || sensor->oversampling == 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "sensor '%s': resolution and oversampling must be positive",
                             sensor->name);
    cam->position_m = v3_from_array(sensor->position_m);
    cam->forward = f;
    cam->right = v3_scale(r, 1.0 / rl);
    cam->up = v3_cross(cam->right, f); /* unit: right and f are orthonormal */
    cam->columns = sensor->columns;
    cam->rows = sensor->rows;
    cam->oversampling = sensor->oversampling;
    cam->half_width = tan(0.5 * sensor->fov_deg * M_PI / 180.0);
    cam->pixel_pitch = 2.0 * cam->half_width / (double)sensor->columns;
    cam->half_height = 0.5 * cam->pixel_pitch * (double)sensor->rows;
    return THZ_OK;
}

vec3 camera_plane_dir(const camera *cam, double x, double y)
{
    vec3 d = v3_madd(v3_madd(cam->forward, x, cam->right), y, cam->up);
    return v3_normalize(d);
}

vec3 camera_sample_dir(const camera *cam, uint32_t col, uint32_t row, uint32_t i, uint32_t j)
{
    double n = (double)cam->oversampling;
    double x = -cam->half_width + ((double)col + ((double)i + 0.5) / n) * cam->pixel_pitch;
    double y = cam->half_height - ((double)row + ((double)j + 0.5) / n) * cam->pixel_pitch;
    return camera_plane_dir(cam, x, y);
}

vec3 camera_pixel_center_dir(const camera *cam, uint32_t col, uint32_t row)
{
    double x = -cam->half_width + ((double)col + 0.5) * cam->pixel_pitch;
    double y = cam->half_height - ((double)row + 0.5) * cam->pixel_pitch;
    return camera_plane_dir(cam, x, y);
}

/* Solid angle of the triangle (a, b, c) on the plane z = 1 (Van Oosterom & Strackee
 * 1983): tan(Omega/2) = |a.(b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|).
 * For points on z = 1 the triple product is twice the planar area, given by the caller
 * as `twice_area` to avoid cancellation between nearly parallel vectors. */
static double camera_triangle_solid_angle(const double a[2], const double b[2], const double c[2],
                                          double twice_area)
{
    vec3 va = v3(a[0], a[1], 1.0), vb = v3(b[0], b[1], 1.0), vc = v3(c[0], c[1], 1.0);
    double la = v3_length(va), lb = v3_length(vb), lc = v3_length(vc);
    double den = la * lb * lc + v3_dot(va, vb) * lc + v3_dot(va, vc) * lb + v3_dot(vb, vc) * la;
    return 2.0 * atan2(fabs(twice_area), den);
}

double camera_rectangle_solid_angle(double x0, double x1, double y0, double y1)
{
    double p00[2] = {x0, y0}, p10[2] = {x1, y0}, p11[2] = {x1, y1}, p01[2] = {x0, y1};
    double twice_area = (x1 - x0) * (y1 - y0);
    return camera_triangle_solid_angle(p00, p10, p11, twice_area) +
           camera_triangle_solid_angle(p00, p11, p01, twice_area);
}

double camera_pixel_solid_angle(const camera *cam, uint32_t col, uint32_t row)
{
    double s = cam->pixel_pitch;
    double x0 = -cam->half_width + (double)col * s;
    double y1 = cam->half_height - (double)row * s;
    return camera_rectangle_solid_angle(x0, x0 + s, y1 - s, y1);
}

double camera_image_solid_angle(const camera *cam)
{
    double a = atan(cam->half_width), b = atan(cam->half_height);
    return 4.0 * asin(sin(a) * sin(b));
}
