/* The emitting atmosphere as a photon source: see air_emission.h for the scheme. */
#include "photon/air_emission.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/cdf.h"
#include "core/sampling.h"
#include "physics/planck.h"

void air_emission_fini(air_emission *a)
{
    if (!a)
        return;
    free(a->q);
    free(a->cdf);
    memset(a, 0, sizeof *a);
}

/* g_c(nu) P_air(nu), W/Hz (unnormalised response), over the whole box: the deviation
 * source 4 pi alpha (B(T_air) - B0) (T_air = 0 when the air does not emit) and, in
 * *physical (may be NULL), the air's own emission 4 pi alpha B(T_air). Equal when
 * T0 = 0. */
static double air_emission_density(const air_emission *a, double freq_hz, double *physical)
{
    if (physical)
        *physical = 0.0;
    if (!(freq_hz > 0.0))
        return 0.0;
    const thz_channel *ch = &a->scene->channels[a->channel];
    const thz_atmosphere *atm = &a->scene->atmosphere;
    double g = channel_response(ch, freq_hz) * a->volume_m3;
    double own = g * atmosphere_volume_emission_w_per_m3_hz(atm, freq_hz);
    if (physical)
        *physical = own;
    if (!(a->t0_k > 0.0))
        return own;
    double air = atm->emitting ? planck_radiance(freq_hz, atm->air.temperature_k) : 0.0;
    return g * 4.0 * M_PI * atmosphere_alpha_per_m(atm, freq_hz) *
           (air - planck_radiance(freq_hz, a->t0_k));
}

/* L_b(nu): the radiance entering the box from outside (the escape radiance at its
 * faces); 0 when the atmosphere does not emit. */
static double air_emission_boundary_radiance(const thz_atmosphere *atm, double freq_hz)
{
    if (!atm->emitting)
        return 0.0;
    if (!atm->has_extent && atmosphere_alpha_per_m(atm, freq_hz) > 0.0)
        return planck_radiance(freq_hz, atm->air.temperature_k);
    return planck_radiance(freq_hz, atm->background_temperature_k);
}

/* L_b(nu) - B0: the boundary's deviation source. */
static double air_emission_boundary_deviation(const air_emission *a, double freq_hz)
{
    double l = air_emission_boundary_radiance(&a->scene->atmosphere, freq_hz);
    return a->t0_k > 0.0 ? l - planck_radiance(freq_hz, a->t0_k) : l;
}

static double air_emission_boundary_at(double freq_hz, void *atm)
{
    return air_emission_boundary_radiance(atm, freq_hz);
}

static double air_emission_boundary_magnitude_at(double freq_hz, void *a)
{
    return fabs(air_emission_boundary_deviation(a, freq_hz));
}

static double air_emission_boundary_deviation_at(double freq_hz, void *a)
{
    return air_emission_boundary_deviation(a, freq_hz);
}

/* The box: the atmosphere's extent, else the bounding box of every mesh widened by 1 % of
 * its diagonal on each side (a flat scene still gets a volume, and the faces keep clear
 * of the surfaces). False if there is none. */
static bool air_emission_box(const thz_scene *scene, double min_m[3], double max_m[3])
{
    const thz_atmosphere *atm = &scene->atmosphere;
    if (atm->has_extent) {
        for (int k = 0; k < 3; k++) {
            min_m[k] = atm->extent_min_m[k];
            max_m[k] = atm->extent_max_m[k];
        }
        return true;
    }
    for (int k = 0; k < 3; k++) {
        min_m[k] = INFINITY;
        max_m[k] = -INFINITY;
    }
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_mesh *m = &scene->objects[i].mesh;
        if (m->n_triangles == 0)
            continue;
        for (int k = 0; k < 3; k++) {
            min_m[k] = fmin(min_m[k], m->bbox_min_m[k]);
            max_m[k] = fmax(max_m[k], m->bbox_max_m[k]);
        }
    }
    double d2 = 0.0;
    for (int k = 0; k < 3; k++)
        d2 += (max_m[k] - min_m[k]) * (max_m[k] - min_m[k]);
    if (!(d2 > 0.0) || !isfinite(d2))
        return false;
    for (int k = 0; k < 3; k++) {
        min_m[k] -= 0.01 * sqrt(d2);
        max_m[k] += 0.01 * sqrt(d2);
    }
    return true;
}

