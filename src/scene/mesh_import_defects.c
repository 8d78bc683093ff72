/* The defects of an imported mesh (mesh_import.h; load.c warns of each): repeated
 * triangles, triangles of no area, edges that two triangles run the same way (the
 * winding check) and edges of one triangle only (holes). mesh_import.c imports the mesh. */
#include "scene/mesh_import.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/order.h"

/* A triangle by its corners in increasing order, and its index. */
typedef struct mesh_corners {
    uint32_t v[3];
    uint32_t t;
} mesh_corners;

static int mesh_corners_cmp(const void *a, const void *b)
{
    const mesh_corners *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->v[k] != y->v[k])
            return x->v[k] < y->v[k] ? -1 : 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

/* Twice the area of the triangle with corners v (its cross product's length). */
static double mesh_triangle_area2(const thz_mesh *mesh, const uint32_t *v)
{
    const float *p = mesh->positions;
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p[3 * v[1] + k] - p[3 * v[0] + k];
        e2[k] = (double)p[3 * v[2] + k] - p[3 * v[0] + k];
    }
    double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

bool mesh_import_defects(const thz_mesh *mesh, mesh_defects *out)
{
    *out = (mesh_defects){0};
    size_t nt = mesh->n_triangles;
    mesh_corners *tri = thz_malloc_array(nt ? nt : 1, sizeof *tri);
    bool *repeat = thz_calloc(nt ? nt : 1, sizeof *repeat); /* left out of the edges */
    uint64_t *edges = thz_malloc_array(3 * nt + 1, sizeof *edges);
    if (!tri || !repeat || !edges) {
        free(tri);
        free(repeat);
        free(edges);
        return false;
    }
    thz_populate(tri, nt * sizeof *tri); /* written whole, edges nearly: pages at once */
    thz_populate(edges, 3 * nt * sizeof *edges);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = &mesh->indices[3 * t];
        uint32_t a = v[0], b = v[1], c = v[2], x;
        if (a > b)
            x = a, a = b, b = x;
        if (b > c)
            x = b, b = c, c = x;
        if (a > b)
            x = a, a = b, b = x;
        tri[t] = (mesh_corners){{a, b, c}, (uint32_t)t};
        if (a == b || b == c || !(mesh_triangle_area2(mesh, v) > 0.0)) {
            out->degenerate++;
            repeat[t] = true; /* nor has it a side to wind */
        }
    }
    /* the same three corners, whichever way round: each after the first is a repeat */
    qsort(tri, nt, sizeof *tri, mesh_corners_cmp);
    for (size_t i = 1; i < nt; i++)
        if (!memcmp(tri[i].v, tri[i - 1].v, sizeof tri[i].v) && !repeat[tri[i].t]) {
            repeat[tri[i].t] = true;
            out->repeated++;
        }
    size_t m = 0;
    for (size_t t = 0; t < nt; t++) {
        if (repeat[t])
            continue;
        const uint32_t *v = &mesh->indices[3 * t];
        for (int k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[(k + 1) % 3];
            if (a != b)
                edges[m++] = ((uint64_t)a << 32) | b;
        }
    }
    order_sort_u64(edges, m);
    for (size_t i = 1; i < m; i++)
        if (edges[i] == edges[i - 1] && (i < 2 || edges[i - 1] != edges[i - 2]))
            out->winding_conflicts++;
    for (size_t i = 0; i < m; i++) {
        if ((i > 0 && edges[i - 1] == edges[i]) || (i + 1 < m && edges[i + 1] == edges[i]))
            continue; /* run twice: not open, whatever its winding */
        uint64_t rev = (edges[i] << 32) | (edges[i] >> 32);
        size_t lo = 0, hi = m; /* the first edge >= rev */
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (edges[mid] < rev)
                lo = mid + 1;
            else
                hi = mid;
        }
        if (lo == m || edges[lo] != rev)
            out->open_edges++;
    }
    free(tri);
    free(repeat);
    free(edges);
    return true;
}
