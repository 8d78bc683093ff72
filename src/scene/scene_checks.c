/* Plausibility checks of a loaded scene (scene_checks.h). */
#include "scene/scene_checks.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/order.h"
#include "core/vec3.h"

/* Per object: closed, signed volume (m^3; < 0: inward normals), bbox diagonal (m). */
struct check_object {
    bool closed;
    double volume_m3;
    double diagonal_m;
};

static vec3 check_vertex(const thz_mesh *m, uint32_t v)
{
    const float *p = &m->positions[3 * (size_t)v];
    return v3(p[0], p[1], p[2]);
}

/* ---- closedness ----------------------------------------------------------------- */

typedef struct check_vkey {
    float p[3];
    uint32_t index;
} check_vkey;

static int check_vkey_cmp(const void *a, const void *b)
{
    const check_vkey *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->p[k] != y->p[k])
            return x->p[k] < y->p[k] ? -1 : 1;
    return 0;
}

/* Whether every edge, its ends welded by position, is shared by exactly two triangles
 * that run it in opposite directions (closed and consistently wound, so that the signed
 * volume tells outward from inward). -1 on allocation failure. */
static int check_mesh_closed(const thz_mesh *m)
{
    size_t nv = m->n_vertices, ne = 3 * m->n_triangles;
    check_vkey *keys = thz_malloc_array(nv ? nv : 1, sizeof *keys);
    uint32_t *weld = thz_malloc_array(nv ? nv : 1, sizeof *weld);
    /* every edge by its welded ends (lower index first), and apart those that a triangle
     * runs the other way round: closed when every edge comes twice and once reversed */
    uint64_t *edges = thz_malloc_array(ne ? ne : 1, sizeof *edges);
    uint64_t *reversed = thz_malloc_array(ne ? ne : 1, sizeof *reversed);
    int closed = -1;
    if (!keys || !weld || !edges || !reversed)
        goto cleanup;
    /* written whole (edges but for degenerate triangles' 3): map their pages at once */
    thz_populate(keys, nv * sizeof *keys);
    thz_populate(weld, nv * sizeof *weld);
    thz_populate(edges, ne * sizeof *edges);
    for (size_t v = 0; v < nv; v++) {
        memcpy(keys[v].p, &m->positions[3 * v], sizeof keys[v].p);
        keys[v].index = (uint32_t)v;
    }
    qsort(keys, nv, sizeof *keys, check_vkey_cmp);
    for (size_t v = 0; v < nv; v++) /* every vertex maps to the first of its position */
        weld[keys[v].index] = v > 0 && check_vkey_cmp(&keys[v], &keys[v - 1]) == 0
                                  ? weld[keys[v - 1].index]
                                  : keys[v].index;
    size_t n = 0, nr = 0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        if (!(m->areas_m2[t] > 0.0))
            continue; /* degenerate triangles neither open nor close a mesh */
        for (int k = 0; k < 3; k++) {
            uint64_t a = weld[m->indices[3 * t + (size_t)k]];
            uint64_t b = weld[m->indices[3 * t + (size_t)(k + 1) % 3]];
            uint64_t key = a < b ? a << 32 | b : b << 32 | a;
            edges[n++] = key;
            if (a > b)
                reversed[nr++] = key;
        }
    }
    order_sort_u64(edges, n);
    order_sort_u64(reversed, nr);
    closed = n > 0 && 2 * nr == n;
    for (size_t i = 0; i < nr && closed; i++)
        closed = edges[2 * i] == reversed[i] && edges[2 * i + 1] == reversed[i] &&
                 (2 * i + 2 >= n || edges[2 * i + 2] != reversed[i]);
cleanup:
    free(keys);
    free(weld);
    free(edges);
    free(reversed);
    return closed;
}

static double check_signed_volume_m3(const thz_mesh *m)
{
    double v = 0.0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        const uint32_t *i = &m->indices[3 * t];
        vec3 a = check_vertex(m, i[0]), b = check_vertex(m, i[1]), c = check_vertex(m, i[2]);
        v += v3_dot(a, v3_cross(b, c)) / 6.0;
    }
    return v;
}

/* Whether p is inside closed mesh m: crossings of a ray from p in a fixed, oblique
 * direction (unlikely to graze an edge of an axis-aligned shape), counted by parity. */
