/* Emission sampling of the photon phase: see emission.h for the scheme. */
#include "photon/emission.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/cdf.h"
#include "core/sampling.h"
#include "photon/emission_reach.h"
#include "physics/planck.h"

static bool spectrum_is_constant(const thz_spectrum *s)
{
    return s->n <= 1;
}

void emission_table_fini(emission_table *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n_sources; i++)
        if (t->sources[i].owns_cdf)
            free(t->sources[i].triangle_cdf);
    for (size_t g = 0; g < t->n_groups; g++)
        free(t->groups[g].cdf);
    free(t->sources);
    free(t->groups);
    free(t->order);
    free(t->cum_q);
    memset(t, 0, sizeof *t);
}

/* Whether sources a and b have powers in a frequency-independent ratio. */
static bool emission_same_group(const emission_table *t, const emission_source *a,
                                const emission_source *b)
{
    const thz_object *oa = &t->scene->objects[a->object], *ob = &t->scene->objects[b->object];
    if (a->kind == EMISSION_BACK || b->kind == EMISSION_BACK)
        return a->kind == b->kind; /* -pi A r B0 whatever the object */
    if (oa->temperature_k != ob->temperature_k || a->constant_optics != b->constant_optics)
        return false;
    if (t->t0_k > 0.0 && a->kind != b->kind)
        return false; /* with T0 = 0 every kind's power is B(T) times a constant */
    if (a->constant_optics)
        return a->kind != EMISSION_EPS_ABSORB || (a->optics.emissivity == b->optics.emissivity &&
                                                  a->optics.reflectivity == b->optics.reflectivity);
    return oa->material == ob->material && oa->type == ob->type &&
           oa->thickness_m == ob->thickness_m && a->sides == b->sides;
}

/* Groups the sources (in order of first appearance). */
static bool emission_group_sources(emission_table *t)
{
    size_t n = t->n_sources;
    t->groups = thz_calloc(n ? n : 1, sizeof *t->groups);
    t->order = thz_malloc_array(n ? n : 1, sizeof *t->order);
    bool *taken = thz_calloc(n ? n : 1, sizeof *taken);
    if (!t->groups || !t->order || !taken) {
        free(taken);
        return false;
    }
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (taken[i])
            continue;
        const emission_source *s = &t->sources[i];
        emission_group *g = &t->groups[t->n_groups++];
        g->temperature_k = t->scene->objects[s->object].temperature_k;
        g->kind = s->kind;
        g->constant_optics = s->constant_optics;
        g->first = k;
        for (size_t j = i; j < n; j++) {
            const emission_source *u = &t->sources[j];
            if (taken[j] || (j != i && !emission_same_group(t, s, u)))
                continue;
            taken[j] = true;
            t->order[k++] = j;
            g->weight += u->constant_optics ? u->weight : M_PI * u->share;
            g->weight0 += u->constant_optics ? u->weight0 : 0.0;
        }
        g->count = k - g->first;
        if (g->count > 1) {
            g->cdf = thz_malloc_array(g->count, sizeof *g->cdf);
            if (!g->cdf) {
                free(taken);
                return false;
            }
            double acc = 0.0;
            for (size_t m = 0; m < g->count; m++) {
                acc += t->sources[t->order[g->first + m]].share;
                g->cdf[m] = acc;
            }
        }
    }
    free(taken);
    return true;
}

/* Tabulates q_g on EMISSION_TABLE_NODES nodes over the band as cumulative sums over the
 * groups. q_g(node) = max(|w_g(node)|, floor) with floor = 1e-6 of the largest sum of
 * |w_g|: q_g > 0 everywhere, so every group with power at some frequency (of either
 * sign) can be drawn there. */
