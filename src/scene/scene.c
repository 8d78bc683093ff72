/* The scene model: construction with the spec's defaults, destruction, warnings, and
 * the per-object optics and emitted power that every stage derives from it. */
#include "scene/scene.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/planck.h"
#include "scene/scene_hash.h"

const char *const scene_integrator_names[] = {
    [INTEGRATOR_PHOTON_MAP] = "photon-map",
    [INTEGRATOR_FINAL_GATHER] = "final-gather",
    [INTEGRATOR_PATH] = "path",
    [INTEGRATOR_PATH + 1] = NULL,
};

thz_scene *scene_create(void)
{
    thz_scene *s = thz_calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->hash_memo = scene_hash_memo_create();
    if (!s->hash_memo) {
        free(s);
        return NULL;
    }
    s->atmosphere.model = ATM_NONE;
    s->photons.per_channel = 1000000;
    s->photons.seed = 1;
    s->photons.min_relative_power = 0.01;
    s->photons.gather_min_photons = 16;
    s->render.integrator = INTEGRATOR_PATH; /* converged fastest: docs/integrators.md */
    s->render.gather_rays = 32;
    s->render.paths_per_sample = 16;
    return s;
}

void mesh_fini(thz_mesh *mesh)
{
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->normals);
    free(mesh->areas_m2);
    memset(mesh, 0, sizeof *mesh);
}

void scene_destroy(thz_scene *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < s->n_materials; i++) {
        thz_material *m = &s->materials[i];
        free(m->name);
        spectrum_fini(&m->reflectivity);
        spectrum_fini(&m->attenuation_per_m);
        spectrum_fini(&m->emissivity);
        material_index_destroy(m->index);
        brdf_ward_table_destroy(m->ward_table);
    }
    free(s->materials);
    for (size_t i = 0; i < s->n_objects; i++) {
        free(s->objects[i].name);
        mesh_fini(&s->objects[i].mesh);
    }
    free(s->objects);
    for (size_t i = 0; i < s->n_sensors; i++) {
        free(s->sensors[i].name);
        free(s->sensors[i].noise.netd_k);
    }
    free(s->sensors);
    for (size_t i = 0; s->channels && i < s->n_channels; i++)
        channel_fini(&s->channels[i]);
    free(s->channels);
    atmosphere_fini(&s->atmosphere);
    for (size_t i = 0; i < s->n_warnings; i++)
        free(s->warnings[i]);
    free(s->warnings);
    free(s->path);
    free(s->dir);
    free(s->name);
    scene_hash_memo_destroy(s->hash_memo);
    free(s);
}

void thz_scene_destroy(thz_scene *scene)
{
    scene_destroy(scene);
}

bool scene_add_warning(thz_scene *s, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    char **w = thz_realloc_array(s->warnings, s->n_warnings + 1, sizeof *w);
    if (!w)
        return false;
    s->warnings = w;
    w[s->n_warnings] = thz_strdup(buf);
    if (!w[s->n_warnings])
        return false;
    s->n_warnings++;
    return true;
}

bool scene_object_optics_constant(const thz_scene *s, const thz_object *obj)
{
    const thz_material *m = &s->materials[obj->material];
    return !m->index && m->reflectivity.n <= 1 && m->attenuation_per_m.n <= 1 &&
           m->emissivity.n <= 1;
}

optics_point scene_object_optics(const thz_scene *s, const thz_object *obj, double freq_hz)
{
    const thz_material *m = &s->materials[obj->material];
    optics_point o = {
        .reflectivity = spectrum_eval(&m->reflectivity, freq_hz),
        .attenuation_per_m = spectrum_eval(&m->attenuation_per_m, freq_hz),
        .thickness_m = obj->type == OBJECT_SHELL ? obj->thickness_m : 0.0,
        .explicit_emissivity = m->emissivity.n > 0,
        .freq_hz = freq_hz,
        .lobe = m->reflection == REFLECTION_SPECULAR ? OPTICS_LOBE_SPECULAR
                : m->reflection == REFLECTION_WARD   ? OPTICS_LOBE_WARD
                                                     : OPTICS_LOBE_DIFFUSE,
        .ward_alpha = {m->ward_alpha[0], m->ward_alpha[1]},
    };
    if (o.explicit_emissivity)
        o.emissivity = spectrum_eval(&m->emissivity, freq_hz);
    if (m->index && material_index_at(m->index, freq_hz, &o.n, &o.k)) {
        /* a property given beside the index overrides it (scene-format.md): the loader
         * leaves a spectrum empty (n == 0) when its key is absent */
        o.has_index = true;
        o.reflectivity_given = m->reflectivity.n > 0;
        o.attenuation_given = m->attenuation_per_m.n > 0;
        if (!o.reflectivity_given)
            o.reflectivity = 0.0;
        if (!o.attenuation_given)
            o.attenuation_per_m = 0.0;
    }
    return o;
}

