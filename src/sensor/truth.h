/* The truth images of a sensor (scene-format.md "Outputs"): what the ray through each
 * pixel's centre hits first, with no physics beyond the geometry.
 */
#ifndef THZ_SENSOR_TRUTH_H
#define THZ_SENSOR_TRUTH_H

#include <stddef.h>

#include "accel/accel.h"
#include "core/error.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "sensor/render.h"

/* Fills the truth images of `sensor` (temperature_k, distance_m, object_id, visual_rgb)
 * from the first hit of the ray through each pixel's centre: 0, 0, -1 and black where
 * it hits nothing; visual = material colour x (0.25 + 0.75 |cos theta|). */
thz_status render_sensor_truth(const thz_scene *scene, const accel *a, size_t sensor,
                               sensor_images *images, const render_options *opt, thz_error *err);

#endif