static bool emission_tabulate(emission_table *t)
{
    const thz_channel *ch = &t->scene->channels[t->channel];
    size_t ng = t->n_groups ? t->n_groups : 1;
    t->cum_q = thz_malloc_array((size_t)EMISSION_TABLE_NODES * ng, sizeof *t->cum_q);
    if (!t->cum_q)
        return false;
    double lo, hi;
    channel_support_hz(ch, EMISSION_TABLE_SIGMAS, &lo, &hi);
    if (lo < 0.0)
        lo = 0.0;
    t->nu0_hz = lo;
    t->step_hz = (hi - lo) / (EMISSION_TABLE_NODES - 1);
    double largest = 0.0;
    for (size_t i = 0; i < EMISSION_TABLE_NODES; i++) {
        double *row = &t->cum_q[i * ng];
        double nu = lo + (double)i * t->step_hz;
        double total = 0.0;
        for (size_t g = 0; g < t->n_groups; g++) {
            row[g] = nu > 0.0 ? fabs(emission_group_power(t, g, nu)) : 0.0;
            total += row[g];
        }
        largest = total > largest ? total : largest;
    }
    double floor_w = 1e-6 * largest;
    if (!(floor_w > 0.0))
        floor_w = DBL_MIN;
    for (size_t i = 0; i < EMISSION_TABLE_NODES; i++) {
        double *row = &t->cum_q[i * ng];
        double acc = 0.0;
        for (size_t g = 0; g < t->n_groups; g++) {
            acc += row[g] > floor_w ? row[g] : floor_w;
            row[g] = acc;
        }
    }
    return true;
}

/* A-bar and sampling by A(mu) mu: the optics with Kirchhoff's eps = A. */
static optics_point emission_kirchhoff_optics(optics_point o)
{
    o.explicit_emissivity = false;
    return o;
}

double *emission_triangle_cdf(const thz_mesh *m)
{
    size_t n = m->n_triangles;
    if (n > UINT32_MAX)
        return NULL;
    double *cdf = thz_malloc_array(n, sizeof(double) + sizeof(uint32_t));
    if (!cdf)
        return NULL;
    double sum = 0.0;
    for (size_t k = 0; k < n; k++) {
        sum += m->areas_m2[k];
        cdf[k] = sum;
    }
    cdf_guide_build(cdf, n, (uint32_t *)(void *)(cdf + n), n);
    return cdf;
}

vec3 emission_point(const thz_mesh *m, const double *triangle_cdf, double area_m2, rng_stream *rng,
                    size_t *tri)
{
    /* the guide table follows the CDF in its block (emission_triangle_cdf) */
    const uint32_t *guide = (const uint32_t *)(const void *)(triangle_cdf + m->n_triangles);
    double u = rng_uniform32(rng);
    size_t k =
        cdf_search_guided(triangle_cdf, m->n_triangles, guide, m->n_triangles, u, u * area_m2);
    while (m->areas_m2[k] <= 0.0 && k > 0)
        k--;
    *tri = k;
    /* p = (1 - sqrt(a)) p0 + sqrt(a)(1 - b) p1 + sqrt(a) b p2. */
    const uint32_t *idx = &m->indices[3 * k];
    vec3 p0 = v3_from_floats(&m->positions[3 * (size_t)idx[0]]);
    vec3 p1 = v3_from_floats(&m->positions[3 * (size_t)idx[1]]);
    vec3 p2 = v3_from_floats(&m->positions[3 * (size_t)idx[2]]);
    double ra = sqrt(rng_uniform32(rng)), rb = rng_uniform32(rng);
    return v3_add(v3_scale(p0, 1.0 - ra),
                  v3_add(v3_scale(p1, ra * (1.0 - rb)), v3_scale(p2, ra * rb)));
}

/* Adds object i's source of `kind` (EMISSION_BACK: whose reach share is reach_share);
 * false only when out of memory. A source without power (constant optics, zero weights; a
 * back side that reaches no front face) is not added. An object's sources share one
 * triangle CDF. */
