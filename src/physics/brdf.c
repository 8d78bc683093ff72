/* Reflection lobes: see brdf.h. */
#include "physics/brdf.h"

#include <math.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "physics/gauss_legendre.h"

/* The albedo table: mu_j = j / (WARD_MU - 1) (mu_0 evaluated at WARD_MU_MIN), phi_i =
 * (pi/2) i / (WARD_PHI - 1) (the lobe is symmetric under phi -> -phi and pi - phi),
 * each entry the mean of WARD_SAMPLES^2 stratified importance samples. */
#define WARD_MU 33
#define WARD_PHI 9
#define WARD_SAMPLES 64
#define WARD_MU_MIN 1e-3

struct brdf_ward_table {
    double ax, ay;
    double a[WARD_MU][WARD_PHI];
    double a_max[WARD_MU]; /* max over phi */
    double a_mean;         /* (1/pi) int a_W cos dw of the interpolant */
};

/* Local coordinates of w in frame f. */
static vec3 brdf_local(const brdf_frame *f, vec3 w)
{
    return v3(v3_dot(w, f->t), v3_dot(w, f->b), v3_dot(w, f->n));
}

static vec3 brdf_world(const brdf_frame *f, vec3 l)
{
    return v3_madd(v3_madd(v3_scale(f->t, l.x), l.y, f->b), l.z, f->n);
}

/* f_W of local directions wi, wo (both z > 0). */
static double ward_eval(double ax, double ay, vec3 wi, vec3 wo)
{
    vec3 h = v3_add(wi, wo);
    if (!(h.z > 0.0))
        return 0.0;
    double hx = h.x / (ax * h.z), hy = h.y / (ay * h.z);
    double hz2 = h.z * h.z;
    return v3_dot(h, h) / (M_PI * ax * ay * hz2 * hz2) * exp(-(hx * hx + hy * hy));
}

/* Ward's half-vector sample for local wi with uniforms u, v: the outgoing local
 * direction and the weight f_W cos_o / pdf = mu_o / ((wi.h)(h.n)) (h unit); false
 * below the surface. */
static bool ward_sample(double ax, double ay, vec3 wi, double u, double v, vec3 *wo, double *weight)
{
    double phi = atan2(ay * sin(2.0 * M_PI * u), ax * cos(2.0 * M_PI * u));
    double c = cos(phi), s = sin(phi);
    double tan2 = -log(1.0 - v) / (c * c / (ax * ax) + s * s / (ay * ay));
    double cos_h = 1.0 / sqrt(1.0 + tan2), sin_h = sqrt(tan2) * cos_h;
    vec3 h = v3(sin_h * c, sin_h * s, cos_h);
    double ih = v3_dot(wi, h);
    if (!(ih > 0.0))
        return false;
    *wo = v3_sub(v3_scale(h, 2.0 * ih), wi);
    if (!(wo->z > 0.0))
        return false;
    *weight = wo->z / (ih * cos_h);
    return true;
}

/* The local direction at cosine mu and azimuth phi. */
static vec3 brdf_dir(double mu, double phi)
{
    double s = sqrt(fmax(0.0, 1.0 - mu * mu));
    return v3(s * cos(phi), s * sin(phi), mu);
}

/* a_W at local (mu, phi) by bilinear interpolation of the table, phi folded into
 * [0, pi/2]. */
static double brdf_ward_albedo_at(const brdf_ward_table *t, double mu, double phi)
{
    double x = fabs(mu) * (WARD_MU - 1);
    if (x > WARD_MU - 1)
        x = WARD_MU - 1;
    int j = (int)x;
    if (j > WARD_MU - 2)
        j = WARD_MU - 2;
    double fx = x - j;
    double y = fabs(atan2(fabs(sin(phi)), fabs(cos(phi)))) / (0.5 * M_PI) * (WARD_PHI - 1);
    int i = (int)y;
    if (i > WARD_PHI - 2)
        i = WARD_PHI - 2;
    double fy = y - i;
    double a0 = t->a[j][i] + fy * (t->a[j][i + 1] - t->a[j][i]);
    double a1 = t->a[j + 1][i] + fy * (t->a[j + 1][i + 1] - t->a[j + 1][i]);
    return a0 + fx * (a1 - a0);
}

