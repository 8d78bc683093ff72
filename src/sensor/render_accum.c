/* Pixel statistics of the renderer: see render_accum.h. */
#include "sensor/render_accum.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/channel.h"
#include "physics/planck.h"
#include "sensor/camera.h"

thz_status render_accum_init(render_accum *acc, size_t pixels, thz_error *err)
{
    memset(acc, 0, sizeof *acc);
    acc->pixels = pixels;
    acc->mean = thz_calloc(pixels ? pixels : 1, sizeof *acc->mean);
    acc->m2 = thz_calloc(pixels ? pixels : 1, sizeof *acc->m2);
    if (!acc->mean || !acc->m2) {
        render_accum_fini(acc);
        return thz_error_set(err, THZ_ERR_NOMEM, "render: out of memory for %zu pixel statistics",
                             pixels);
    }
    return THZ_OK;
}

void render_accum_fini(render_accum *acc)
{
    free(acc->mean);
    free(acc->m2);
    free(acc->batch);
    free(acc->disk_var);
    memset(acc, 0, sizeof *acc);
}

/* The photon map's variance of pixel p's mean given the gather rays (final-gather from a
 * batched map; acc->n >= 2): the spread of the pixel's photon part between the
 * independent batches, s_B^2 / B, less what the spread of the estimates already holds of
 * it (each gather disk's own Poisson variance, sum / N^2), at least 0. */
static double render_accum_map_var(const render_accum *acc, size_t p)
{
    double n = (double)acc->n;
    const double *s = &acc->batch[p * PHOTON_MAP_BATCHES];
    double nb = (double)PHOTON_MAP_BATCHES, mean = 0.0, ss = 0.0;
    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
        mean += s[b];
    mean /= nb;
    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
        ss += (s[b] - mean) * (s[b] - mean);
    /* Z_b = B s_b / N estimates the photon part alone; var of their mean */
    double map_var = ss * nb * nb / (n * n) / (nb - 1.0) / nb;
    double diag = acc->disk_var[p] / (n * n);
    return map_var > diag ? map_var - diag : 0.0;
}

double render_accum_stderr(const render_accum *acc, size_t p)
{
    if (acc->poisson)
        return sqrt(acc->m2[p]);
    if (acc->n < 2)
        return 0.0;
    double n = (double)acc->n;
    double var = acc->m2[p] / ((n - 1.0) * n);
    if (acc->batch)
        var += render_accum_map_var(acc, p);
    return sqrt(var);
}

double render_accum_map_stderr(const render_accum *acc, size_t p)
{
    if (acc->poisson || !acc->batch || acc->n < 2)
        return 0.0;
    return sqrt(render_accum_map_var(acc, p));
}

thz_status render_accum_want_batches(render_accum *acc, thz_error *err)
{
    if (acc->batch)
        return THZ_OK;
    acc->batch = thz_calloc(acc->pixels * PHOTON_MAP_BATCHES, sizeof *acc->batch);
    acc->disk_var = thz_calloc(acc->pixels ? acc->pixels : 1, sizeof *acc->disk_var);
    if (!acc->batch || !acc->disk_var) {
        free(acc->batch);
        free(acc->disk_var);
        acc->batch = acc->disk_var = NULL;
        return thz_error_set(err, THZ_ERR_NOMEM,
                             "render: out of memory for %zu pixels' photon batches", acc->pixels);
    }
    return THZ_OK;
}

void render_accum_set_poisson_pixel(render_accum *acc, size_t p, double mean, double var)
{
    acc->mean[p] = mean;
    acc->m2[p] = var;
}

void render_accum_add_pixel(render_accum *acc, size_t p, const double *est, uint32_t n_est,
                            const double *batch, const double *disk_var)
{
    double n_b = (double)n_est, n_a = (double)acc->n, n_ab = n_a + n_b;
    /* this pass's mean and squared deviations (two-pass), merged with the earlier
     * passes' (Chan et al.) */
    double shift = 0.0, m2_b = 0.0; /* about est[0]: equal estimates give 0 */
    for (uint32_t k = 1; k < n_est; k++)
        shift += est[k] - est[0];
    double mean_b = est[0] + shift / n_b;
    for (uint32_t k = 0; k < n_est; k++)
        m2_b += (est[k] - mean_b) * (est[k] - mean_b);
    double delta = mean_b - acc->mean[p];
    acc->mean[p] += delta * n_b / n_ab;
    acc->m2[p] += m2_b + delta * delta * n_a * n_b / n_ab;
    if (batch) {
        for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
            acc->batch[p * PHOTON_MAP_BATCHES + b] += batch[b];
        acc->disk_var[p] += *disk_var;
    }
}

void render_accum_end_pass(render_accum *acc, uint32_t n_est, bool poisson)
{
    acc->n += n_est;
    acc->passes++;
    acc->poisson = poisson;
}

thz_status render_accum_write(const thz_scene *scene, size_t channel, size_t sensor,
                              const render_accum *acc, sensor_images *images, thz_error *err)
{
    const thz_sensor *sn = &scene->sensors[sensor];
    if (images->columns != sn->columns || images->rows != sn->rows ||
        images->n_channels != scene->n_channels || acc->pixels != (size_t)sn->columns * sn->rows)
        return thz_error_set(err, THZ_ERR_INTERNAL, "render: images do not match sensor '%s'",
                             sn->name);
    camera cam;
    thz_status st = camera_init(&cam, sn, err);
    if (st != THZ_OK)
        return st;
    const thz_channel *ch = &scene->channels[channel];
    channel_quadrature q;
    st = channel_quadrature_init(&q, ch, CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK)
        return st;
    double b_ref = 0.0; /* band mean of B_nu(T_ref) */
    for (size_t k = 0; k < q.n; k++)
        b_ref += q.weight[k] * planck_radiance(q.freq_hz[k], sn->normalize_to_k);
    channel_quadrature_fini(&q);
    double bandwidth_hz = channel_bandwidth_hz(ch);
    size_t plane = channel * acc->pixels;
    for (size_t p = 0; p < acc->pixels; p++) {
        uint32_t row = (uint32_t)(p / sn->columns), col = (uint32_t)(p % sn->columns);
        double omega_sr = camera_pixel_solid_angle(&cam, col, row);
        double l = acc->mean[p]; /* L_c, W m^-2 sr^-1 Hz^-1 */
        size_t at = plane + p;
        images->radiance[at] = (float)l;
        if (images->radiance_stderr)
            images->radiance_stderr[at] = (float)render_accum_stderr(acc, p);
        images->power[at] = (float)(l * omega_sr * sn->aperture_m2 * bandwidth_hz);
        images->brightness_temperature[at] =
            l > 0.0 ? (float)planck_brightness_temperature(ch->center_hz, l) : 0.0f;
        images->normalized[at] = b_ref > 0.0 ? (float)(l / b_ref) : 0.0f;
    }
    return THZ_OK;
}

double render_stderr_k(double freq_hz, double tb_k, double stderr_l)
{
    if (!(tb_k > 0.0))
        return 0.0;
    return stderr_l / planck_dbdt(freq_hz, tb_k);
}
