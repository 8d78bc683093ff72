/* Hand-built scenes for the photon-phase tests: exact geometry without the JSON loader.
 * Header-only (static inline) so that each test program includes what it uses. */
#ifndef THZ_TESTS_PHOTON_SCENES_H
#define THZ_TESTS_PHOTON_SCENES_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "core/alloc.h"
#include "core/vec3.h"
#include "photon/phase.h"
#include "scene/scene.h"

/* THZ_TEST_SCALE (e.g. 0.25 under sanitizers) shrinks photon counts; tolerances are
 * derived from the counts actually used, so they widen by themselves. */
static inline double ps_test_scale(void)
{
    const char *s = getenv("THZ_TEST_SCALE");
    double x = s ? atof(s) : 1.0;
    return x > 0.0 && x <= 1.0 ? x : 1.0;
}

static inline uint64_t ps_scaled(uint64_t n)
{
    uint64_t m = (uint64_t)((double)n * ps_test_scale());
    return m < 1000 ? 1000 : m;
}

static inline void ps_check(int ok)
{
    if (!ok)
        abort();
}

/* A scene with one channel (centre in THz, relative width) and K photons. */
static inline thz_scene *ps_scene(double freq_thz, double width, uint64_t photons, uint64_t seed)
{
    thz_scene *s = scene_create();
    ps_check(s != NULL);
    s->n_channels = 1;
    s->channels = thz_calloc(1, sizeof *s->channels);
    ps_check(s->channels != NULL);
    s->channels[0].center_hz = freq_thz * 1e12;
    s->channels[0].relative_width = width;
    strcpy(s->channels[0].name, "test");
    s->photons.per_channel = photons;
    s->photons.seed = seed;
    s->name = thz_strdup("test");
    return s;
}

static inline void ps_add_channel(thz_scene *s, double freq_thz, double width)
{
    s->channels = thz_realloc_array(s->channels, s->n_channels + 1, sizeof *s->channels);
    ps_check(s->channels != NULL);
    thz_channel *c = &s->channels[s->n_channels++];
    memset(c, 0, sizeof *c);
    c->center_hz = freq_thz * 1e12;
    c->relative_width = width;
    strcpy(c->name, "extra");
}

/* A material with constant R, alpha_M and explicit eps (eps < 0: Kirchhoff). */
static inline size_t ps_material(thz_scene *s, double r, double alpha_per_m, double eps,
                                 thz_transmission mode)
{
    s->materials = thz_realloc_array(s->materials, s->n_materials + 1, sizeof *s->materials);
    ps_check(s->materials != NULL);
    thz_material *m = &s->materials[s->n_materials];
    memset(m, 0, sizeof *m);
    m->name = thz_strdup("m");
    ps_check(spectrum_set_constant(&m->reflectivity, r));
    ps_check(spectrum_set_constant(&m->attenuation_per_m, alpha_per_m));
    if (eps >= 0.0)
        ps_check(spectrum_set_constant(&m->emissivity, eps));
    m->transmission = mode;
    for (int k = 0; k < 3; k++)
        m->color[k] = 0.6;
    return s->n_materials++;
}

/* An object with an empty mesh; returns its index. */
static inline size_t ps_object(thz_scene *s, thz_object_type type, size_t material, double temp_k,
                               double thickness_m, bool two_sided)
{
    s->objects = thz_realloc_array(s->objects, s->n_objects + 1, sizeof *s->objects);
    ps_check(s->objects != NULL);
    thz_object *o = &s->objects[s->n_objects];
    memset(o, 0, sizeof *o);
    o->name = thz_strdup("o");
    o->type = type;
    o->material = material;
    o->temperature_k = temp_k;
    o->thickness_m = type == OBJECT_SHELL ? thickness_m : 0.0;
    o->two_sided = type == OBJECT_SHELL ? true : two_sided;
    return s->n_objects++;
}

/* Appends the quad p0 p1 p2 p3 (counter-clockwise seen from its front side, whose
 * normal is along (p1 - p0) x (p2 - p0)) as two triangles. */