brdf_ward_table *brdf_ward_table_create(double alpha_x, double alpha_y)
{
    if (!(alpha_x > 0.0) || !(alpha_y > 0.0))
        return NULL;
    brdf_ward_table *t = thz_calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->ax = alpha_x;
    t->ay = alpha_y;
    for (int j = 0; j < WARD_MU; j++) {
        double mu = j == 0 ? WARD_MU_MIN : (double)j / (WARD_MU - 1);
        t->a_max[j] = 0.0;
        for (int i = 0; i < WARD_PHI; i++) {
            vec3 wi = brdf_dir(mu, 0.5 * M_PI * i / (WARD_PHI - 1));
            double sum = 0.0;
            for (int p = 0; p < WARD_SAMPLES; p++)
                for (int q = 0; q < WARD_SAMPLES; q++) {
                    vec3 wo;
                    double w;
                    if (ward_sample(alpha_x, alpha_y, wi, (p + 0.5) / WARD_SAMPLES,
                                    (q + 0.5) / WARD_SAMPLES, &wo, &w))
                        sum += w;
                }
            t->a[j][i] = sum / (WARD_SAMPLES * WARD_SAMPLES);
            t->a_max[j] = fmax(t->a_max[j], t->a[j][i]);
        }
    }
    /* (1/pi) int a cos dw = 2 int_0^1 mu <a>_phi dmu, <a>_phi by the trapezoid rule */
    double mean = 0.0;
    for (int g = 0; g < GAUSS_LEGENDRE_NODES; g++) {
        double mu = gauss_legendre_x[g], avg = 0.0;
        for (int i = 0; i < WARD_PHI; i++) {
            double w = (i == 0 || i == WARD_PHI - 1) ? 0.5 : 1.0;
            avg += w * brdf_ward_albedo_at(t, mu, 0.5 * M_PI * i / (WARD_PHI - 1));
        }
        mean += gauss_legendre_w[g] * mu * avg / (WARD_PHI - 1);
    }
    t->a_mean = 2.0 * mean;
    return t;
}

void brdf_ward_table_destroy(brdf_ward_table *t)
{
    free(t);
}

void brdf_lobe_init_sampling(brdf_lobe *l, const optics_point *o, const brdf_ward_table *ward)
{
    l->o = o;
    l->ward = o->lobe == OPTICS_LOBE_WARD ? ward : NULL;
    l->scale = 0.0;
    l->comp_norm = 0.0;
    if (!l->ward)
        return;
    const brdf_ward_table *t = l->ward;
    double s = INFINITY;
    for (int j = 0; j < WARD_MU; j++) {
        if (!(t->a_max[j] > 0.0))
            continue;
        double mu = j == 0 ? WARD_MU_MIN : (double)j / (WARD_MU - 1);
        double ratio = optics_reflectance(o, mu) / t->a_max[j];
        s = ratio < s ? ratio : s;
    }
    l->scale = isfinite(s) && s > 0.0 ? s : 0.0;
    l->comp_norm = NAN;
}

void brdf_lobe_init(brdf_lobe *l, const optics_point *o, const brdf_ward_table *ward)
{
    brdf_lobe_init_sampling(l, o, ward);
    if (!l->ward)
        return;
    double c = optics_mean_reflectance(o) - l->scale * l->ward->a_mean;
    l->comp_norm = c > 1e-12 ? M_PI * c : 0.0;
}

/* Ward's complement C(w) = R(mu) - s a_W(w) >= 0 at local w. */
static double brdf_complement(const brdf_lobe *l, vec3 w)
{
    double c = optics_reflectance(l->o, w.z) -
               l->scale * brdf_ward_albedo_at(l->ward, w.z, atan2(w.y, w.x));
    return c > 0.0 ? c : 0.0;
}