/* A uniform point in the box and an isotropic direction. */
static void air_emission_volume_point(const air_emission *a, rng_stream *rng, vec3 *p, vec3 *dir)
{
    double x[3];
    for (int k = 0; k < 3; k++)
        x[k] = a->min_m[k] + rng_uniform32(rng) * (a->max_m[k] - a->min_m[k]);
    *p = v3(x[0], x[1], x[2]);
    double z = 1.0 - 2.0 * rng_uniform32(rng);
    double s = sqrt(fmax(0.0, 1.0 - z * z)), phi = 2.0 * M_PI * rng_uniform32(rng);
    *dir = v3(s * cos(phi), s * sin(phi), z);
}

/* A point uniform over the box's faces (by area) and a cosine-distributed direction
 * into the box. */
static void air_emission_face_point(const air_emission *a, rng_stream *rng, vec3 *p, vec3 *dir)
{
    double x = rng_uniform32(rng) * a->face_cdf[5];
    int f = 0;
    while (f < 5 && !(a->face_cdf[f] > x))
        f++;
    int axis = f / 2;
    bool at_max = f % 2 == 1;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = a->min_m[k] + rng_uniform32(rng) * (a->max_m[k] - a->min_m[k]);
    c[axis] = at_max ? a->max_m[axis] : a->min_m[axis];
    *p = v3(c[0], c[1], c[2]);
    double nv[3] = {0.0, 0.0, 0.0};
    nv[axis] = at_max ? -1.0 : 1.0;
    double u = rng_uniform32(rng);
    *dir = sampling_direction(v3(nv[0], nv[1], nv[2]), sqrt(1.0 - u), rng_uniform32(rng));
}

/* Whether a boundary photon at p going along dir comes from outside: a ray from just
 * inside back out of the box meets nothing (always, without casting it, when every mesh
 * keeps clear of the faces). */
static bool air_emission_open(const air_emission *a, vec3 p, vec3 dir)
{
    if (a->faces_clear)
        return true;
    accel_hit hit;
    return !accel_intersect(a->acc, v3_madd(p, a->eps_m, dir), v3_scale(dir, -1.0), INFINITY,
                            ACCEL_NO_OBJECT, 0, &hit);
}

/* Whether trace_photon keeps a photon starting at p along dir: its first hit is not the
 * back face of a one-sided solid. */
static bool air_emission_kept(const air_emission *a, vec3 p, vec3 dir)
{
    accel_hit hit;
    return !accel_intersect(a->acc, p, dir, INFINITY, ACCEL_NO_OBJECT, 0, &hit) ||
           scene_object_side_is_front(&a->scene->objects[hit.object], hit.side);
}

/* Whether a photon starting at p along dir meets the front side of a surface first: it
 * stores a record (a deviation map's boundary photons count only if so, see below). */
static bool air_emission_reaches(const air_emission *a, vec3 p, vec3 dir)
{
    accel_hit hit;
    return accel_intersect(a->acc, p, dir, INFINITY, ACCEL_NO_OBJECT, 0, &hit) &&
           scene_object_side_is_front(&a->scene->objects[hit.object], hit.side);
}

/* Whether every mesh's bounding box lies inside the box by more than 1e-3 of its
 * diagonal (1000 times the step eps_m the visibility ray starts inside): that ray runs
 * from eps_m inside a face outwards, so it can meet no surface. Always so without an
 * extent (the box is widened by 1 % of the meshes' diagonal). */
