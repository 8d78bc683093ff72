/* Propagation of one photon: see trace.h for the rules. */
#include "photon/trace.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/sampling.h"

void trace_counters_add(trace_counters *sum, const trace_counters *c)
{
    sum->photons += c->photons;
    sum->rays += c->rays;
    sum->hits += c->hits;
    sum->reflected += c->reflected;
    sum->transmitted += c->transmitted;
    sum->absorbed += c->absorbed;
    sum->escaped += c->escaped;
    sum->back_face_hits += c->back_face_hits;
    sum->terminated += c->terminated;
    sum->capped += c->capped;
    sum->fired_power += c->fired_power;
    sum->absorbed_power += c->absorbed_power;
    sum->escaped_power += c->escaped_power;
    sum->atmosphere_power += c->atmosphere_power;
    sum->terminated_power += c->terminated_power;
}

void trace_buffer_fini(trace_buffer *b)
{
    free(b->records);
    b->records = NULL;
    b->count = b->capacity = 0;
}

/* Amortised doubling; happens O(log n) times per thread over a whole run. */
static bool trace_buffer_push(trace_buffer *b, const photon_record *r)
{
    if (b->count == b->capacity) {
        photon_record *p = thz_grow_array(b->records, &b->capacity, 4096, sizeof *p);
        if (!p)
            return false;
        b->records = p;
    }
    b->records[b->count++] = *r;
    return true;
}

trace_event trace_roulette(const optics_point *o, double mu, double u)
{
    double r = optics_reflectance(o, mu);
    if (u < r)
        return TRACE_REFLECT;
    if (o->thickness_m > 0.0 && u < r + optics_transmission(o, mu))
        return TRACE_TRANSMIT;
    return TRACE_ABSORB;
}

vec3 trace_diffuse_transmission_dir(const optics_point *o, vec3 n_out, rng_stream *rng)
{
    double mu;
    if (!optics_sample_transmission_mu(o, sampling_uniform32, rng, &mu))
        mu = sqrt(1.0 - rng_uniform32(rng)); /* unreachable after a transmission event */
    return sampling_direction(n_out, mu, rng_uniform32(rng));
}

/* Reflection by the material's lobe (brdf.h) from hit, arriving along *dir: the new
 * direction, and the power times the sample's weight (1 for diffuse and mirror; for
 * Ward of mean 1: the difference is booked as terminated power, so that the power sums
 * still balance). False if the sample is lost. */
static bool trace_reflect_lobe(const thz_scene *scene, const thz_object *obj, const accel_hit *hit,
                               const optics_point *o, rng_stream *rng, vec3 *dir, double *power,
                               trace_counters *c)
{
    brdf_frame f = scene_triangle_frame(obj, hit->triangle, hit->side);
    brdf_lobe lobe; /* sampling only: per reflection, R-bar would cost 48 Fresnel terms */
    brdf_lobe_init_sampling(&lobe, o, scene->materials[obj->material].ward_table);
    double w;
    if (!brdf_sample(&lobe, &f, v3_scale(*dir, -1.0), sampling_uniform32, rng, dir, &w))
        return false;
    if (w != 1.0) {
        c->terminated_power -= *power * (w - 1.0);
        *power *= w;
    }
    return true;
}

thz_status trace_optics_init(trace_optics *t, const thz_scene *scene, thz_error *err)
{
    size_t n = scene->n_objects ? scene->n_objects : 1;
    t->optics = thz_calloc(n, sizeof *t->optics);
    t->constant = thz_calloc(n, sizeof *t->constant);
    if (!t->optics || !t->constant) {
        trace_optics_fini(t);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon phase: out of memory");
    }
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_object *obj = &scene->objects[i];
        t->constant[i] = scene_object_optics_constant(scene, obj);
        if (t->constant[i])
            t->optics[i] = scene_object_optics(scene, obj, 0.0);
    }
    return THZ_OK;
}

void trace_optics_fini(trace_optics *t)
{
    free(t->optics);
    free(t->constant);
    t->optics = NULL;
    t->constant = NULL;
}

