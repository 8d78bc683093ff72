/* The truth images of a sensor: see truth.h. */
#include "sensor/truth.h"

#include <math.h>
#include <omp.h>
#include <stdatomic.h>

#include "core/clock.h"
#include "core/threads.h"

#include "sensor/camera.h"

thz_status render_sensor_truth(const thz_scene *scene, const accel *a, size_t sensor,
                               sensor_images *images, const render_options *opt, thz_error *err)
{
    if (sensor >= scene->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: sensor %zu out of range", sensor);
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    int64_t n_px = (int64_t)cam.columns * cam.rows;
    int threads = thz_threads_or_all(opt ? opt->threads : 0);
    /* about 16 M pixels take seconds: poll for cancelling */
    render_poll poll = {
        .opt = opt, .scene = scene, .total = sn->rows, .next_s = thz_now_s() + RENDER_POLL_S};
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
    for (int64_t px = 0; px < n_px; px++) {
        if (render_poll_stop(&poll))
            continue;
        uint32_t row = (uint32_t)(px / cam.columns), col = (uint32_t)(px % cam.columns);
        vec3 dir = camera_pixel_center_dir(&cam, col, row);
        accel_hit hit;
        float *rgb = &images->visual_rgb[3 * (size_t)px];
        if (!accel_intersect(a, cam.position_m, dir, INFINITY, ACCEL_NO_OBJECT, 0, &hit)) {
            images->temperature_k[px] = SENSOR_NOTHING_HIT;
            images->distance_m[px] = SENSOR_NOTHING_HIT;
            images->object_id[px] = -1;
            rgb[0] = rgb[1] = rgb[2] = 0.0f;
            continue;
        }
        const thz_object *obj = &scene->objects[hit.object];
        const double *color = scene->materials[obj->material].color;
        double shade = 0.25 + 0.75 * fabs(hit.cos_theta);
        images->temperature_k[px] = (float)obj->temperature_k;
        images->distance_m[px] = (float)hit.distance_m;
        images->object_id[px] = (int32_t)hit.object;
        for (int c = 0; c < 3; c++)
            rgb[c] = (float)(color[c] * shade);
    }
    if (atomic_load(&poll.stop))
        return thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
    return THZ_OK;
}
