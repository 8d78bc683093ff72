/* Tessellation of the analytic shapes into triangle meshes. */
#include "scene/primitives.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

thz_status primitive_mesh_alloc(thz_mesh *mesh, size_t n_vertices, size_t n_triangles,
                                thz_error *err)
{
    memset(mesh, 0, sizeof *mesh);
    if (n_vertices > UINT32_MAX || n_vertices > (SIZE_MAX - 4) / 3)
        return thz_error_set(err, THZ_ERR_LIMIT, "mesh of %zu vertices is too large", n_vertices);
    mesh->positions = thz_malloc_array(3 * n_vertices + 4, sizeof *mesh->positions);
    mesh->indices = thz_malloc_array(n_triangles, 3 * sizeof *mesh->indices);
    if (!mesh->positions || !mesh->indices) {
        mesh_fini(mesh);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a mesh of %zu triangles",
                             n_triangles);
    }
    memset(&mesh->positions[3 * n_vertices], 0, 4 * sizeof *mesh->positions);
    mesh->n_vertices = n_vertices;
    mesh->n_triangles = n_triangles;
    return THZ_OK;
}

float primitive_to_float(double x)
{
    return fabs(x) <= FLT_MAX ? (float)x : (float)copysign(INFINITY, x);
}

static void primitive_set_vertex(thz_mesh *m, size_t v, double x, double y, double z)
{
    m->positions[3 * v] = primitive_to_float(x);
    m->positions[3 * v + 1] = primitive_to_float(y);
    m->positions[3 * v + 2] = primitive_to_float(z);
}

static void primitive_set_triangle(thz_mesh *m, size_t t, size_t a, size_t b, size_t c)
{
    m->indices[3 * t] = (uint32_t)a;
    m->indices[3 * t + 1] = (uint32_t)b;
    m->indices[3 * t + 2] = (uint32_t)c;
}

thz_status primitive_box(thz_mesh *mesh, const double size_m[3], bool inward, thz_error *err)
{
    thz_status st = primitive_mesh_alloc(mesh, 8, 12, err);
    if (st != THZ_OK)
        return st;
    /* vertex v has coordinate bits (x: bit 0, y: bit 1, z: bit 2), 1 = positive side */
    for (size_t v = 0; v < 8; v++)
        primitive_set_vertex(mesh, v, (v & 1 ? 0.5 : -0.5) * size_m[0],
                             (v & 2 ? 0.5 : -0.5) * size_m[1], (v & 4 ? 0.5 : -0.5) * size_m[2]);
    /* each face as a quad a b c d, counter-clockwise seen from outside, with a -> b along
     * x (the faces normal to x: along y), the direction of Ward's tangent there */
    static const size_t faces[6][4] = {
        {1, 0, 2, 3}, /* -z */
        {4, 5, 7, 6}, /* +z */
        {0, 1, 5, 4}, /* -y */
        {3, 2, 6, 7}, /* +y */
        {2, 0, 4, 6}, /* -x */
        {1, 3, 7, 5}, /* +x */
    };
    /* Both triangles of a face start on a side parallel to a -> b (the tangent is a
     * triangle's first edge; on the diagonal, half of each face was brushed across it) */
    for (size_t f = 0; f < 6; f++) {
        const size_t *q = faces[f];
        if (inward) {
            primitive_set_triangle(mesh, 2 * f, q[1], q[0], q[2]);
            primitive_set_triangle(mesh, 2 * f + 1, q[3], q[2], q[0]);
        } else {
            primitive_set_triangle(mesh, 2 * f, q[0], q[1], q[2]);
            primitive_set_triangle(mesh, 2 * f + 1, q[2], q[3], q[0]);
        }
    }
    return THZ_OK;
}