bool trace_photon(const thz_scene *scene, const accel *acc, const trace_optics *optics,
                  const emission_photon *e, rng_stream *rng, trace_buffer *buf, trace_counters *c)
{
    c->photons++;
    /* The power is signed in a deviation map (emission.h): the path is traced with its
     * magnitude and every record and sum keeps the sign. */
    double power = e->power_w_per_hz;
    if (power == 0.0 || isnan(power))
        return true;
    c->fired_power += power;
    const double w_min = scene->photons.min_relative_power * fabs(power);
    const double nu = e->freq_hz;
    /* The frequency is the path's: alpha(nu) once (atmosphere_transmittance per hit
     * would evaluate it, an interpolation or a line sum, at every hit). */
    const double alpha = atmosphere_alpha_per_m(&scene->atmosphere, nu);

    accel_hit from = {
        .object = e->object, .triangle = e->triangle, .position_m = e->position_m, .side = e->side};
    vec3 dir = e->dir;
    /* An air photon (air_emission.h) starts from its point in the volume itself. */
    vec3 origin =
        e->object == ACCEL_NO_OBJECT ? e->position_m : accel_offset_origin(acc, &from, dir);
    vec3 surface = e->position_m; /* the un-offset point the free path starts from */
    uint32_t ignore_obj = e->object, ignore_tri = e->triangle;

    for (uint32_t bounce = 0;; bounce++) {
        if (bounce >= TRACE_MAX_BOUNCES) {
            c->capped++;
            c->terminated_power += power;
            return true;
        }
        accel_hit hit;
        c->rays++;
        if (!accel_intersect(acc, origin, dir, INFINITY, ignore_obj, ignore_tri, &hit)) {
            c->escaped++;
            c->escaped_power += power;
            return true;
        }
        if (bounce == 0 && e->object == ACCEL_NO_OBJECT &&
            !scene_object_side_is_front(&scene->objects[hit.object], hit.side)) {
            /* An air photon born inside a solid (it meets a back face first): there is
             * no air there, so it was never emitted (counted absorbed, with no power).
             * Photons carry the power of the whole extent, so the rest fire the air's
             * true power in expectation (air_emission.h). */
            c->fired_power -= power;
            c->absorbed++;
            return true;
        }
        if (alpha != 0.0) { /* as atmosphere_transmittance: alpha = 0 transmits all */
            /* The free path runs from the surface point along dir, not from the offset
             * origin: its length to the plane of the triangle hit. (From the offset
             * origin it would be short by about eps/cos, a bias of alpha eps / cos.) */
            const float *hn = &scene->objects[hit.object].mesh.normals[3 * (size_t)hit.triangle];
            vec3 to_hit = v3_sub(hit.position_m, surface);
            double d = hit.cos_theta > 1e-6
                           ? fabs(v3_dot(to_hit, v3(hn[0], hn[1], hn[2]))) / hit.cos_theta
                           : v3_length(to_hit);
            double tr = exp(-alpha * d);
            c->atmosphere_power += power * (1.0 - tr);
            power *= tr;
        }
        if (fabs(power) < w_min) {
            /* Low-power roulette: survive with probability |w| / w_min at +-w_min. */
            if (rng_uniform32(rng) * w_min < fabs(power)) {
                double survivor = copysign(w_min, power);
                c->terminated_power -= survivor - power;
                power = survivor;
            } else {
                c->terminated++;
                c->terminated_power += power;
                return true;
            }
        }

        photon_record rec = {
            .position_m = {(float)hit.position_m.x, (float)hit.position_m.y,
                           (float)hit.position_m.z},
            .power_w_per_hz = (float)power,
            .freq_hz = (float)nu,
            .dir_oct = photon_encode_direction(dir),
            .tag = photon_tag(hit.object, hit.side, bounce == 0, e->batch),
        };
        if (!trace_buffer_push(buf, &rec))
            return false;
        c->hits++;

        const thz_object *obj = &scene->objects[hit.object];
        if (!scene_object_side_is_front(obj, hit.side)) {
            c->back_face_hits++;
            c->absorbed++;
            c->absorbed_power += power;
            return true;
        }
        optics_point o = optics && optics->constant[hit.object]
                             ? optics->optics[hit.object]
                             : scene_object_optics(scene, obj, nu);
        const float *nf = &obj->mesh.normals[3 * (size_t)hit.triangle];
        vec3 n = v3(nf[0], nf[1], nf[2]);
        vec3 n_in = hit.side == 0 ? n : v3_scale(n, -1.0); /* towards where it came from */

        switch (trace_roulette(&o, hit.cos_theta, rng_uniform32(rng))) {
        case TRACE_REFLECT:
            if (o.lobe == OPTICS_LOBE_DIFFUSE && !optics_reflectance_varies(&o)) {
                dir = sampling_cosine32(n_in, rng);
            } else if (!trace_reflect_lobe(scene, obj, &hit, &o, rng, &dir, &power, c)) {
                c->absorbed++; /* a glossy sample below the surface: lost, not reflected */
                c->absorbed_power += power;
                return true;
            }
            c->reflected++;
            break;
        case TRACE_TRANSMIT:
            c->transmitted++;
            if (scene->materials[obj->material].transmission == TRANSMISSION_DIFFUSE)
                dir = trace_diffuse_transmission_dir(&o, v3_scale(n_in, -1.0), rng);
            break;
        case TRACE_ABSORB:
            c->absorbed++;
            c->absorbed_power += power;
            return true;
        }
        origin = accel_offset_origin(acc, &hit, dir);
        surface = hit.position_m;
        ignore_obj = hit.object;
        ignore_tri = hit.triangle;
    }
}
