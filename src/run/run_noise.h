/* The noise figures of a run: over the rendered pixels of a channel (every selected
 * sensor), the median and the 95th percentile of the per-pixel standard error of Tb_c
 * (K), for the whole picture and per object (the pixels whose truth object_id is that
 * object). The 95th percentile is what a noise target aims at: a median can hide the
 * noisy objects (a metal part, a covered target) behind the walls around them.
 */
#ifndef THZ_RUN_RUN_NOISE_H
#define THZ_RUN_RUN_NOISE_H

#include <stddef.h>

#include "core/error.h"
#include "sensor/images.h"
#include "sensor/render_accum.h"

/* One set of pixels' figures; both 0 when there are no pixels. A pixel whose standard
 * error is unknown (NaN in radiance_stderr: a photon-map sample short of photons) ranks
 * above every known one, as +infinity: the figures are then bounds the truth cannot
 * exceed, and +infinity where the rank falls on such a pixel. */
typedef struct run_noise {
    double median_k;
    double p95_k;   /* nearest rank: the smallest value >= 95 % of the pixels' */
    size_t pixels;  /* pixels counted (Tb_c > 0: nothing or a back face seen are left out) */
    size_t unknown; /* of them, those whose standard error is unknown */
} run_noise;

/* Figures of channel c (centre freq_hz) over n_images images: *all for every pixel, and
 * objects[o] (n_objects entries, NULL to skip) per object. Images without standard
 * errors are skipped. */
thz_status run_noise_channel(const sensor_images *images, size_t n_images, size_t c, double freq_hz,
                             size_t n_objects, run_noise *all, run_noise *objects, thz_error *err);

/* final-gather's floor in channel c (centre freq_hz): the 95th percentile, over the pixels
 * run_noise_channel counts, of the photon map's share of the standard error of Tb_c
 * (render_accum_map_stderr; accs[i] holds images[i]'s statistics), K. More gather rays
 * from the same map do not lower it: the target's 95th percentile stays at least this.
 * 0 without photon batches (path, photon-map); -1 when out of memory. */
double run_noise_map_floor_k(const render_accum *accs, const sensor_images *images, size_t n_images,
                             size_t c, double freq_hz);

#endif