thz_status primitive_cylinder(thz_mesh *mesh, double radius_m, double height_m, bool caps,
                              unsigned segments, thz_error *err)
{
    size_t n = segments;
    /* ring vertices: bottom 0..n-1, top n..2n-1; cap centres 2n (bottom), 2n+1 (top) */
    size_t nv = 2 * n + (caps ? 2 : 0);
    size_t nt = 2 * n + (caps ? 2 * n : 0);
    thz_status st = primitive_mesh_alloc(mesh, nv, nt, err);
    if (st != THZ_OK)
        return st;
    for (size_t i = 0; i < n; i++) {
        double a = 2.0 * M_PI * (double)i / (double)n;
        double x = radius_m * cos(a), y = radius_m * sin(a);
        primitive_set_vertex(mesh, i, x, y, 0.0);
        primitive_set_vertex(mesh, n + i, x, y, height_m);
    }
    size_t t = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        /* both start along the circumference (Ward's tangent) */
        primitive_set_triangle(mesh, t++, i, j, n + j);
        primitive_set_triangle(mesh, t++, n + j, n + i, i);
    }
    if (caps) {
        size_t cb = 2 * n, ct = 2 * n + 1;
        primitive_set_vertex(mesh, cb, 0.0, 0.0, 0.0);
        primitive_set_vertex(mesh, ct, 0.0, 0.0, height_m);
        for (size_t i = 0; i < n; i++) {
            size_t j = (i + 1) % n;
            primitive_set_triangle(mesh, t++, cb, j, i);         /* faces -z */
            primitive_set_triangle(mesh, t++, ct, n + i, n + j); /* faces +z */
        }
    }
    return THZ_OK;
}

thz_status primitive_rectangle(thz_mesh *mesh, const double size_m[2], thz_error *err)
{
    thz_status st = primitive_mesh_alloc(mesh, 4, 2, err);
    if (st != THZ_OK)
        return st;
    double hx = 0.5 * size_m[0], hy = 0.5 * size_m[1];
    primitive_set_vertex(mesh, 0, -hx, -hy, 0.0);
    primitive_set_vertex(mesh, 1, hx, -hy, 0.0);
    primitive_set_vertex(mesh, 2, hx, hy, 0.0);
    primitive_set_vertex(mesh, 3, -hx, hy, 0.0);
    primitive_set_triangle(mesh, 0, 0, 1, 2); /* both start along x (Ward's tangent) */
    primitive_set_triangle(mesh, 1, 2, 3, 0);
    return THZ_OK;
}

thz_status primitive_disk(thz_mesh *mesh, double radius_m, unsigned segments, thz_error *err)
{
    size_t n = segments;
    thz_status st = primitive_mesh_alloc(mesh, n + 1, n, err);
    if (st != THZ_OK)
        return st;
    primitive_set_vertex(mesh, n, 0.0, 0.0, 0.0);
    for (size_t i = 0; i < n; i++) {
        double a = 2.0 * M_PI * (double)i / (double)n;
        primitive_set_vertex(mesh, i, radius_m * cos(a), radius_m * sin(a), 0.0);
        primitive_set_triangle(mesh, i, n, i, (i + 1) % n);
    }
    return THZ_OK;
}

/* Icosphere. Subdivision splits each edge at its midpoint; the midpoint vertex of an
 * edge is shared by the two triangles that use it, found through a table keyed by
 * the edge's smaller vertex (each vertex has at most 6 neighbours after the first
 * level, 5 on the icosahedron), so the result stays a closed, consistently wound
 * surface. Positions are kept in double until the end. */
typedef struct sphere_edge_slot {
    uint32_t other; /* the larger vertex of the edge; UINT32_MAX: empty */
    uint32_t mid;
} sphere_edge_slot;

#define SPHERE_SLOTS 6

