/* Noise figures of a run (run_noise.h). */
#include "run/run_noise.h"

#include <stdint.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"

typedef struct noise_pixel {
    int32_t object;
    double stderr_k;
} noise_pixel;

static int noise_cmp(const void *a, const void *b)
{
    const noise_pixel *x = a, *y = b;
    if (x->object != y->object)
        return (x->object > y->object) - (x->object < y->object);
    return (x->stderr_k > y->stderr_k) - (x->stderr_k < y->stderr_k);
}

/* Figures of n values sorted by stderr_k. */
static run_noise noise_of(const noise_pixel *v, size_t n)
{
    run_noise r = {.pixels = n};
    if (n == 0)
        return r;
    r.median_k = n % 2 ? v[n / 2].stderr_k : 0.5 * (v[n / 2 - 1].stderr_k + v[n / 2].stderr_k);
    size_t rank = (95 * n + 99) / 100; /* ceil(0.95 n), >= 1 */
    r.p95_k = v[rank - 1].stderr_k;
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
            v[(*m)++] = (noise_pixel){img->object_id[p], render_stderr_k(freq_hz, tb, l)};
        }
    }
    return v;
}

double run_noise_map_floor_k(const render_accum *accs, const sensor_images *images, size_t n_images,
                             size_t c, double freq_hz)
{
    size_t m;
    noise_pixel *v = noise_collect(images, n_images, c, freq_hz, accs, &m);
    if (!v)
        return -1.0;
    for (size_t k = 0; k < m; k++) /* by value alone */
        v[k].object = 0;
    qsort(v, m, sizeof *v, noise_cmp);
    double floor_k = noise_of(v, m).p95_k;
    free(v);
    return floor_k;
}

thz_status run_noise_channel(const sensor_images *images, size_t n_images, size_t c, double freq_hz,
                             size_t n_objects, run_noise *all, run_noise *objects, thz_error *err)
{
    size_t m;
    noise_pixel *v = noise_collect(images, n_images, c, freq_hz, NULL, &m);
    if (!v)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the noise figures");
    qsort(v, m, sizeof *v, noise_cmp); /* by object, then by value */
    for (size_t o = 0; objects && o < n_objects; o++)
        objects[o] = (run_noise){0};
    for (size_t k = 0; objects && k < m;) {
        size_t j = k;
        while (j < m && v[j].object == v[k].object)
            j++;
        if (v[k].object >= 0 && (size_t)v[k].object < n_objects)
            objects[v[k].object] = noise_of(&v[k], j - k);
        k = j;
    }
    for (size_t k = 0; k < m; k++) /* then all pixels, by value alone */
        v[k].object = 0;
    qsort(v, m, sizeof *v, noise_cmp);
    *all = noise_of(v, m);
    free(v);
    return THZ_OK;
}