static bool emission_add_source(emission_table *t, size_t i, emission_kind kind, double reach_share)
{
    const thz_scene *scene = t->scene;
    const thz_object *obj = &scene->objects[i];
    emission_source *s = &t->sources[t->n_sources];
    memset(s, 0, sizeof *s);
    s->object = (uint32_t)i;
    s->kind = kind;
    s->sides = (obj->type == OBJECT_SHELL || obj->two_sided) ? 2 : 1;
    const thz_material *m = &scene->materials[obj->material];
    s->constant_optics =
        kind == EMISSION_BACK ||
        (!m->index && spectrum_is_constant(&m->reflectivity) &&
         spectrum_is_constant(&m->attenuation_per_m) && spectrum_is_constant(&m->emissivity));
    s->area_m2 = obj->mesh.total_area_m2; /* the sum of areas_m2, in order */
    s->share = s->area_m2 * s->sides;
    s->reach_share = 1.0;
    /* The object's previous source (an explicit-emissivity shell's eps B(T), a solid's
     * front side) has the same triangle CDF. */
    const emission_source *prev = t->n_sources ? &t->sources[t->n_sources - 1] : NULL;
    s->triangle_cdf = prev && prev->object == s->object ? prev->triangle_cdf : NULL;
    s->owns_cdf = false;
    if (!s->triangle_cdf) {
        s->triangle_cdf = emission_triangle_cdf(&obj->mesh);
        if (!s->triangle_cdf)
            return false;
        s->owns_cdf = true;
    }
    if (kind == EMISSION_BACK) {
        s->reach_share = reach_share;
        s->weight0 = M_PI * s->area_m2 * s->reach_share;
        s->share = s->weight0;
    } else if (s->constant_optics) {
        s->optics = scene_object_optics(scene, obj, scene->channels[t->channel].center_hz);
        optics_prepare(&s->optics);
        s->cosine_law = kind != EMISSION_ABSORB && optics_emission_is_cosine(&s->optics);
        double eps = optics_mean_emissivity(&s->optics);
        optics_point kirchhoff = emission_kirchhoff_optics(s->optics);
        double abs = optics_mean_emissivity(&kirchhoff);
        double coef = M_PI * s->area_m2 * s->sides;
        s->weight = kind == EMISSION_ABSORB ? 0.0 : M_PI * eps * s->area_m2 * s->sides;
        if (t->t0_k > 0.0)
            s->weight0 = kind == EMISSION_KIRCHHOFF ? s->weight
                         : kind == EMISSION_EPS     ? 0.0
                                                    : coef * abs;
        s->share = s->weight + s->weight0;
    }
    if (!(s->share > 0.0)) { /* eps-bar = 0 (and A-bar = 0), or a closed back: nothing */
        if (s->owns_cdf)
            free(s->triangle_cdf);
        memset(s, 0, sizeof *s);
        return true;
    }
    t->n_sources++;
    return true;
}

thz_status emission_table_init(emission_table *t, const thz_scene *scene, const accel *acc,
                               size_t channel, uint64_t n_photons, double t0_k,
                               const emission_reach *reach, thz_error *err)
{
    memset(t, 0, sizeof *t);
    if (!(t0_k >= 0.0) || !isfinite(t0_k))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "photon emission: reference temperature must be >= 0 K, got %g K",
                             t0_k);
    if (t0_k > 0.0 && !acc)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "photon emission: a deviation map needs the scene's ray caster");
    emission_reach own = {0};
    if (t0_k > 0.0 && (!reach || !reach->done)) {
        thz_status st = emission_reach_compute(&own, scene, acc, 0, NULL, NULL, err);
        if (st != THZ_OK)
            return st;
        reach = &own;
    }
    if (t0_k > 0.0 && reach->n_objects != scene->n_objects) {
        emission_reach_fini(&own);
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "photon emission: reach shares of %zu objects for a scene of %zu",
                             reach->n_objects, scene->n_objects);
    }
    t->scene = scene;
    t->channel = channel;
    t->n_photons = n_photons ? n_photons : 1;
    t->t0_k = t0_k;
    /* At most three sources per object (with T0 > 0: an explicit-emissivity shell or
     * solid with a complex index is two, eps B(T) and -A(mu) B0, and a one-sided solid
     * adds its back side); emission_add_source writes a slot before it knows whether the
     * source has power. */
    size_t cap = 3 * scene->n_objects;
    t->sources = thz_calloc(cap ? cap : 1, sizeof *t->sources);
    if (!t->sources) {
        emission_reach_fini(&own);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
    }
    bool ok = true;
    for (size_t i = 0; i < scene->n_objects && ok; i++) {
        const thz_object *obj = &scene->objects[i];
        if (!(obj->mesh.total_area_m2 > 0.0) || obj->mesh.n_triangles == 0)
            continue;
        bool hot = obj->temperature_k > 0.0;
        bool explicit_eps = scene->materials[obj->material].emissivity.n > 0;
        if (!(t0_k > 0.0)) { /* the paper's sources: eps B(T) */
            if (hot)
                ok = emission_add_source(t, i, explicit_eps ? EMISSION_EPS : EMISSION_KIRCHHOFF,
                                         1.0);
        } else if (!explicit_eps) { /* A (B(T) - B0): nothing at T0 */
            if (obj->temperature_k != t0_k)
                ok = emission_add_source(t, i, EMISSION_KIRCHHOFF, 1.0);
        } else if (obj->type == OBJECT_SHELL || scene->materials[obj->material].index) {
            /* eps B(T) and -A(mu) B0: two laws (A of a solid depends on angle with an index) */
            if (hot)
                ok = emission_add_source(t, i, EMISSION_EPS, 1.0);
            if (ok)
                ok = emission_add_source(t, i, EMISSION_ABSORB, 1.0);
        } else {
            ok = emission_add_source(t, i, EMISSION_EPS_ABSORB, 1.0);
        }
        if (ok && t0_k > 0.0 && emission_reach_needed(scene, i))
            ok = emission_add_source(t, i, EMISSION_BACK, reach->share[i]);
    }
    emission_reach_fini(&own);
    if (!ok || !emission_group_sources(t) || !emission_tabulate(t)) {
        emission_table_fini(t);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
    }
    return THZ_OK;
}

