/* Emission sampling of the photon phase: see emission.h for the scheme. */
#include "photon/emission.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/planck.h"

double emission_uniform(void *rng)
{
    return rng_uniform(rng);
}

vec3 emission_direction(vec3 n, double mu, double u)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    double phi = 2.0 * M_PI * u;
    vec3 d = v3_scale(n, mu);
    d = v3_madd(d, s * cos(phi), t);
    d = v3_madd(d, s * sin(phi), b);
    return v3_normalize(d);
}

static bool spectrum_is_constant(const thz_spectrum *s)
{
    return s->n <= 1;
}

void emission_table_fini(emission_table *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n_sources; i++)
        free(t->sources[i].triangle_cdf);
    free(t->sources);
    memset(t, 0, sizeof *t);
}

thz_status emission_table_init(emission_table *t, const thz_scene *scene, size_t channel,
                               uint64_t n_photons, thz_error *err)
{
    memset(t, 0, sizeof *t);
    t->scene = scene;
    t->channel = channel;
    t->n_photons = n_photons ? n_photons : 1;
    t->sources = thz_calloc(scene->n_objects, sizeof *t->sources);
    if (!t->sources)
        return thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_object *obj = &scene->objects[i];
        if (!(obj->temperature_k > 0.0) || !(obj->mesh.total_area_m2 > 0.0) ||
            obj->mesh.n_triangles == 0)
            continue;
        emission_source *s = &t->sources[t->n_sources];
        s->object = (uint32_t)i;
        s->sides = (obj->type == OBJECT_SHELL || obj->two_sided) ? 2 : 1;
        s->triangle_cdf = thz_malloc_array(obj->mesh.n_triangles, sizeof *s->triangle_cdf);
        if (!s->triangle_cdf) {
            emission_table_fini(t);
            return thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
        }
        double sum = 0.0;
        for (size_t k = 0; k < obj->mesh.n_triangles; k++) {
            sum += obj->mesh.areas_m2[k];
            s->triangle_cdf[k] = sum;
        }
        s->area_m2 = sum;
        const thz_material *m = &scene->materials[obj->material];
        s->constant_optics = spectrum_is_constant(&m->reflectivity) &&
                             spectrum_is_constant(&m->attenuation_per_m) &&
                             spectrum_is_constant(&m->emissivity);
        if (s->constant_optics) {
            optics_point o = scene_object_optics(scene, obj, scene->channels[channel].center_hz);
            s->eps_mean = optics_mean_emissivity(&o);
        }
        t->n_sources++;
    }
    return THZ_OK;
}

double emission_source_weights(const emission_table *t, double freq_hz, double *weights)
{
    double total = 0.0;
    for (size_t i = 0; i < t->n_sources; i++) {
        const emission_source *s = &t->sources[i];
        const thz_object *obj = &t->scene->objects[s->object];
        double eps = s->eps_mean;
        if (!s->constant_optics) {
            optics_point o = scene_object_optics(t->scene, obj, freq_hz);
            eps = optics_mean_emissivity(&o);
        }
        double w = M_PI * eps * s->area_m2 * s->sides * planck_radiance(freq_hz, obj->temperature_k);
        weights[i] = w;
        total += w;
    }
    return total;
}

/* First index whose cumulative value exceeds x (x in [0, cdf[n-1])). */
static size_t emission_search(const double *cdf, size_t n, double x)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cdf[mid] > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

bool emission_sample(const emission_table *t, rng_stream *rng, double *scratch,
                     emission_photon *out)
{
    const thz_channel *ch = &t->scene->channels[t->channel];
    double u1 = rng_uniform(rng), u2 = rng_uniform(rng);
    out->freq_hz = channel_sample_hz(ch, u1, u2);
    double total = emission_source_weights(t, out->freq_hz, scratch);
    out->power_w_per_hz = total / (double)t->n_photons;
    if (!(total > 0.0)) {
        out->power_w_per_hz = 0.0;
        return false;
    }

    /* Source object by its weight at this frequency (linear scan: objects are few). */
    double x = rng_uniform(rng) * total;
    size_t src = t->n_sources - 1;
    double acc = 0.0;
    for (size_t i = 0; i < t->n_sources; i++) {
        acc += scratch[i];
        if (x < acc && scratch[i] > 0.0) {
            src = i;
            break;
        }
    }
    while (scratch[src] <= 0.0 && src > 0) /* rounding at the top end */
        src--;
    const emission_source *s = &t->sources[src];
    const thz_object *obj = &t->scene->objects[s->object];
    const thz_mesh *m = &obj->mesh;

    int side = 0;
    double us = rng_uniform(rng);
    if (s->sides == 2)
        side = us < 0.5 ? 0 : 1;

    size_t tri = emission_search(s->triangle_cdf, m->n_triangles, rng_uniform(rng) * s->area_m2);
    while (m->areas_m2[tri] <= 0.0 && tri > 0)
        tri--;

    /* Uniform point: p = (1 - sqrt(a)) p0 + sqrt(a)(1 - b) p1 + sqrt(a) b p2. */
    const uint32_t *idx = &m->indices[3 * tri];
    vec3 p0 = v3_from_floats(&m->positions[3 * (size_t)idx[0]]);
    vec3 p1 = v3_from_floats(&m->positions[3 * (size_t)idx[1]]);
    vec3 p2 = v3_from_floats(&m->positions[3 * (size_t)idx[2]]);
    double ra = sqrt(rng_uniform(rng)), rb = rng_uniform(rng);
    out->position_m = v3_add(v3_scale(p0, 1.0 - ra),
                             v3_add(v3_scale(p1, ra * (1.0 - rb)), v3_scale(p2, ra * rb)));

    const float *nf = &m->normals[3 * tri];
    vec3 n = v3(nf[0], nf[1], nf[2]);
    if (side == 1)
        n = v3_scale(n, -1.0);
    optics_point o = scene_object_optics(t->scene, obj, out->freq_hz);
    double mu;
    if (!optics_sample_emission_mu(&o, emission_uniform, rng, &mu))
        mu = sqrt(1.0 - rng_uniform(rng)); /* unreachable: the source has eps-bar > 0 */
    out->dir = emission_direction(n, mu, rng_uniform(rng));
    out->object = s->object;
    out->triangle = (uint32_t)tri;
    out->side = side;
    return true;
}
