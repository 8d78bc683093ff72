/* Noise figures of a run (run_noise.h). */
#include "run/run_noise.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/order.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"

typedef struct noise_pixel {
    int32_t object;
    double stderr_k;
} noise_pixel;

/* Figures of n values in any order (reordered). */
static run_noise noise_of(double *x, size_t n)
{
    run_noise r = {.pixels = n};
    if (n == 0)
        return r;
    for (size_t k = 0; k < n; k++)
        r.unknown += isinf(x[k]) != 0;
    double upper = order_select(x, n, n / 2);
    if (n % 2) {
        r.median_k = upper;
    } else { /* the largest of the lower half, which the selection left below n / 2 */
        double lower = x[0];
        for (size_t k = 1; k < n / 2; k++)
            lower = x[k] > lower ? x[k] : lower;
        r.median_k = 0.5 * (lower + upper);
    }
    size_t rank = (95 * n + 99) / 100; /* ceil(0.95 n), >= 1 */
    r.p95_k = order_select(x, n, rank - 1);
    return r;
}

/* The counted pixels of channel c (Tb_c > 0) of the images that have standard errors:
 * a malloc'd array (NULL when out of memory) of *m, each with its object and standard
 * error of Tb_c in K: the images' own (accs NULL) or the photon map's share of it
 * (render_accum_map_stderr of accs[i], the statistics of images[i]). */
static noise_pixel *noise_collect(const sensor_images *images, size_t n_images, size_t c,
                                  double freq_hz, const render_accum *accs, size_t *m)
{
    size_t total = 0;
    for (size_t i = 0; i < n_images; i++)
        total += (size_t)images[i].columns * images[i].rows;
    noise_pixel *v = thz_malloc_array(total ? total : 1, sizeof *v);
    *m = 0;
    for (size_t i = 0; v && i < n_images; i++) {
        const sensor_images *img = &images[i];
        size_t px = (size_t)img->columns * img->rows;
        if (!img->radiance_stderr || (accs && (!accs[i].batch || accs[i].pixels < px)))
            continue;
        for (size_t p = 0; p < px; p++) {
            double tb = img->brightness_temperature[c * px + p];
            if (!(tb > 0.0))
                continue;
            double l = accs ? render_accum_map_stderr(&accs[i], p)
                            : (double)img->radiance_stderr[c * px + p];
            double se = render_stderr_k(freq_hz, tb, l);
            v[(*m)++] = (noise_pixel){img->object_id[p], se == se ? se : INFINITY};
        }
    }
    return v;
}

double run_noise_map_floor_k(const render_accum *accs, const sensor_images *images, size_t n_images,
                             size_t c, double freq_hz)
{
    size_t m;
    noise_pixel *v = noise_collect(images, n_images, c, freq_hz, accs, &m);
    double *x = v ? thz_malloc_array(m ? m : 1, sizeof *x) : NULL;
    if (!x) {
        free(v);
        return -1.0;
    }
    for (size_t k = 0; k < m; k++)
        x[k] = v[k].stderr_k;
    double floor_k = noise_of(x, m).p95_k;
    free(x);
    free(v);
    return floor_k;
}

thz_status run_noise_channel(const sensor_images *images, size_t n_images, size_t c, double freq_hz,
                             size_t n_objects, run_noise *all, run_noise *objects, thz_error *err)
{
    size_t m;
    noise_pixel *v = noise_collect(images, n_images, c, freq_hz, NULL, &m);
    /* the values grouped by object (a counting sort; group 0 the pixels of no object
     * in range), then each group's figures and the whole array's */
    double *x = v ? thz_malloc_array(m ? m : 1, sizeof *x) : NULL;
    size_t *at = x ? thz_calloc(n_objects + 2, sizeof *at) : NULL;
    if (!at) {
        free(x);
        free(v);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the noise figures");
    }
    for (size_t k = 0; k < m; k++) {
        int32_t o = v[k].object;
        at[o >= 0 && (size_t)o < n_objects ? (size_t)o + 2 : 1]++;
    }
    for (size_t g = 1; g < n_objects + 2; g++)
        at[g] += at[g - 1]; /* at[g]: the end of group g - 1, the start of group g */
    for (size_t k = 0; k < m; k++) {
        int32_t o = v[k].object;
        x[at[o >= 0 && (size_t)o < n_objects ? (size_t)o + 1 : 0]++] = v[k].stderr_k;
    }
    /* at[g] is now the end of group g: object o's values are x[at[o] .. at[o + 1]) */
    for (size_t o = 0; objects && o < n_objects; o++)
        objects[o] = noise_of(x + at[o], at[o + 1] - at[o]);
    *all = noise_of(x, m);
    free(at);
    free(x);
    free(v);
    return THZ_OK;
}