static bool check_inside(const thz_mesh *m, const double p_m[3])
{
    vec3 o = v3_from_array(p_m), d = v3_normalize(v3(0.5417, 0.6139, 0.5741));
    for (int k = 0; k < 3; k++)
        if (p_m[k] < m->bbox_min_m[k] || p_m[k] > m->bbox_max_m[k])
            return false;
    unsigned crossings = 0;
    for (size_t t = 0; t < m->n_triangles; t++) { /* Moller-Trumbore */
        const uint32_t *i = &m->indices[3 * t];
        vec3 a = check_vertex(m, i[0]), b = check_vertex(m, i[1]), c = check_vertex(m, i[2]);
        vec3 e1 = v3_sub(b, a), e2 = v3_sub(c, a), q = v3_cross(d, e2);
        double det = v3_dot(e1, q);
        if (fabs(det) < 1e-300)
            continue;
        vec3 s = v3_sub(o, a);
        double u = v3_dot(s, q) / det;
        if (u < 0.0 || u > 1.0)
            continue;
        vec3 r = v3_cross(s, e1);
        double v = v3_dot(d, r) / det;
        if (v < 0.0 || u + v > 1.0)
            continue;
        if (v3_dot(e2, r) / det > 0.0)
            crossings++;
    }
    return crossings % 2 == 1;
}

check_object *scene_checks_objects(const thz_scene *s)
{
    check_object *info = thz_calloc(s->n_objects ? s->n_objects : 1, sizeof *info);
    for (size_t i = 0; info && i < s->n_objects; i++) {
        const thz_mesh *m = &s->objects[i].mesh;
        int closed = check_mesh_closed(m);
        if (closed < 0) {
            free(info);
            return NULL;
        }
        info[i].closed = closed == 1;
        info[i].volume_m3 = check_signed_volume_m3(m);
        double d2 = 0.0;
        for (int k = 0; k < 3; k++)
            d2 += (m->bbox_max_m[k] - m->bbox_min_m[k]) * (m->bbox_max_m[k] - m->bbox_min_m[k]);
        info[i].diagonal_m = sqrt(d2);
    }
    return info;
}

static bool check_is_enclosure(const check_object *o)
{
    return o->closed && o->volume_m3 < 0.0;
}

size_t scene_checks_enclosure(const thz_scene *s, const check_object *info)
{
    size_t best = SIZE_MAX;
    for (size_t i = 0; i < s->n_objects; i++) {
        if (!check_is_enclosure(&info[i]))
            continue;
        bool all = true;
        for (size_t k = 0; k < s->n_sensors && all; k++)
            all = check_inside(&s->objects[i].mesh, s->sensors[k].position_m);
        if (all && (best == SIZE_MAX || -info[i].volume_m3 < -info[best].volume_m3))
            best = i;
    }
    return best;
}

/* ---- the checks ----------------------------------------------------------------- */

/* Temperatures in degrees Celsius: most objects between 5 and 60 "K" and none hotter
 * than 100 K (a cryogenic scene has its warm parts, a room in Celsius has none). */
static bool check_celsius(thz_scene *s)
{
    size_t low = 0, first = SIZE_MAX;
    double hottest = 0.0;
    for (size_t i = 0; i < s->n_objects; i++) {
        double t = s->objects[i].temperature_k;
        hottest = fmax(hottest, t);
        if (t >= 5.0 && t <= 60.0) {
            low++;
            if (first == SIZE_MAX)
                first = i;
        }
    }
    if (hottest > 100.0 || 2 * low < s->n_objects || first == SIZE_MAX)
        return true;
    const thz_object *o = &s->objects[first];
    return scene_add_warning(
        s,
        "%zu of %zu objects have temperatures between 5 and 60 K and none is above 100 K (object "
        "\"%s\": temperature_k %g K): these look like degrees Celsius; temperature_k is in "
        "kelvin (%g degC = %.2f K)",
        low, s->n_objects, o->name, o->temperature_k, o->temperature_k, o->temperature_k + 273.15);
}