static bool air_emission_faces_clear(const air_emission *a)
{
    double margin = 1e3 * a->eps_m;
    for (size_t i = 0; i < a->scene->n_objects; i++) {
        const thz_mesh *m = &a->scene->objects[i].mesh;
        if (m->n_triangles == 0)
            continue;
        for (int k = 0; k < 3; k++)
            if (!(m->bbox_min_m[k] - a->min_m[k] > margin &&
                  a->max_m[k] - m->bbox_max_m[k] > margin))
                return false;
    }
    return true;
}

/* Shares of air and boundary photons kept, by the rules of sampling and tracing; with
 * T0 > 0 also the share of boundary photons that reach a surface. */
static void air_emission_shares(air_emission *a)
{
    uint64_t air = 0, open = 0, reach = 0;
    for (uint64_t i = 0; i < AIR_EMISSION_SHARE_RAYS; i++) {
        rng_stream rng;
        rng_init(&rng, a->scene->photons.seed, (uint32_t)a->channel, RNG_PURPOSE_AIR_VOLUME, i);
        vec3 p, dir;
        air_emission_volume_point(a, &rng, &p, &dir);
        air += air_emission_kept(a, p, dir);
        air_emission_face_point(a, &rng, &p, &dir);
        bool is_open = air_emission_open(a, p, dir) && air_emission_kept(a, p, dir);
        open += is_open;
        if (a->t0_k > 0.0)
            reach += is_open && air_emission_reaches(a, p, dir);
    }
    a->air_share = (double)air / AIR_EMISSION_SHARE_RAYS;
    a->open_share = (double)open / AIR_EMISSION_SHARE_RAYS;
    a->reach_share = a->t0_k > 0.0 ? (double)reach / AIR_EMISSION_SHARE_RAYS : a->open_share;
}

/* The air's frequency histogram (of |g_c P_air|) and band powers over the whole box: the
 * deviation source's (signed) and the air's own emission (0 if none). */
static thz_status air_emission_tabulate(air_emission *a, double *power, double *physical_power,
                                        thz_error *err)
{
    *power = *physical_power = 0.0;
    const thz_channel *ch = &a->scene->channels[a->channel];
    double lo, hi;
    channel_support_hz(ch, AIR_EMISSION_SIGMAS, &lo, &hi);
    if (lo < 0.0)
        lo = 0.0;
    a->lo_hz = lo;
    a->bin_hz = (hi - lo) / AIR_EMISSION_BINS;
    a->q = thz_malloc_array(AIR_EMISSION_BINS, sizeof *a->q);
    a->cdf = thz_malloc_array(AIR_EMISSION_BINS, sizeof *a->cdf);
    if (!a->q || !a->cdf)
        return thz_error_set(err, THZ_ERR_NOMEM, "air emission: out of memory");
    /* q_i = the larger |node value| of the bin (the bins resolve alpha's table far finer
     * than a line), floored at 1e-6 of the peak so that q > 0 wherever g P may be
     * nonzero. (B(T_air) - B0 has one sign over the band: so has the density.) */
    double own_prev, own_next;
    double prev = air_emission_density(a, lo, &own_prev), peak = 0.0, trapezoid = 0.0;
    double own_trapezoid = 0.0;
    for (size_t i = 0; i < AIR_EMISSION_BINS; i++) {
        double next = air_emission_density(a, lo + (double)(i + 1) * a->bin_hz, &own_next);
        a->q[i] = fmax(fabs(prev), fabs(next));
        trapezoid += 0.5 * (prev + next) * a->bin_hz;
        own_trapezoid += 0.5 * (own_prev + own_next) * a->bin_hz;
        peak = fmax(peak, a->q[i]);
        prev = next;
        own_prev = own_next;
    }
    *physical_power = own_trapezoid / channel_bandwidth_hz(ch);
    if (!(peak > 0.0)) {
        free(a->q);
        free(a->cdf);
        a->q = a->cdf = NULL;
        return THZ_OK;
    }
    double sum = 0.0;
    for (size_t i = 0; i < AIR_EMISSION_BINS; i++) {
        a->q[i] = fmax(a->q[i], 1e-6 * peak);
        sum += a->q[i] * a->bin_hz;
        a->cdf[i] = sum;
    }
    *power = trapezoid / channel_bandwidth_hz(ch);
    return THZ_OK;
}