static inline void ps_quad(thz_scene *s, size_t object, vec3 p0, vec3 p1, vec3 p2, vec3 p3)
{
    thz_mesh *m = &s->objects[object].mesh;
    size_t nv = m->n_vertices;
    m->positions = thz_realloc_array(m->positions, 3 * (nv + 4) + 4, sizeof(float));
    m->indices = thz_realloc_array(m->indices, 3 * (m->n_triangles + 2), sizeof(uint32_t));
    ps_check(m->positions && m->indices);
    vec3 p[4] = {p0, p1, p2, p3};
    for (int i = 0; i < 4; i++) {
        m->positions[3 * (nv + (size_t)i) + 0] = (float)p[i].x;
        m->positions[3 * (nv + (size_t)i) + 1] = (float)p[i].y;
        m->positions[3 * (nv + (size_t)i) + 2] = (float)p[i].z;
    }
    for (int k = 0; k < 4; k++)
        m->positions[3 * (nv + 4) + (size_t)k] = 0.0f; /* Embree's padding */
    uint32_t base = (uint32_t)nv;
    uint32_t idx[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
    memcpy(&m->indices[3 * m->n_triangles], idx, sizeof idx);
    m->n_vertices += 4;
    m->n_triangles += 2;
}

/* An axis-aligned rectangle face centred at c with half-axes u, v; its normal is along
 * u x v. */
static inline void ps_face(thz_scene *s, size_t object, vec3 c, vec3 u, vec3 v)
{
    ps_quad(s, object, v3_sub(v3_sub(c, u), v), v3_sub(v3_add(c, u), v), v3_add(v3_add(c, u), v),
            v3_add(v3_sub(c, u), v));
}

/* The six faces of the box [lo, hi], normals outward (or inward). */
static inline void ps_box(thz_scene *s, size_t object, vec3 lo, vec3 hi, bool inward)
{
    vec3 c = v3_scale(v3_add(lo, hi), 0.5);
    vec3 h = v3_scale(v3_sub(hi, lo), 0.5);
    double sg = inward ? -1.0 : 1.0;
    vec3 ex = v3(h.x, 0, 0), ey = v3(0, h.y, 0), ez = v3(0, 0, h.z);
    ps_face(s, object, v3_add(c, ex), ey, v3_scale(ez, sg)); /* +x */
    ps_face(s, object, v3_sub(c, ex), ez, v3_scale(ey, sg)); /* -x */
    ps_face(s, object, v3_add(c, ey), ez, v3_scale(ex, sg)); /* +y */
    ps_face(s, object, v3_sub(c, ey), ex, v3_scale(ez, sg)); /* -y */
    ps_face(s, object, v3_add(c, ez), ex, v3_scale(ey, sg)); /* +z */
    ps_face(s, object, v3_sub(c, ez), ey, v3_scale(ex, sg)); /* -z */
}

static inline void ps_finalize(thz_scene *s)
{
    for (size_t i = 0; i < s->n_objects; i++)
        ps_check(mesh_finalize(&s->objects[i].mesh));
}

/* Channel 0's photon phase of s with options opt (NULL: the defaults), its accel built and
 * freed here: the map into *map, the statistics into *st. A failure aborts the test
 * program, its message on stderr. */
static inline void ps_fire(const thz_scene *s, const photon_phase_options *opt, photon_map **map,
                           photon_stats *st)
{
    accel *acc;
    thz_error err;
    thz_status status = accel_create(s, &acc, &err);
    if (status == THZ_OK) {
        status = photon_phase_run(s, acc, 0, opt, map, st, &err);
        accel_destroy(acc);
    }
    if (status != THZ_OK) {
        fprintf(stderr, "photon phase: %s\n", err.message);
        abort();
    }
}

/* A "box scene" with every kind of surface: a 2 x 2 x 2.5 m room (inward, R = 0.3,
 * 295 K), a solid cube (R = 0.1, 310 K), a diffuse shell (R = 0.05, alpha 200/m, 1 mm,
 * 300 K), a straight shell (R = 0.1, alpha 100/m, 2 mm, 290 K), a one-sided plate whose
 * back faces are visible (R = 0.2, 320 K), a cold (0 K) two-sided plate, and an
 * atmosphere of constant alpha = atm_per_m (none when 0). */
static inline thz_scene *ps_box_scene(uint64_t photons, uint64_t seed, double atm_per_m)
{
    thz_scene *s = ps_scene(0.35, 0.02, photons, seed);
    size_t wall = ps_material(s, 0.3, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t paint = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t cloth = ps_material(s, 0.05, 200.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t film = ps_material(s, 0.1, 100.0, -1.0, TRANSMISSION_STRAIGHT);
    size_t metal = ps_material(s, 0.2, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, wall, 295, 0, false);
    ps_box(s, room, v3(-1, -1, 0), v3(1, 1, 2.5), true);
    size_t cube = ps_object(s, OBJECT_SOLID, paint, 310, 0, false);
    ps_box(s, cube, v3(-0.3, -0.3, 0.05), v3(0.3, 0.3, 0.6), false);
    size_t shell = ps_object(s, OBJECT_SHELL, cloth, 300, 1e-3, true);
    ps_box(s, shell, v3(-0.4, -0.4, 0.02), v3(0.4, 0.4, 0.8), false);
    size_t straight = ps_object(s, OBJECT_SHELL, film, 290, 2e-3, true);
    ps_face(s, straight, v3(0, 0.8, 1.2), v3(0.5, 0, 0), v3(0, 0, 0.5));
    size_t plate = ps_object(s, OBJECT_SOLID, metal, 320, 0, false);
    ps_face(s, plate, v3(0.6, -0.6, 1.8), v3(0.2, 0, 0), v3(0, 0.2, 0));
    size_t cold = ps_object(s, OBJECT_SOLID, metal, 0, 0, true);
    ps_face(s, cold, v3(-0.6, 0.6, 2.0), v3(0.2, 0, 0), v3(0, 0.2, 0));
    if (atm_per_m > 0.0) {
        s->atmosphere.model = ATM_CONSTANT;
        ps_check(spectrum_set_constant(&s->atmosphere.attenuation_per_m, atm_per_m));
    }
    ps_finalize(s);
    return s;
}

#endif
