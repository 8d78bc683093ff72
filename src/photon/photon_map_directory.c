/* A renderer's lookup table over a photon map's spatial index: see photon_map.h. */
#include <omp.h>
#include <stdlib.h>

#include "core/alloc.h"
#include "core/threads.h"
#include "photon/photon_map_layout.h"

/* The directory's level for a group of n records: the deepest L <= PHOTON_DIR_MAX_LEVELS
 * with PHOTON_DIR_MIN_PER_CELL records per cell of level L on average; 0 for groups too
 * small to need one (their binary searches stay within a few cache lines), and for
 * groups of 2^32 records or more (its offsets are 32 bits). */
static int photon_dir_level(size_t n)
{
    int level = 0;
    if (n > UINT32_MAX)
        return 0;
    while (level < PHOTON_DIR_MAX_LEVELS && (size_t)PHOTON_DIR_MIN_PER_CELL << 3 * (level + 1) <= n)
        level++;
    return level;
}

/* Descends from `cell` to the directory's level by the queries' own splits, writing the
 * first record of every cell there (empty cells included: their start is where they would
 * begin). */
static void photon_dir_fill(const photon_cube *cube, const photon_record *r,
                            const photon_cell *cell, int level, size_t base, uint32_t *starts)
{
    if (cell->level == level) {
        starts[cell->m] = (uint32_t)(cell->lo - base);
        return;
    }
    size_t b[9];
    photon_cell_split(cube, r, cell, b);
    for (unsigned d = 0; d < 8; d++) {
        photon_cell child = photon_child(cell, d, b);
        photon_dir_fill(cube, r, &child, level, base, starts);
    }
}

void photon_map_directory_destroy(photon_map_directory *dir)
{
    if (!dir)
        return;
    for (size_t g = 0; dir->starts && g < dir->n_groups; g++)
        free(dir->starts[g]);
    free(dir->starts);
    free(dir->level);
    free(dir);
}

thz_status photon_map_directory_create(const photon_map *map, int threads,
                                       photon_map_directory **out, thz_error *err)
{
    *out = NULL;
    photon_map_directory *dir = thz_calloc(1, sizeof *dir);
    size_t n_groups = map ? map->n_groups : 0;
    if (dir) {
        dir->n_groups = n_groups;
        dir->level = thz_calloc(n_groups ? n_groups : 1, sizeof *dir->level);
        dir->starts = thz_calloc(n_groups ? n_groups : 1, sizeof *dir->starts);
    }
    if (!dir || !dir->level || !dir->starts) {
        photon_map_directory_destroy(dir);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for its directory");
    }
    for (size_t g = 0; g < n_groups; g++) {
        size_t lo = map->start[g], hi = map->start[g + 1];
        int level = photon_dir_level(hi - lo);
        if (level == 0)
            continue;
        size_t cells = (size_t)1 << 3 * level;
        uint32_t *starts = thz_malloc_array(cells + 1, sizeof *starts);
        if (!starts) {
            photon_map_directory_destroy(dir);
            return thz_error_set(err, THZ_ERR_NOMEM, "photon map: out of memory for its directory");
        }
        starts[cells] = (uint32_t)(hi - lo);
        dir->starts[g] = starts;
        dir->level[g] = level;
    }
    /* The fills, each group's 8 children of its root a task of their own: they write
     * disjoint cells, so the directory is the same for any thread count. Serial, they
     * were ~12 % of a photon-map render of the paper's 10 M-photon maps on 2 threads. */
    int nt = thz_threads_or_all(threads);
#pragma omp parallel num_threads(nt)
#pragma omp single
    for (size_t g = 0; g < n_groups; g++) {
        if (dir->level[g] == 0)
            continue;
        photon_cell root = {.level = 0, .lo = map->start[g], .hi = map->start[g + 1]};
        size_t b[9];
        photon_cell_split(&map->cubes[g], map->records, &root, b);
        for (unsigned d = 0; d < 8; d++) {
            photon_cell child = photon_child(&root, d, b);
#pragma omp task firstprivate(child, g)
            photon_dir_fill(&map->cubes[g], map->records, &child, dir->level[g], map->start[g],
                            dir->starts[g]);
        }
    }
    *out = dir;
    return THZ_OK;
}

size_t photon_map_directory_bytes(const photon_map_directory *dir)
{
    if (!dir)
        return 0;
    size_t bytes = sizeof *dir + dir->n_groups * (sizeof *dir->level + sizeof *dir->starts);
    for (size_t g = 0; g < dir->n_groups; g++)
        if (dir->level[g] > 0)
            bytes += (((size_t)1 << 3 * dir->level[g]) + 1) * sizeof(uint32_t);
    return bytes;
}
