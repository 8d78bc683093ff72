/* Radiometer noise: NETD per pixel, Gaussian in radiance (noise.h). */
#include "sensor/noise.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/rng.h"
#include "core/threads.h"
#include "physics/planck.h"

/* sigma_L(Tb) is tabulated per channel over the plane's range of Tb at this many
 * intervals: the per-pixel band mean (CHANNEL_QUADRATURE_NODES Planck derivatives) cost
 * twice the rendering of a path-traced image (noise.h has the table's accuracy). */
#define NOISE_TABLE_INTERVALS 1024u

static double noise_radiometer_k(thz_radiometer r)
{
    return r == RADIOMETER_DICKE ? 2.0 : 1.0;
}

double noise_netd_k(const thz_sensor_noise *n, const thz_channel *ch, size_t c, double tb_k)
{
    switch (n->kind) {
    case NOISE_NETD:
        return n->netd_k[c];
    case NOISE_RADIOMETER:
        return noise_radiometer_k(n->radiometer) * (tb_k + n->receiver_temperature_k) /
               sqrt(channel_noise_bandwidth_hz(ch) * n->integration_time_s);
    case NOISE_NONE:
        break;
    }
    return 0.0;
}

/* Band mean of dB_nu/dT at temp_k over the quadrature q, W m^-2 sr^-1 Hz^-1 K^-1. */
static double noise_band_dbdt(const channel_quadrature *q, double temp_k)
{
    double sum = 0.0;
    for (size_t k = 0; k < q->n; k++)
        sum += q->weight[k] * planck_dbdt(q->freq_hz[k], temp_k);
    return sum;
}

/* sigma_L(Tb) of one channel at NOISE_TABLE_INTERVALS + 3 points uniform in ln Tb,
 * ln Tb = s0 + (i - 1) h, spanning the plane's positive Tb with one node beyond each end
 * for the cubic's stencil. In ln Tb the Wien knee near Tb = h nu / k is as smooth as
 * the rest. n = 0: no positive Tb in the plane. */
typedef struct noise_table {
    double s0, h;
    size_t n;
    double *sigma;
} noise_table;

static thz_status noise_table_init(noise_table *t, const thz_sensor_noise *n, const thz_channel *ch,
                                   size_t c, const float *tb_k, size_t pixels, thz_error *err)
{
    memset(t, 0, sizeof *t);
    double lo = INFINITY, hi = 0.0;
    for (size_t p = 0; p < pixels; p++) {
        double tb = tb_k[p];
        if (tb > 0.0 && isfinite(tb)) {
            lo = tb < lo ? tb : lo;
            hi = tb > hi ? tb : hi;
        }
    }
    if (!(lo <= hi))
        return THZ_OK; /* sigma_L is 0 at Tb <= 0 */
    /* one Tb in the whole plane: one interval of 1e-3 in ln Tb, whose first node is it */
    size_t intervals = hi > lo ? NOISE_TABLE_INTERVALS : 1;
    t->s0 = log(lo);
    t->h = hi > lo ? (log(hi) - t->s0) / (double)intervals : 1e-3;
    t->n = intervals + 3;
    t->sigma = thz_malloc_array(t->n, sizeof *t->sigma);
    if (!t->sigma)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the noise table");
    channel_quadrature q;
    thz_status st = channel_quadrature_init(&q, ch, CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK) {
        free(t->sigma);
        return st;
    }
    for (size_t i = 0; i < t->n; i++) {
        double tb = exp(t->s0 + ((double)i - 1.0) * t->h);
        t->sigma[i] = noise_netd_k(n, ch, c, tb) * noise_band_dbdt(&q, tb);
    }
    channel_quadrature_fini(&q);
    return THZ_OK;
}

/* sigma_L at tb_k: 4-point Lagrange cubic in ln Tb (exact at the nodes); 0 at Tb <= 0,
 * as noise_dbdt. */
static double noise_table_at(const noise_table *t, double tb_k)
{
    if (!(tb_k > 0.0) || t->n == 0)
        return 0.0;
    double u = (log(tb_k) - t->s0) / t->h + 1.0;
    double last = (double)(t->n - 3);
    double i = floor(u < 1.0 ? 1.0 : u > last ? last : u);
    if (!isfinite(i))
        i = 1.0;
    double f = u - i;
    const double *s = t->sigma + (size_t)i - 1;
    return -f * (f - 1.0) * (f - 2.0) / 6.0 * s[0] +
           (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0 * s[1] - (f + 1.0) * f * (f - 2.0) / 2.0 * s[2] +
           (f + 1.0) * f * (f - 1.0) / 6.0 * s[3];
}

thz_status noise_apply(const thz_sensor *sn, size_t sensor, const thz_channel *ch, size_t c,
                       uint64_t seed, const float *tb_k, float *radiance, int threads,
                       thz_error *err)
{
    long long pixels = (long long)sn->columns * sn->rows;
    noise_table table;
    thz_status st = noise_table_init(&table, &sn->noise, ch, c, tb_k, (size_t)pixels, err);
    if (st != THZ_OK)
        return st;
    int nt = thz_threads_or_all(threads);
#pragma omp parallel for schedule(static) num_threads(nt)
    for (long long p = 0; p < pixels; p++) {
        double sigma_l = noise_table_at(&table, tb_k[p]);
        rng_stream rng;
        rng_init(&rng, seed, (uint32_t)c, RNG_PURPOSE_SENSOR_NOISE,
                 ((uint64_t)sensor << 32) | (uint64_t)p);
        /* Box-Muller: u1 in (0, 1] keeps the log finite */
        double u1 = rng_uniform_open0(&rng), u2 = rng_uniform(&rng);
        double z = sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
        radiance[p] = (float)((double)radiance[p] + sigma_l * z);
    }
    free(table.sigma);
    return THZ_OK;
}