static int check_double_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Objects SCENE_CHECK_ENCLOSURE_RATIO times larger than the enclosure around the sensors
 * (other enclosures, such as a hall around a booth, SCENE_CHECK_SCALE_RATIO times), or
 * SCENE_CHECK_SCALE_RATIO times the median object. */
static bool check_scales(thz_scene *s, const check_object *info, size_t enclosure)
{
    double ref = 0.0;
    const char *ref_what = "the median object";
    if (enclosure != SIZE_MAX) {
        ref = info[enclosure].diagonal_m;
        ref_what = "the enclosure";
    } else if (s->n_objects >= 2) {
        double *d = thz_malloc_array(s->n_objects, sizeof *d);
        if (!d)
            return false;
        for (size_t i = 0; i < s->n_objects; i++)
            d[i] = info[i].diagonal_m;
        qsort(d, s->n_objects, sizeof *d, check_double_cmp);
        ref = d[(s->n_objects - 1) / 2];
        free(d);
    }
    bool ok = true;
    for (size_t i = 0; i < s->n_objects && ok && ref > 0.0; i++) {
        double ratio = enclosure != SIZE_MAX && !check_is_enclosure(&info[i])
                           ? SCENE_CHECK_ENCLOSURE_RATIO
                           : SCENE_CHECK_SCALE_RATIO;
        if (!(info[i].diagonal_m > ratio * ref))
            continue;
        const char *ref_name = enclosure != SIZE_MAX ? s->objects[enclosure].name : "";
        ok = scene_add_warning(
            s,
            "object \"%s\" is %.3g m across, %.0f times %s%s%s%s (%.3g m): the scene's scales "
            "differ by orders of magnitude; is a mesh or a size in millimetres (coordinates "
            "and sizes are in metres; for a mesh \"transform\": {\"scale\": 0.001} converts)?",
            s->objects[i].name, info[i].diagonal_m, info[i].diagonal_m / ref, ref_what,
            ref_name[0] ? " \"" : "", ref_name, ref_name[0] ? "\"" : "", ref);
    }
    return ok;
}

/* A scene far from the origin for its size: its coordinates' single-precision step (in
 * which meshes and Embree's rays are held) above SCENE_CHECK_PRECISION of its bounding
 * box's diagonal. */
static bool check_precision(thz_scene *s)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double far = 0.0;
    for (size_t i = 0; i < s->n_objects; i++) {
        const thz_mesh *m = &s->objects[i].mesh;
        for (int k = 0; k < 3 && m->n_triangles; k++) {
            lo[k] = fmin(lo[k], m->bbox_min_m[k]);
            hi[k] = fmax(hi[k], m->bbox_max_m[k]);
            far = fmax(far, fmax(fabs(m->bbox_min_m[k]), fabs(m->bbox_max_m[k])));
        }
    }
    if (!(lo[0] <= hi[0]))
        return true;
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double step = FLT_EPSILON * far;
    if (!(step > SCENE_CHECK_PRECISION * diag))
        return true;
    return scene_add_warning(
        s,
        "the objects lie up to %.3g m from the origin, %.0f times the scene's size (%.3g m "
        "across): single precision, in which meshes and rays are held, resolves %.2g m "
        "there, and a ray leaving a surface near an edge may start outside it (a closed "
        "room 10 m across at 300 K, 3 km from the origin, read a pixel 2.4 K low in 2 of "
        "16 seeds); place the scene around the origin",
        far, far / diag, diag, step);
}

static bool check_frequencies(thz_scene *s)
{
    size_t outside = 0, first = 0;
    for (size_t c = 0; c < s->n_channels; c++) {
        /* in Hz, as the loader made it: hz * 1e-12 puts 0.05 THz just below 0.05 */
        double hz = s->channels[c].center_hz;
        if (hz < SCENE_CHECK_MIN_THZ * 1e12 || hz > SCENE_CHECK_MAX_THZ * 1e12) {
            if (outside++ == 0)
                first = c;
        }
    }
    if (outside == 0)
        return true;
    const thz_channel *ch = &s->channels[first];
    return scene_add_warning(s,
                             "channel \"%s\" at %g THz%s is outside %g to %g THz, the range "
                             "thzmap's models are meant for: frequency_thz is in THz (%g GHz "
                             "= %g THz)",
                             ch->name, ch->center_hz * 1e-12, outside > 1 ? " and others" : "",
                             SCENE_CHECK_MIN_THZ, SCENE_CHECK_MAX_THZ, ch->center_hz * 1e-12,
                             ch->center_hz * 1e-15);
}