thz_status air_emission_init(air_emission *a, const thz_scene *scene, const accel *acc,
                             size_t channel, uint64_t n_photons, double surface_power_w_per_hz,
                             double t0_k, thz_error *err)
{
    memset(a, 0, sizeof *a);
    a->scene = scene;
    a->acc = acc;
    a->channel = channel;
    a->n_photons = n_photons ? n_photons : 1;
    a->t0_k = t0_k > 0.0 ? t0_k : 0.0;
    const thz_atmosphere *atm = &scene->atmosphere;
    /* With T0 > 0 the boundary emits L_b - B0 != 0 and absorbing air 4 pi alpha
     * (B(T_air) - B0) != 0 even when the atmosphere does not emit. */
    if ((!atm->emitting && !(a->t0_k > 0.0)) || !air_emission_box(scene, a->min_m, a->max_m))
        return THZ_OK;
    double ext[3], d2 = 0.0;
    for (int k = 0; k < 3; k++) {
        ext[k] = a->max_m[k] - a->min_m[k];
        d2 += ext[k] * ext[k];
    }
    a->eps_m = 1e-6 * sqrt(d2);
    a->faces_clear = air_emission_faces_clear(a);
    a->volume_m3 = ext[0] * ext[1] * ext[2];
    double sum = 0.0;
    for (int f = 0; f < 6; f++) {
        int axis = f / 2;
        sum += ext[(axis + 1) % 3] * ext[(axis + 2) % 3];
        a->face_cdf[f] = sum;
    }
    a->area_m2 = sum;

    /* Band powers over the whole box and faces: the air's and the boundary's own
     * (physical) ones, their deviation sources' (signed) ones and the magnitudes that
     * set the class probabilities. All equal when T0 = 0. */
    double air_box = 0.0, air_own = 0.0, boundary_box = 0.0, boundary_own = 0.0;
    double boundary_magnitude = 0.0;
    const thz_channel *ch = &scene->channels[channel];
    if (a->volume_m3 > 0.0) {
        thz_status st = air_emission_tabulate(a, &air_box, &air_own, err);
        if (st != THZ_OK) {
            air_emission_fini(a);
            return st;
        }
    }
    if (a->area_m2 > 0.0) {
        boundary_own =
            atm->emitting
                ? M_PI * a->area_m2 * channel_band_mean(ch, air_emission_boundary_at, (void *)atm)
                : 0.0;
        if (a->t0_k > 0.0) {
            boundary_box =
                M_PI * a->area_m2 * channel_band_mean(ch, air_emission_boundary_deviation_at, a);
            boundary_magnitude =
                M_PI * a->area_m2 * channel_band_mean(ch, air_emission_boundary_magnitude_at, a);
        } else {
            boundary_box = boundary_magnitude = boundary_own;
        }
    }
    bool air_fires = a->q != NULL && air_box != 0.0;
    bool boundary_fires = boundary_magnitude > 0.0;
    if (!air_fires && !boundary_fires && !(air_own > 0.0) && !(boundary_own > 0.0)) {
        air_emission_fini(a);
        a->scene = scene;
        a->t0_k = t0_k > 0.0 ? t0_k : 0.0;
        return THZ_OK;
    }
    air_emission_shares(a);
    /* A deviation map's boundary fires only where its photons reach a surface: in a
     * closed room without extent the box's faces see the room from outside, and the
     * photons that slip through the gap between them store nothing (they would take
     * most of the photons when the surfaces' sources are small, as near T0). */
    if (a->t0_k > 0.0)
        boundary_fires = boundary_fires && a->reach_share > 0.0;
    a->air_power_w_per_hz = a->air_share * air_own;
    a->boundary_power_w_per_hz = a->open_share * boundary_own;
    a->band_power_w_per_hz = a->air_power_w_per_hz + a->boundary_power_w_per_hz;
    a->air_deviation_w_per_hz = a->air_share * air_box;
    a->boundary_deviation_w_per_hz = a->open_share * boundary_box;
    if (a->t0_k > 0.0 && !air_fires && !boundary_fires)
        return THZ_OK; /* nothing to fire (a furnace at T0): statistics only */
    double air_mass = air_fires ? a->air_share * fabs(air_box) : 0.0;
    double boundary_mass = a->reach_share * boundary_magnitude;
    if (!boundary_fires)
        boundary_mass = 0.0;
    double surface_mass = fmax(surface_power_w_per_hz, 0.0);
    double total = air_mass + boundary_mass + surface_mass;
    if (!(total > 0.0))
        return THZ_OK; /* every air and boundary photon would be dropped */
    a->p_air = air_mass / total;
    a->p_boundary = boundary_mass / total;
    a->p_surfaces = surface_mass / total;
    a->active = true;
    return THZ_OK;
}

