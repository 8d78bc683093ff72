/* Vertex welding of an imported mesh (in the import child, mesh_import_child.c): the
 * vertices that triangles use kept, those at exactly the same position merged (STL stores
 * each triangle's corners separately) and renumbered in position order, by radix sorts
 * (mesh_import_internal.h). */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/order.h"
#include "scene/mesh_import_internal.h"

/* Orders positions; 0 exactly when the weld merges them (so the sort and the merge
 * agree on what is equal). */
static int mesh_import_position_cmp(const float *x, const float *y)
{
    for (int k = 0; k < 3; k++) {
        if (x[k] < y[k])
            return -1;
        if (x[k] > y[k])
            return 1;
    }
    return 0;
}

/* A finite float's bits as an unsigned number in the float's order (-0 made +0 before). */
static uint64_t mesh_import_float_key(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u & 0x80000000u ? ~u : u | 0x80000000u;
}

/* Puts order[0..n) (vertex indices, increasing) in mesh_import_position_cmp's order, equal
 * positions by index: sorted by z, then y, then x, each a radix sort of (coordinate's key
 * << 32 | place) that keeps the order of equal coordinates. Where qsort's comparisons
 * through pointers took 8-16 % of a 2^24-triangle STL's load. keys: n words of scratch,
 * next: n more places. */
static void mesh_import_position_order(const float *positions, uint32_t *order, uint32_t *next,
                                       uint64_t *keys, size_t n)
{
    for (int k = 2; k >= 0; k--) {
        for (size_t i = 0; i < n; i++)
            keys[i] = mesh_import_float_key(positions[3 * (size_t)order[i] + (size_t)k]) << 32 | i;
        order_sort_u64_threads(keys, n, 1); /* the import's child: no OpenMP team */
        for (size_t i = 0; i < n; i++)
            next[i] = order[keys[i] & 0xffffffffu];
        memcpy(order, next, n * sizeof *order);
    }
}

bool mesh_import_weld(thz_mesh *mesh)
{
    size_t n = mesh->n_vertices;
    uint32_t *order = thz_malloc_array(n, sizeof *order);
    uint32_t *next = thz_malloc_array(n, sizeof *next);
    uint64_t *keys = thz_malloc_array(n, sizeof *keys);
    uint32_t *remap = thz_calloc(n, sizeof *remap);
    float *pos = thz_malloc_array(3 * n + 4, sizeof *pos);
    bool ok = order && next && keys && remap && pos;
    if (!ok)
        goto cleanup;
    /* written whole but for unused vertices: their pages mapped at once */
    thz_populate(order, n * sizeof *order);
    thz_populate(next, n * sizeof *next);
    thz_populate(keys, n * sizeof *keys);
    for (size_t i = 0; i < 3 * mesh->n_triangles; i++)
        remap[mesh->indices[i]] = 1;
    size_t used = 0;
    for (size_t v = 0; v < n; v++) {
        if (!remap[v])
            continue;
        float *p = &mesh->positions[3 * v];
        for (int k = 0; k < 3; k++)
            if (p[k] == 0.0f)
                p[k] = 0.0f; /* -0 becomes +0: one position, one bit pattern */
        order[used++] = (uint32_t)v;
    }
    mesh_import_position_order(mesh->positions, order, next, keys, used);
    size_t unique = 0;
    const float *last = NULL;
    for (size_t i = 0; i < used; i++) {
        const float *p = &mesh->positions[3 * (size_t)order[i]];
        if (!last || mesh_import_position_cmp(p, last) != 0) {
            memcpy(&pos[3 * unique], p, 3 * sizeof(float));
            unique++;
        }
        last = p;
        remap[order[i]] = (uint32_t)(unique - 1);
    }
    memset(&pos[3 * unique], 0, 4 * sizeof *pos);
    for (size_t i = 0; i < 3 * mesh->n_triangles; i++)
        mesh->indices[i] = remap[mesh->indices[i]];
    free(mesh->positions);
    mesh->positions = pos;
    mesh->n_vertices = unique;
    pos = NULL;
cleanup:
    free(order);
    free(next);
    free(keys);
    free(remap);
    free(pos);
    return ok;
}