void scene_checks_ghz_hint(const thz_scene *s, char *buf, size_t size)
{
    if (size)
        buf[0] = '\0';
    for (size_t c = 0; c < s->n_channels; c++) {
        const thz_channel *ch = &s->channels[c];
        if (ch->center_hz > SCENE_CHECK_MAX_THZ * 1e12) {
            snprintf(buf, size,
                     "; channel \"%s\" is at %g THz, beyond the %g to %g THz thzmap's models are "
                     "meant for: frequency_thz is in THz (%g GHz = %g THz)",
                     ch->name, ch->center_hz * 1e-12, SCENE_CHECK_MIN_THZ, SCENE_CHECK_MAX_THZ,
                     ch->center_hz * 1e-12, ch->center_hz * 1e-15);
            return;
        }
    }
}

void scene_checks_ghz_table_hint(double table_lo_hz, double centre_hz, char *buf, size_t size)
{
    if (size)
        buf[0] = '\0';
    if (table_lo_hz > SCENE_CHECK_MAX_THZ * 1e12 && centre_hz <= SCENE_CHECK_MAX_THZ * 1e12)
        snprintf(buf, size,
                 " (a table beyond %g THz: are its frequencies in GHz? frequency_thz is in THz, "
                 "%.4g GHz = %.4g THz)",
                 SCENE_CHECK_MAX_THZ, table_lo_hz * 1e-12, table_lo_hz * 1e-15);
}

/* A sensor inside a closed solid, or outside every enclosure while the scene has one. */
static bool check_sensors(thz_scene *s, const check_object *info)
{
    size_t any_enclosure = SIZE_MAX;
    for (size_t i = 0; i < s->n_objects; i++)
        if (check_is_enclosure(&info[i]) &&
            (any_enclosure == SIZE_MAX || -info[i].volume_m3 > -info[any_enclosure].volume_m3))
            any_enclosure = i;
    bool ok = true;
    for (size_t k = 0; k < s->n_sensors && ok; k++) {
        thz_sensor *sn = &s->sensors[k];
        const double *p = sn->position_m;
        bool enclosed = false;
        for (size_t i = 0; i < s->n_objects && ok; i++) {
            if (!info[i].closed)
                continue;
            bool inside = check_inside(&s->objects[i].mesh, p);
            if (check_is_enclosure(&info[i])) {
                enclosed = enclosed || inside;
            } else if (inside) {
                sn->misplaced = true;
                ok = scene_add_warning(
                    s,
                    "sensor \"%s\" at [%g, %g, %g] m is inside object \"%s\" (a closed solid): "
                    "it sees that object from inside; move the sensor out of it, or, if it is "
                    "meant as the room around the sensor, turn its normals inwards (\"inward\": "
                    "true on a box; a mesh's faces listed clockwise seen from outside)",
                    sn->name, p[0], p[1], p[2], s->objects[i].name);
            }
        }
        if (ok && !enclosed && any_enclosure != SIZE_MAX) {
            sn->misplaced = true;
            ok = scene_add_warning(s,
                                   "sensor \"%s\" at [%g, %g, %g] m is outside the enclosure "
                                   "\"%s\" (a closed object with inward normals): it sees the "
                                   "enclosure from outside; move the sensor into it, or, if it "
                                   "is a solid seen from outside, turn its normals outwards "
                                   "(no \"inward\": true; a mesh's faces listed "
                                   "counter-clockwise seen from outside)",
                                   sn->name, p[0], p[1], p[2], s->objects[any_enclosure].name);
        }
    }
    return ok;
}

/* Whether some sensor is inside closed mesh i. */
static bool check_holds_sensor(const thz_scene *s, size_t i)
{
    for (size_t k = 0; k < s->n_sensors; k++)
        if (check_inside(&s->objects[i].mesh, s->sensors[k].position_m))
            return true;
    return false;
}

