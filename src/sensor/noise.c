/* Radiometer noise: NETD per pixel, Gaussian in radiance (noise.h). */
#include "sensor/noise.h"

#include <math.h>
#include <omp.h>

#include "core/rng.h"
#include "physics/planck.h"

double noise_radiometer_k(thz_radiometer r)
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

/* dB_nu/dT = B_nu(T) x e^x / ((e^x - 1) T), x = h nu / k T. */
static double noise_dbdt(double freq_hz, double temp_k)
{
    if (!(temp_k > 0.0))
        return 0.0;
    double x = THZ_PLANCK_H * freq_hz / (THZ_BOLTZMANN_K * temp_k);
    double em1 = expm1(x);
    return planck_radiance(freq_hz, temp_k) * x * (em1 + 1.0) / (em1 * temp_k);
}

double noise_band_dbdt(const channel_quadrature *q, double temp_k)
{
    double sum = 0.0;
    for (size_t k = 0; k < q->n; k++)
        sum += q->weight[k] * noise_dbdt(q->freq_hz[k], temp_k);
    return sum;
}

thz_status noise_apply(const thz_sensor *sn, size_t sensor, const thz_channel *ch, size_t c,
                       uint64_t seed, const float *tb_k, float *radiance, int threads,
                       thz_error *err)
{
    channel_quadrature q;
    thz_status st = channel_quadrature_init(&q, ch, CHANNEL_QUADRATURE_NODES, err);
    if (st != THZ_OK)
        return st;
    long long pixels = (long long)sn->columns * sn->rows;
    int nt = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(static) num_threads(nt)
    for (long long p = 0; p < pixels; p++) {
        double tb = tb_k[p];
        double sigma_l = noise_netd_k(&sn->noise, ch, c, tb) * noise_band_dbdt(&q, tb);
        rng_stream rng;
        rng_init(&rng, seed, (uint32_t)c, RNG_PURPOSE_SENSOR_NOISE,
                 ((uint64_t)sensor << 32) | (uint64_t)p);
        /* Box-Muller: u1 in (0, 1] keeps the log finite */
        double u1 = rng_uniform_open0(&rng), u2 = rng_uniform(&rng);
        double z = sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
        radiance[p] = (float)((double)radiance[p] + sigma_l * z);
    }
    channel_quadrature_fini(&q);
    return THZ_OK;
}
