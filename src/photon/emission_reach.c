/* The back sides' reach shares: see emission_reach.h. */
#include "photon/emission_reach.h"

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/threads.h"
#include "photon/emission.h"

/* Rays of one work item (an object has EMISSION_REACH_RAYS / REACH_BLOCK items). */
#define REACH_BLOCK 1024u
/* A round, between which a stop is asked: objects until this many rays (about 0.1 s on
 * two cores) or this many triangles in their CDFs (12 bytes each), at least one object. */
#define REACH_ROUND_RAYS ((uint64_t)1 << 20)
#define REACH_ROUND_TRIANGLES ((size_t)1 << 22)

_Static_assert(EMISSION_REACH_RAYS % REACH_BLOCK == 0, "an object's rays are whole blocks");

bool emission_reach_needed(const thz_scene *scene, size_t i)
{
    const thz_object *obj = &scene->objects[i];
    return obj->mesh.total_area_m2 > 0.0 && obj->mesh.n_triangles > 0 &&
           !scene_object_side_is_front(obj, 1);
}

bool emission_reach_any(const thz_scene *scene)
{
    for (size_t i = 0; i < scene->n_objects; i++)
        if (emission_reach_needed(scene, i))
            return true;
    return false;
}

void emission_reach_fini(emission_reach *r)
{
    if (!r)
        return;
    free(r->share);
    memset(r, 0, sizeof *r);
}

/* Rays k0 .. k1 - 1 of object i's EMISSION_REACH_RAYS: cosine rays from uniform points of
 * its back side, traced as trace_photon starts a photon; how many first hit a front face.
 * Ray k's stream depends on the seed, i and k only (channel 0). */
static uint64_t reach_rays(const thz_scene *scene, const accel *acc, size_t i, const double *cdf,
                           uint64_t k0, uint64_t k1)
{
    const thz_mesh *m = &scene->objects[i].mesh;
    uint64_t reach = 0;
    for (uint64_t k = k0; k < k1; k++) {
        rng_stream rng;
        rng_init(&rng, scene->photons.seed, 0, RNG_PURPOSE_BACK_FACE,
                 (uint64_t)i * EMISSION_REACH_RAYS + k);
        size_t tri;
        vec3 p = emission_point(m, cdf, m->total_area_m2, &rng, &tri);
        const float *nf = &m->normals[3 * tri];
        vec3 n = v3_scale(v3(nf[0], nf[1], nf[2]), -1.0);
        double u = rng_uniform32(&rng);
        vec3 dir = sampling_direction(n, sqrt(1.0 - u), rng_uniform32(&rng));
        accel_hit from = {
            .object = (uint32_t)i, .triangle = (uint32_t)tri, .position_m = p, .side = 1};
        accel_hit hit;
        reach += accel_intersect(acc, accel_offset_origin(acc, &from, dir), dir, INFINITY,
                                 (uint32_t)i, (uint32_t)tri, &hit) &&
                 scene_object_side_is_front(&scene->objects[hit.object], hit.side);
    }
    return reach;
}

/* One round: objects obj[0 .. n - 1]; their shares into share[]. False when out of
 * memory. */
static bool reach_round(const thz_scene *scene, const accel *acc, const size_t *obj, size_t n,
                        int nt, double *share)
{
    const uint64_t blocks = EMISSION_REACH_RAYS / REACH_BLOCK;
    double **cdf = thz_calloc(n, sizeof *cdf);
    uint64_t *count = thz_calloc(n * blocks, sizeof *count);
    int failed = 0;
    if (!cdf || !count)
        failed = 1;
    if (!failed) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
        for (long j = 0; j < (long)n; j++) {
            cdf[j] = emission_triangle_cdf(&scene->objects[obj[j]].mesh);
            if (!cdf[j]) {
#pragma omp atomic write
                failed = 1;
            }
        }
    }
    if (!failed) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
        for (long w = 0; w < (long)(n * blocks); w++) {
            size_t j = (size_t)w / blocks;
            uint64_t k0 = (uint64_t)w % blocks * REACH_BLOCK;
            count[w] = reach_rays(scene, acc, obj[j], cdf[j], k0, k0 + REACH_BLOCK);
        }
        for (size_t j = 0; j < n; j++) { /* integer sums: the same for any thread count */
            uint64_t reach = 0;
            for (uint64_t b = 0; b < blocks; b++)
                reach += count[j * blocks + b];
            share[obj[j]] = (double)reach / EMISSION_REACH_RAYS;
        }
    }
    for (size_t j = 0; cdf && j < n; j++)
        free(cdf[j]);
    free(cdf);
    free(count);
    return !failed;
}

/* Reports m of n objects done; whether to stop. */
static bool reach_stop(const thz_scene *scene, thz_progress_fn progress, void *user, size_t m,
                       size_t n)
{
    thz_progress p = {
        .stage = "prepare", .channel = 0, .n_channels = scene->n_channels, .done = m, .total = n};
    return progress && progress(user, &p) != 0;
}

thz_status emission_reach_compute(emission_reach *r, const thz_scene *scene, const accel *acc,
                                  int threads, thz_progress_fn progress, void *progress_user,
                                  thz_error *err)
{
    if (r->done)
        return THZ_OK;
    double t0 = omp_get_wtime();
    emission_reach_fini(r);
    r->n_objects = scene->n_objects;
    if (!emission_reach_any(scene)) {
        r->done = true;
        r->seconds = omp_get_wtime() - t0;
        return THZ_OK;
    }
    if (!acc)
        return thz_error_set(err, THZ_ERR_INTERNAL,
                             "photon emission: the back sides' reach needs the scene's ray caster");
    int nt = thz_threads_or_all(threads);
    nt = nt < 1 ? 1 : nt;
    size_t n = scene->n_objects;
    r->share = thz_malloc_array(n, sizeof *r->share);
    size_t *obj = thz_malloc_array(n, sizeof *obj);
    if (!r->share || !obj) {
        free(obj);
        emission_reach_fini(r);
        return thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
    }
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        r->share[i] = 1.0;
        if (emission_reach_needed(scene, i))
            obj[m++] = i;
    }
    thz_status st = THZ_OK;
    for (size_t a = 0; st == THZ_OK;) {
        if (reach_stop(scene, progress, progress_user, a, m)) {
            st = thz_error_set(err, THZ_ERR_CANCELLED, "photon emission: cancelled");
            break;
        }
        if (a == m)
            break;
        size_t b = a;
        uint64_t rays = 0;
        size_t triangles = 0;
        do {
            rays += EMISSION_REACH_RAYS;
            triangles += scene->objects[obj[b]].mesh.n_triangles;
            b++;
        } while (b < m && rays < REACH_ROUND_RAYS &&
                 triangles + scene->objects[obj[b]].mesh.n_triangles <= REACH_ROUND_TRIANGLES);
        if (!reach_round(scene, acc, obj + a, b - a, nt, r->share))
            st = thz_error_set(err, THZ_ERR_NOMEM, "photon emission: out of memory");
        a = b;
    }
    free(obj);
    if (st != THZ_OK) {
        emission_reach_fini(r);
        return st;
    }
    r->done = true;
    r->seconds = omp_get_wtime() - t0;
    return THZ_OK;
}
