/* The emitting atmosphere as a photon source: see air_emission.h for the scheme. */
#include "photon/air_emission.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/planck.h"

void air_emission_fini(air_emission *a)
{
    if (!a)
        return;
    free(a->q);
    free(a->cdf);
    memset(a, 0, sizeof *a);
}

/* g_c(nu) P_air(nu), W/Hz (unnormalised response). */
static double air_emission_density(const air_emission *a, double sigma_hz, double freq_hz)
{
    if (!(freq_hz > 0.0))
        return 0.0;
    const thz_channel *ch = &a->scene->channels[a->channel];
    double x = (freq_hz - ch->center_hz) / sigma_hz;
    return exp(-0.5 * x * x) * a->volume_m3 *
           atmosphere_volume_emission_w_per_m3_hz(&a->scene->atmosphere, freq_hz);
}

/* The emitting box: the atmosphere's extent, else the bounding box of every mesh. */
static void air_emission_box(const thz_scene *scene, double min_m[3], double max_m[3])
{
    const thz_atmosphere *atm = &scene->atmosphere;
    for (int k = 0; k < 3; k++) {
        min_m[k] = atm->has_extent ? atm->extent_min_m[k] : INFINITY;
        max_m[k] = atm->has_extent ? atm->extent_max_m[k] : -INFINITY;
    }
    if (atm->has_extent)
        return;
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_mesh *m = &scene->objects[i].mesh;
        if (m->n_triangles == 0)
            continue;
        for (int k = 0; k < 3; k++) {
            min_m[k] = fmin(min_m[k], m->bbox_min_m[k]);
            max_m[k] = fmax(max_m[k], m->bbox_max_m[k]);
        }
    }
}

/* A uniform point in the box and an isotropic direction from rng. */
static void air_emission_point(const air_emission *a, rng_stream *rng, vec3 *p, vec3 *dir)
{
    double x[3];
    for (int k = 0; k < 3; k++)
        x[k] = a->min_m[k] + rng_uniform(rng) * (a->max_m[k] - a->min_m[k]);
    *p = v3(x[0], x[1], x[2]);
    double z = 1.0 - 2.0 * rng_uniform(rng);
    double s = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * rng_uniform(rng);
    *dir = v3(s * cos(phi), s * sin(phi), z);
}

/* Share of air photons that trace_photon keeps: points whose first hit along an isotropic
 * direction is not the back face of a one-sided solid. */
static double air_emission_share(const air_emission *a, const accel *acc)
{
    const thz_scene *scene = a->scene;
    uint64_t inside = 0;
    for (uint64_t i = 0; i < AIR_EMISSION_VOLUME_RAYS; i++) {
        rng_stream rng;
        rng_init(&rng, scene->photons.seed, (uint32_t)a->channel, RNG_PURPOSE_AIR_VOLUME, i);
        vec3 p, dir;
        air_emission_point(a, &rng, &p, &dir);
        accel_hit hit;
        if (accel_intersect(acc, p, dir, INFINITY, ACCEL_NO_OBJECT, 0, &hit) &&
            !scene_object_side_is_front(&scene->objects[hit.object], hit.side))
            inside++;
    }
    return 1.0 - (double)inside / AIR_EMISSION_VOLUME_RAYS;
}

thz_status air_emission_init(air_emission *a, const thz_scene *scene, const accel *acc,
                             size_t channel, uint64_t n_photons, double surface_power_w_per_hz,
                             thz_error *err)
{
    memset(a, 0, sizeof *a);
    a->scene = scene;
    a->channel = channel;
    a->n_photons = n_photons ? n_photons : 1;
    if (!scene->atmosphere.emitting)
        return THZ_OK;
    air_emission_box(scene, a->min_m, a->max_m);
    a->volume_m3 = 1.0;
    for (int k = 0; k < 3; k++)
        a->volume_m3 *= a->max_m[k] - a->min_m[k];
    if (!(a->volume_m3 > 0.0) || !isfinite(a->volume_m3))
        return THZ_OK;

    const thz_channel *ch = &scene->channels[channel];
    double sigma = channel_sigma_hz(ch);
    double lo = ch->center_hz - AIR_EMISSION_SIGMAS * sigma;
    double hi = ch->center_hz + AIR_EMISSION_SIGMAS * sigma;
    if (lo < 0.0)
        lo = 0.0;
    a->lo_hz = lo;
    a->bin_hz = (hi - lo) / AIR_EMISSION_BINS;
    a->q = thz_malloc_array(AIR_EMISSION_BINS, sizeof *a->q);
    a->cdf = thz_malloc_array(AIR_EMISSION_BINS, sizeof *a->cdf);
    if (!a->q || !a->cdf) {
        air_emission_fini(a);
        return thz_error_set(err, THZ_ERR_NOMEM, "air emission: out of memory");
    }
    /* q_i = the larger node value of the bin (the bins resolve alpha's table far finer
     * than a line), floored at 1e-6 of the peak so that q > 0 wherever g P may be. */
    double prev = air_emission_density(a, sigma, lo), peak = 0.0, trapezoid = 0.0;
    for (size_t i = 0; i < AIR_EMISSION_BINS; i++) {
        double next = air_emission_density(a, sigma, lo + (double)(i + 1) * a->bin_hz);
        a->q[i] = fmax(prev, next);
        trapezoid += 0.5 * (prev + next) * a->bin_hz;
        peak = fmax(peak, a->q[i]);
        prev = next;
    }
    if (!(peak > 0.0)) {
        air_emission_fini(a);
        a->scene = scene;
        return THZ_OK;
    }
    double sum = 0.0;
    for (size_t i = 0; i < AIR_EMISSION_BINS; i++) {
        a->q[i] = fmax(a->q[i], 1e-6 * peak);
        sum += a->q[i] * a->bin_hz;
        a->cdf[i] = sum;
    }
    a->air_share = air_emission_share(a, acc);
    a->band_power_w_per_hz = a->air_share * trapezoid / (sigma * sqrt(2.0 * M_PI));
    a->p_air = a->band_power_w_per_hz /
               (a->band_power_w_per_hz + fmax(surface_power_w_per_hz, 0.0));
    a->active = true;
    return THZ_OK;
}

bool air_emission_sample(const air_emission *a, const emission_table *t, rng_stream *rng,
                         double *scratch, emission_photon *out)
{
    if (!a || !a->active)
        return emission_sample(t, rng, scratch, out);
    if (!(rng_uniform(rng) < a->p_air)) {
        bool ok = emission_sample(t, rng, scratch, out);
        out->power_w_per_hz /= 1.0 - a->p_air;
        return ok;
    }
    /* Bin by the histogram's CDF, then uniform within the bin. */
    double x = rng_uniform(rng) * a->cdf[AIR_EMISSION_BINS - 1];
    size_t lo = 0, hi = AIR_EMISSION_BINS - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (a->cdf[mid] > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    double nu = a->lo_hz + ((double)lo + rng_uniform(rng)) * a->bin_hz;
    const thz_channel *ch = &a->scene->channels[a->channel];
    double sigma = channel_sigma_hz(ch);
    double f = air_emission_density(a, sigma, nu);
    out->freq_hz = nu;
    out->power_w_per_hz = f * a->cdf[AIR_EMISSION_BINS - 1] /
                          (a->q[lo] * sigma * sqrt(2.0 * M_PI) * a->p_air * (double)a->n_photons);
    air_emission_point(a, rng, &out->position_m, &out->dir);
    out->object = ACCEL_NO_OBJECT;
    out->triangle = 0;
    out->side = 0;
    return out->power_w_per_hz > 0.0;
}