/* An air photon: frequency from the histogram, point and direction uniform. */
static bool air_emission_air_photon(const air_emission *a, rng_stream *rng, emission_photon *out)
{
    double x = rng_uniform32(rng) * a->cdf[AIR_EMISSION_BINS - 1];
    size_t lo = cdf_search(a->cdf, AIR_EMISSION_BINS, x);
    double nu = a->lo_hz + ((double)lo + rng_uniform32(rng)) * a->bin_hz;
    /* sigma sqrt(2 pi) = B_c (channel_sigma_hz; kept as two factors, the outputs' rounding) */
    double sigma = channel_sigma_hz(&a->scene->channels[a->channel]);
    double f = air_emission_density(a, nu, NULL);
    out->freq_hz = nu;
    out->power_w_per_hz = f * a->cdf[AIR_EMISSION_BINS - 1] /
                          (a->q[lo] * sigma * sqrt(2.0 * M_PI) * a->p_air * (double)a->n_photons);
    air_emission_volume_point(a, rng, &out->position_m, &out->dir);
    return out->power_w_per_hz != 0.0;
}

/* A boundary photon: frequency from g_c, a point on the faces, cosine inwards; dropped
 * (power 0) where the point is hidden from outside. */
static bool air_emission_boundary_photon(const air_emission *a, rng_stream *rng,
                                         emission_photon *out)
{
    const thz_channel *ch = &a->scene->channels[a->channel];
    double u1 = rng_uniform32(rng), u2 = rng_uniform32(rng);
    double nu = channel_sample_hz(ch, u1, u2);
    out->freq_hz = nu;
    air_emission_face_point(a, rng, &out->position_m, &out->dir);
    out->power_w_per_hz = 0.0;
    if (!air_emission_open(a, out->position_m, out->dir))
        return false;
    out->power_w_per_hz = M_PI * a->area_m2 * air_emission_boundary_deviation(a, nu) /
                          (a->p_boundary * (double)a->n_photons);
    return out->power_w_per_hz != 0.0;
}

bool air_emission_draw_class(const air_emission *a, rng_stream *rng, emission_photon *out,
                             bool *surface)
{
    *surface = true;
    if (!a || !a->active)
        return true;
    out->batch = 0;
    double u = rng_uniform32(rng);
    if (!(u < a->p_air + a->p_boundary))
        return true;
    *surface = false;
    out->object = ACCEL_NO_OBJECT;
    out->triangle = 0;
    out->side = 0;
    return u < a->p_air ? air_emission_air_photon(a, rng, out)
                        : air_emission_boundary_photon(a, rng, out);
}

void air_emission_surface_share(const air_emission *a, emission_photon *out)
{
    if (a && a->active)
        out->power_w_per_hz = a->p_surfaces > 0.0 ? out->power_w_per_hz / a->p_surfaces : 0.0;
}