/* The signed power of group gr at freq_hz, given the optics `o` of its sources (used
 * for variable optics only). */
static double emission_power_with(const emission_table *t, const emission_group *gr,
                                  const optics_point *o, double freq_hz)
{
    double b0 = t->t0_k > 0.0 ? planck_radiance(freq_hz, t->t0_k) : 0.0;
    double w;
    switch (gr->kind) {
    case EMISSION_KIRCHHOFF:
    case EMISSION_EPS:
    default:
        /* EMISSION_EPS has no B0 term (and with T0 = 0 b0 = 0, B - 0 = B exactly). */
        w = gr->weight * (planck_radiance(freq_hz, gr->temperature_k) -
                          (gr->kind == EMISSION_KIRCHHOFF ? b0 : 0.0));
        if (!gr->constant_optics)
            w *= optics_mean_emissivity(o);
        return w;
    case EMISSION_EPS_ABSORB:
        if (gr->constant_optics)
            return gr->weight * planck_radiance(freq_hz, gr->temperature_k) - gr->weight0 * b0;
        {
            optics_point k = emission_kirchhoff_optics(*o);
            return gr->weight *
                   (optics_mean_emissivity(o) * planck_radiance(freq_hz, gr->temperature_k) -
                    optics_mean_emissivity(&k) * b0);
        }
    case EMISSION_BACK:
        return -gr->weight0 * b0;
    case EMISSION_ABSORB:
        if (gr->constant_optics)
            return -gr->weight0 * b0;
        {
            optics_point k = emission_kirchhoff_optics(*o);
            return -gr->weight * optics_mean_emissivity(&k) * b0;
        }
    }
}

double emission_group_power(const emission_table *t, size_t g, double freq_hz)
{
    const emission_group *gr = &t->groups[g];
    optics_point o = {0};
    if (!gr->constant_optics) {
        const emission_source *s = &t->sources[t->order[gr->first]];
        o = scene_object_optics(t->scene, &t->scene->objects[s->object], freq_hz);
    }
    return emission_power_with(t, gr, &o, freq_hz);
}

static double emission_magnitude_at(double freq_hz, void *ctx)
{
    const emission_table *t = ctx;
    double total = 0.0;
    for (size_t g = 0; g < t->n_groups; g++)
        total += fabs(emission_group_power(t, g, freq_hz));
    return total;
}

double emission_band_magnitude_w_per_hz(const emission_table *t)
{
    if (t->n_groups == 0)
        return 0.0;
    return channel_band_mean(&t->scene->channels[t->channel], emission_magnitude_at, (void *)t);
}

/* The tabulated cumulative weight C_g(nu) at interpolation position (row, frac). */
static double emission_cum(const emission_table *t, size_t row, double frac, size_t g)
{
    const double *a = &t->cum_q[row * t->n_groups + g];
    return a[0] + frac * (a[t->n_groups] - a[0]);
}

bool emission_sample(const emission_table *t, rng_stream *rng, emission_photon *out)
{
    const thz_channel *ch = &t->scene->channels[t->channel];
    double u1 = rng_uniform32(rng), u2 = rng_uniform32(rng);
    return emission_sample_at(t, rng, channel_sample_hz(ch, u1, u2), out);
}