/* Whether the bounding boxes of meshes a and b are apart (share no point). */
static bool check_apart(const thz_mesh *a, const thz_mesh *b)
{
    bool apart = false;
    for (int k = 0; k < 3; k++)
        apart = apart || a->bbox_min_m[k] > b->bbox_max_m[k] || a->bbox_max_m[k] < b->bbox_min_m[k];
    return apart;
}

/* A closed object with inward normals, in the enclosure around the sensors but holding
 * none of them: a solid whose mesh is wound the wrong way round, seen from outside. (An
 * annex beside that enclosure, which no sensor sees, is no mistake; without an enclosure
 * around the sensors check_sensors says they are outside one.) */
static bool check_inverted(thz_scene *s, const check_object *info, size_t enclosure)
{
    if (enclosure == SIZE_MAX)
        return true;
    const thz_mesh *e = &s->objects[enclosure].mesh;
    bool ok = true;
    for (size_t i = 0; i < s->n_objects && ok; i++)
        if (i != enclosure && check_is_enclosure(&info[i]) &&
            !check_apart(&s->objects[i].mesh, e) && !check_holds_sensor(s, i))
            ok = scene_add_warning(
                s,
                "object \"%s\" is closed with its normals pointing inwards, as a room's, but no "
                "sensor is inside it: seen from outside it shows only its back faces (radiance "
                "0, counted in summary.json's back_face_samples); a solid's normals point "
                "outwards (no \"inward\": true; a mesh's faces listed counter-clockwise seen "
                "from outside)",
                s->objects[i].name);
    return ok;
}

/* An object wholly outside the enclosure around the sensors (their bounding boxes apart):
 * no sensor sees it and none of its radiation reaches them; most often a coordinate in
 * centimetres or millimetres. */
static bool check_outside(thz_scene *s, const check_object *info, size_t enclosure)
{
    if (enclosure == SIZE_MAX)
        return true;
    const thz_mesh *e = &s->objects[enclosure].mesh;
    bool ok = true;
    for (size_t i = 0; i < s->n_objects && ok; i++) {
        const thz_mesh *m = &s->objects[i].mesh;
        if (i == enclosure || check_is_enclosure(&info[i]) || !m->n_triangles || !check_apart(m, e))
            continue;
        ok = scene_add_warning(
            s,
            "object \"%s\" (bounds [%g, %g, %g] to [%g, %g, %g] m) lies wholly outside \"%s\", "
            "the enclosure around the sensors ([%g, %g, %g] to [%g, %g, %g] m): no sensor sees "
            "it; are its coordinates in metres?",
            s->objects[i].name, m->bbox_min_m[0], m->bbox_min_m[1], m->bbox_min_m[2],
            m->bbox_max_m[0], m->bbox_max_m[1], m->bbox_max_m[2], s->objects[enclosure].name,
            e->bbox_min_m[0], e->bbox_min_m[1], e->bbox_min_m[2], e->bbox_max_m[0],
            e->bbox_max_m[1], e->bbox_max_m[2]);
    }
    return ok;
}

static bool check_atmosphere(thz_scene *s, const scene_check_inputs *in, size_t enclosure)
{
    bool ok = true;
    if (in->non_emitting_air && s->atmosphere.model != ATM_NONE)
        ok = scene_add_warning(s, "atmosphere: \"emitting\": false makes the air absorb without "
                                  "emitting (the paper's assumption, not physics): this breaks "
                                  "equilibrium, so a closed room no longer reads its own "
                                  "temperature; leave \"emitting\" out for air that emits");
    if (ok && in->background_given && enclosure != SIZE_MAX)
        ok = scene_add_warning(s,
                               "atmosphere.background_temperature_k is given but every sensor "
                               "is inside the closed object \"%s\": no ray leaves the scene, "
                               "so it has no effect",
                               s->objects[enclosure].name);
    return ok;
}

bool scene_checks_run(thz_scene *scene, const check_object *info, size_t enclosure,
                      const scene_check_inputs *in)
{
    return check_celsius(scene) && check_scales(scene, info, enclosure) && check_precision(scene) &&
           check_frequencies(scene) && check_sensors(scene, info) &&
           check_inverted(scene, info, enclosure) && check_outside(scene, info, enclosure) &&
           check_atmosphere(scene, in, enclosure);
}