brdf_frame scene_triangle_frame(const thz_object *obj, uint32_t tri, int side)
{
    const thz_mesh *m = &obj->mesh;
    vec3 n = v3_from_floats(&m->normals[3 * (size_t)tri]);
    if (side == 1)
        n = v3_scale(n, -1.0);
    const uint32_t *ix = &m->indices[3 * (size_t)tri];
    vec3 e = v3_sub(v3_from_floats(&m->positions[3 * (size_t)ix[1]]),
                    v3_from_floats(&m->positions[3 * (size_t)ix[0]]));
    e = v3_sub(e, v3_scale(n, v3_dot(e, n)));
    brdf_frame f = {.n = n};
    double len = v3_length(e);
    if (len > 0.0) {
        f.t = v3_scale(e, 1.0 / len);
        f.b = v3_cross(n, f.t);
    } else {
        v3_basis(n, &f.t, &f.b);
    }
    return f;
}

void scene_object_lobe(const thz_scene *scene, const thz_object *obj, const optics_point *o,
                       brdf_lobe *lobe)
{
    brdf_lobe_init(lobe, o, scene->materials[obj->material].ward_table);
}

bool scene_object_two_sided(const thz_object *obj)
{
    return obj->type == OBJECT_SHELL || obj->two_sided;
}

bool scene_object_side_is_front(const thz_object *obj, int side)
{
    return side == 0 || scene_object_two_sided(obj);
}

double scene_emitted_power_w_per_hz(const thz_scene *s, double freq_hz)
{
    double total = 0.0;
    for (size_t i = 0; i < s->n_objects; i++) {
        const thz_object *obj = &s->objects[i];
        if (obj->temperature_k <= 0.0 || obj->mesh.total_area_m2 <= 0.0)
            continue;
        optics_point o = scene_object_optics(s, obj, freq_hz);
        double eps_mean = optics_mean_emissivity(&o);
        total += M_PI * eps_mean * obj->mesh.total_area_m2 * (scene_object_two_sided(obj) ? 2 : 1) *
                 planck_radiance(freq_hz, obj->temperature_k);
    }
    return total;
}

static double emitted_power_at(double freq_hz, void *ctx)
{
    return scene_emitted_power_w_per_hz(ctx, freq_hz);
}

double scene_band_emitted_power_w_per_hz(const thz_scene *s, size_t channel)
{
    return channel_band_mean(&s->channels[channel], emitted_power_at, (void *)s);
}

bool mesh_finalize(thz_mesh *mesh)
{
    free(mesh->normals);
    free(mesh->areas_m2);
    mesh->normals = thz_malloc_array(mesh->n_triangles, 3 * sizeof *mesh->normals);
    mesh->areas_m2 = thz_malloc_array(mesh->n_triangles, sizeof *mesh->areas_m2);
    if (!mesh->normals || !mesh->areas_m2)
        return false;
    mesh->total_area_m2 = 0.0;
    for (int k = 0; k < 3; k++) {
        mesh->bbox_min_m[k] = mesh->n_vertices ? INFINITY : 0.0;
        mesh->bbox_max_m[k] = mesh->n_vertices ? -INFINITY : 0.0;
    }
    for (size_t v = 0; v < mesh->n_vertices; v++) {
        for (int k = 0; k < 3; k++) {
            double x = mesh->positions[3 * v + (size_t)k];
            mesh->bbox_min_m[k] = fmin(mesh->bbox_min_m[k], x);
            mesh->bbox_max_m[k] = fmax(mesh->bbox_max_m[k], x);
        }
    }
    for (size_t t = 0; t < mesh->n_triangles; t++) {
        const float *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * t + (size_t)k]];
        double e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)p[1][k] - (double)p[0][k];
            e2[k] = (double)p[2][k] - (double)p[0][k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        mesh->areas_m2[t] = 0.5 * len;
        mesh->total_area_m2 += mesh->areas_m2[t];
        for (int k = 0; k < 3; k++)
            mesh->normals[3 * t + (size_t)k] = len > 0.0 ? (float)(n[k] / len) : 0.0f;
    }
    return true;
}