bool emission_sample_at(const emission_table *t, rng_stream *rng, double nu, emission_photon *out)
{
    emission_aim aim;
    if (!emission_sample_aim(t, rng, nu, out, &aim))
        return false;
    out->dir = sampling_direction(aim.normal, aim.mu, aim.u);
    return true;
}

bool emission_sample_aim(const emission_table *t, rng_stream *rng, double nu, emission_photon *out,
                         emission_aim *aim)
{
    out->batch = 0;
    out->freq_hz = nu;
    out->power_w_per_hz = 0.0;
    if (t->n_groups == 0)
        return false;

    /* Group g by q_g(nu): C_g(nu) interpolates two monotone rows, so it is monotone in g
     * and a binary search finds the first C_g > x; then q_g = C_g - C_{g-1} > 0. */
    double pos = (nu - t->nu0_hz) / t->step_hz;
    if (!(pos > 0.0))
        pos = 0.0;
    if (pos > EMISSION_TABLE_NODES - 1)
        pos = EMISSION_TABLE_NODES - 1;
    size_t row = (size_t)pos;
    if (row > EMISSION_TABLE_NODES - 2)
        row = EMISSION_TABLE_NODES - 2;
    double frac = pos - (double)row;
    size_t ng = t->n_groups;
    double total = emission_cum(t, row, frac, ng - 1);
    double x = rng_uniform32(rng) * total;
    size_t lo = 0, hi = ng - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (emission_cum(t, row, frac, mid) > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    size_t g = lo;
    double q = emission_cum(t, row, frac, g) - (g ? emission_cum(t, row, frac, g - 1) : 0.0);

    const emission_group *gr = &t->groups[g];
    size_t within = 0;
    if (gr->count > 1) { /* a draw only where there is a choice (docs/physics.md) */
        within = cdf_search(gr->cdf, gr->count, rng_uniform32(rng) * gr->cdf[gr->count - 1]);
        while (t->sources[t->order[gr->first + within]].share <= 0.0 && within > 0)
            within--;
    }
    size_t src = t->order[gr->first + within];
    const emission_source *s = &t->sources[src];
    const thz_object *obj = &t->scene->objects[s->object];
    const thz_mesh *m = &obj->mesh;

    /* The exact signed power of the group drawn, at this frequency. */
    const optics_point *o = &s->optics;
    optics_point at_nu;
    if (!s->constant_optics) {
        at_nu = scene_object_optics(t->scene, obj, nu);
        o = &at_nu;
    }
    double w = emission_power_with(t, gr, o, nu);
    if (w == 0.0 || isnan(w) || !(q > 0.0))
        return false;
    out->power_w_per_hz = w * (total / q) / (double)t->n_photons;
    bool back = s->kind == EMISSION_BACK;
    if (back) /* drawn r times as often as its power says (emission.h) */
        out->power_w_per_hz /= s->reach_share;

    int side = back ? 1 : 0;
    if (!back && s->sides == 2)
        side = rng_uniform32(rng) < 0.5 ? 0 : 1;

    size_t tri;
    out->position_m = emission_point(m, s->triangle_cdf, s->area_m2, rng, &tri);

    const float *nf = &m->normals[3 * tri];
    vec3 n = v3(nf[0], nf[1], nf[2]);
    if (side == 1)
        n = v3_scale(n, -1.0);
    /* mu ~ eps(mu) mu, or A(mu) mu for the -A B0 part of an explicit-emissivity shell
     * (EMISSION_EPS_ABSORB is a solid's: eps and A both cosine). */
    double mu;
    if (back || s->cosine_law) {
        mu = sqrt(1.0 - rng_uniform32(rng)); /* radiance -B0, or constant eps: cosine */
    } else {
        optics_point law = s->kind == EMISSION_ABSORB ? emission_kirchhoff_optics(*o) : *o;
        if (!optics_sample_emission_mu(&law, sampling_uniform32, rng, &mu))
            mu = sqrt(1.0 - rng_uniform32(rng)); /* eps = 0 (a -A B0 source) or unreachable */
    }
    aim->normal = n;
    aim->mu = mu;
    aim->u = rng_uniform32(rng);
    out->object = s->object;
    out->triangle = (uint32_t)tri;
    out->side = side;
    return true;
}