static uint32_t sphere_midpoint(double *pos, size_t *nv, sphere_edge_slot *slots, uint32_t a,
                                uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    sphere_edge_slot *s = &slots[(size_t)lo * SPHERE_SLOTS];
    int k = 0;
    for (; k < SPHERE_SLOTS && s[k].other != UINT32_MAX; k++)
        if (s[k].other == hi)
            return s[k].mid;
    /* k < SPHERE_SLOTS: a vertex has at most 6 edges on a subdivided icosahedron */
    uint32_t m = (uint32_t)*nv;
    double p[3];
    for (int i = 0; i < 3; i++)
        p[i] = 0.5 * (pos[3 * (size_t)a + (size_t)i] + pos[3 * (size_t)b + (size_t)i]);
    double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int i = 0; i < 3; i++)
        pos[3 * (size_t)m + (size_t)i] = p[i] / len;
    (*nv)++;
    s[k].other = hi;
    s[k].mid = m;
    return m;
}

thz_status primitive_sphere(thz_mesh *mesh, double radius_m, unsigned subdivisions, thz_error *err)
{
    thz_status st = THZ_OK;
    double *pos = NULL;
    uint32_t *tri = NULL, *next = NULL;
    sphere_edge_slot *slots = NULL;
    if (subdivisions > PRIMITIVE_MAX_SUBDIVISIONS)
        return thz_error_set(err, THZ_ERR_LIMIT, "sphere subdivisions %u exceed %u", subdivisions,
                             PRIMITIVE_MAX_SUBDIVISIONS);
    size_t max_t = (size_t)20 << (2 * subdivisions);
    size_t max_v = max_t / 2 + 2; /* Euler: V = F/2 + 2 for a closed triangulated sphere */
    pos = thz_malloc_array(max_v, 3 * sizeof *pos);
    tri = thz_malloc_array(max_t, 3 * sizeof *tri);
    next = thz_malloc_array(max_t, 3 * sizeof *next);
    slots = thz_malloc_array(max_v, SPHERE_SLOTS * sizeof *slots);
    if (!pos || !tri || !next || !slots) {
        st =
            thz_error_set(err, THZ_ERR_NOMEM, "out of memory for a sphere of %zu triangles", max_t);
        goto cleanup;
    }
    const double g = (1.0 + sqrt(5.0)) / 2.0;
    const double ico_v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                 {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                 {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    static const uint32_t ico_t[20][3] = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    size_t nv = 12, nt = 20;
    for (size_t v = 0; v < 12; v++) {
        double len = sqrt(1.0 + g * g);
        for (int i = 0; i < 3; i++)
            pos[3 * v + (size_t)i] = ico_v[v][i] / len;
    }
    memcpy(tri, ico_t, sizeof ico_t);
    for (unsigned level = 0; level < subdivisions; level++) {
        for (size_t i = 0; i < nv * SPHERE_SLOTS; i++) /* midpoints key on older vertices */
            slots[i].other = UINT32_MAX;
        size_t nt2 = 0;
        for (size_t t = 0; t < nt; t++) {
            uint32_t a = tri[3 * t], b = tri[3 * t + 1], c = tri[3 * t + 2];
            uint32_t ab = sphere_midpoint(pos, &nv, slots, a, b);
            uint32_t bc = sphere_midpoint(pos, &nv, slots, b, c);
            uint32_t ca = sphere_midpoint(pos, &nv, slots, c, a);
            const uint32_t quad[4][3] = {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}};
            memcpy(&next[3 * nt2], quad, sizeof quad);
            nt2 += 4;
        }
        uint32_t *swap = tri;
        tri = next;
        next = swap;
        nt = nt2;
    }
    st = primitive_mesh_alloc(mesh, nv, nt, err);
    if (st != THZ_OK)
        goto cleanup;
    for (size_t v = 0; v < nv; v++)
        primitive_set_vertex(mesh, v, radius_m * pos[3 * v], radius_m * pos[3 * v + 1],
                             radius_m * pos[3 * v + 2]);
    memcpy(mesh->indices, tri, nt * 3 * sizeof *tri);
cleanup:
    free(pos);
    free(tri);
    free(next);
    free(slots);
    return st;
}