double scene_reference_temperature_k(const thz_scene *scene, size_t channel)
{
    const thz_channel *ch = &scene->channels[channel];
    double best = -1.0, t0 = 0.0;
    for (size_t o = 0; o < scene->n_objects; o++) {
        const thz_object *obj = &scene->objects[o];
        optics_point op = scene_object_optics(scene, obj, ch->center_hz);
        double sides = obj->type == OBJECT_SHELL || obj->two_sided ? 2.0 : 1.0;
        double w = obj->mesh.total_area_m2 * sides * optics_mean_emissivity(&op);
        if (w > best) {
            best = w;
            t0 = obj->temperature_k;
        }
    }
    return t0;
}

/* The points of one table in (lo_hz, hi_hz), appended at out[m] when out is not NULL;
 * the new count. */
static size_t scene_knots_add(const double *freq_hz, size_t count, double lo_hz, double hi_hz,
                              double *out, size_t m)
{
    for (size_t i = 0; freq_hz && count > 1 && i < count; i++)
        if (freq_hz[i] > lo_hz && freq_hz[i] < hi_hz) {
            if (out)
                out[m] = freq_hz[i];
            m++;
        }
    return m;
}

static size_t scene_knots_collect(const thz_scene *s, double lo_hz, double hi_hz, double *out)
{
    size_t m = 0;
    for (size_t i = 0; i < s->n_materials; i++) {
        bool used = false;
        for (size_t o = 0; o < s->n_objects && !used; o++)
            used = s->objects[o].material == i;
        if (!used)
            continue;
        const thz_material *mat = &s->materials[i];
        const thz_spectrum *spectra[] = {&mat->reflectivity, &mat->attenuation_per_m,
                                         &mat->emissivity};
        for (size_t k = 0; k < sizeof spectra / sizeof spectra[0]; k++)
            m = scene_knots_add(spectra[k]->freq_hz, spectra[k]->n, lo_hz, hi_hz, out, m);
        if (mat->index) {
            const double *f;
            size_t count = material_index_table_hz(mat->index, &f);
            m = scene_knots_add(f, count, lo_hz, hi_hz, out, m);
        }
    }
    const thz_spectrum *air = &s->atmosphere.attenuation_per_m;
    if (s->atmosphere.model == ATM_TABLE)
        m = scene_knots_add(air->freq_hz, air->n, lo_hz, hi_hz, out, m);
    return m;
}

size_t scene_spectral_knots_bound(const thz_scene *scene, double lo_hz, double hi_hz)
{
    return scene_knots_collect(scene, lo_hz, hi_hz, NULL);
}

static int scene_knot_compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

thz_status scene_spectral_knots(const thz_scene *scene, double lo_hz, double hi_hz, double **knots,
                                size_t *n, thz_error *err)
{
    *knots = NULL;
    *n = 0;
    size_t count = scene_knots_collect(scene, lo_hz, hi_hz, NULL);
    if (count == 0)
        return THZ_OK;
    double *k = thz_malloc_array(count, sizeof *k);
    if (!k)
        return thz_error_set(err, THZ_ERR_NOMEM, "scene: cannot allocate %zu spectral knots",
                             count);
    scene_knots_collect(scene, lo_hz, hi_hz, k);
    qsort(k, count, sizeof *k, scene_knot_compare);
    size_t m = 1;
    for (size_t i = 1; i < count; i++)
        if (k[i] != k[m - 1])
            k[m++] = k[i];
    *knots = k;
    *n = m;
    return THZ_OK;
}