double brdf_eval(const brdf_lobe *l, const brdf_frame *f, vec3 wi, vec3 wo)
{
    const optics_point *o = l->o;
    double mi = v3_dot(wi, f->n), mo = v3_dot(wo, f->n);
    if (!(mi > 0.0) || !(mo > 0.0))
        return 0.0;
    switch (o->lobe) {
    case OPTICS_LOBE_SPECULAR:
        return 0.0;
    case OPTICS_LOBE_WARD: {
        if (!l->ward)
            return 0.0;
        vec3 li = brdf_local(f, wi), lo = brdf_local(f, wo);
        double v = l->scale * ward_eval(l->ward->ax, l->ward->ay, li, lo);
        if (l->comp_norm > 0.0)
            v += brdf_complement(l, li) * brdf_complement(l, lo) / l->comp_norm;
        return v;
    }
    case OPTICS_LOBE_DIFFUSE:
    default:
        if (!optics_reflectance_varies(o))
            return optics_reflectance(o, mi) / M_PI;
        {
            double rbar = optics_mean_reflectance(o);
            return rbar > 0.0
                       ? optics_reflectance(o, mi) * optics_reflectance(o, mo) / (M_PI * rbar)
                       : 0.0;
        }
    }
}

bool brdf_sample(const brdf_lobe *l, const brdf_frame *f, vec3 wi, optics_uniform_fn next,
                 void *ctx, vec3 *wo, double *weight)
{
    const optics_point *o = l->o;
    double mi = v3_dot(wi, f->n);
    *weight = 1.0;
    switch (o->lobe) {
    case OPTICS_LOBE_SPECULAR:
        *wo = v3_sub(v3_scale(f->n, 2.0 * mi), wi);
        return true;
    case OPTICS_LOBE_WARD: {
        if (!l->ward)
            return false;
        vec3 li = brdf_local(f, wi);
        double r = optics_reflectance(o, li.z);
        double lobe = l->scale * brdf_ward_albedo_at(l->ward, li.z, atan2(li.y, li.x));
        if (!(r > 0.0))
            return false;
        if (next(ctx) * r < lobe) {
            vec3 lo;
            double w;
            double u = next(ctx), v = next(ctx);
            if (!ward_sample(l->ward->ax, l->ward->ay, li, u, v, &lo, &w))
                return false;
            *wo = brdf_world(f, lo);
            *weight = w * l->scale / lobe; /* s f_W cos / pdf over the branch's s a_W */
            return true;
        }
        /* the complement: w ~ C(w) cos(theta), by rejection from the cosine law */
        for (long k = 0; k < OPTICS_MAX_TRIES; k++) {
            double mu = sqrt(1.0 - next(ctx));
            double phi = 2.0 * M_PI * next(ctx);
            vec3 lo = brdf_dir(mu, phi);
            if (mu > 0.0 && next(ctx) < brdf_complement(l, lo)) {
                *wo = brdf_world(f, lo);
                return true;
            }
        }
        return false;
    }
    case OPTICS_LOBE_DIFFUSE:
    default: {
        double mu;
        if (!optics_sample_reflection_mu(o, next, ctx, &mu))
            return false;
        double phi = 2.0 * M_PI * next(ctx);
        *wo = brdf_world(f, brdf_dir(mu, phi));
        return true;
    }
    }
}

double brdf_pdf(const brdf_lobe *l, const brdf_frame *f, vec3 wi, vec3 wo)
{
    const optics_point *o = l->o;
    double mi = v3_dot(wi, f->n), mo = v3_dot(wo, f->n);
    if (!(mi > 0.0) || !(mo > 0.0))
        return 0.0;
    switch (o->lobe) {
    case OPTICS_LOBE_SPECULAR:
        return 0.0;
    case OPTICS_LOBE_WARD: {
        if (!l->ward)
            return 0.0;
        vec3 li = brdf_local(f, wi), lo = brdf_local(f, wo);
        double r = optics_reflectance(o, li.z);
        if (!(r > 0.0))
            return 0.0;
        double lobe = l->scale * brdf_ward_albedo_at(l->ward, li.z, atan2(li.y, li.x));
        double p = 0.0;
        vec3 h = v3_normalize(v3_add(li, lo));
        if (lobe > 0.0)
            p += lobe / r * ward_eval(l->ward->ax, l->ward->ay, li, lo) * v3_dot(li, h) * h.z;
        if (l->comp_norm > 0.0)
            p += (1.0 - lobe / r) * brdf_complement(l, lo) * lo.z / l->comp_norm;
        return p;
    }
    case OPTICS_LOBE_DIFFUSE:
    default:
        if (!optics_reflectance_varies(o))
            return mo / M_PI;
        {
            double rbar = optics_mean_reflectance(o);
            return rbar > 0.0 ? optics_reflectance(o, mo) * mo / (M_PI * rbar) : 0.0;
        }
    }
}
