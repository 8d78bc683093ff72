/* Raw Embree probe: see bench_probe.h. */
#include "bench_probe.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "core/alloc.h"
#include "core/cdf.h"
#include "core/rng.h"
#include "core/vec3.h"

#define BENCH_PROBE_POOL (1u << 20)
#define BENCH_PROBE_CHUNK 256u

typedef struct bench_ray {
    float org[3];
    float dir[3];
} bench_ray;

/* Fills pool[0..n) with photon-like rays. cdf: per emitting triangle (all objects in
 * order, both sides counted for two-sided ones), tri_obj/tri_idx name the triangle. */
static thz_status bench_probe_pool(const thz_scene *scene, bench_ray *pool, size_t n,
                                   double offset_m, thz_error *err)
{
    size_t total = 0;
    for (size_t i = 0; i < scene->n_objects; i++)
        if (scene->objects[i].temperature_k > 0.0)
            total += scene->objects[i].mesh.n_triangles;
    if (total == 0)
        return thz_error_set(err, THZ_ERR_INPUT, "probe: the scene has no emitting triangle");
    double *cdf = thz_malloc_array(total, sizeof *cdf);
    uint32_t *obj_of = thz_malloc_array(total, sizeof *obj_of);
    uint32_t *tri_of = thz_malloc_array(total, sizeof *tri_of);
    if (!cdf || !obj_of || !tri_of) {
        free(cdf);
        free(obj_of);
        free(tri_of);
        return thz_error_set(err, THZ_ERR_NOMEM, "probe: out of memory");
    }
    size_t k = 0;
    double acc = 0.0;
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_object *o = &scene->objects[i];
        if (!(o->temperature_k > 0.0))
            continue;
        double sides = (o->type == OBJECT_SHELL || o->two_sided) ? 2.0 : 1.0;
        for (size_t t = 0; t < o->mesh.n_triangles; t++) {
            acc += sides * o->mesh.areas_m2[t];
            cdf[k] = acc;
            obj_of[k] = (uint32_t)i;
            tri_of[k] = (uint32_t)t;
            k++;
        }
    }
    rng_stream rng;
    for (size_t r = 0; r < n; r++) {
        rng_init(&rng, 12345, 0, RNG_PURPOSE_TEST, r);
        size_t j = cdf_search(cdf, total, rng_uniform(&rng) * acc);
        const thz_object *o = &scene->objects[obj_of[j]];
        const thz_mesh *m = &o->mesh;
        size_t t = tri_of[j];
        const uint32_t *idx = &m->indices[3 * t];
        vec3 p0 = v3_from_floats(&m->positions[3 * (size_t)idx[0]]);
        vec3 p1 = v3_from_floats(&m->positions[3 * (size_t)idx[1]]);
        vec3 p2 = v3_from_floats(&m->positions[3 * (size_t)idx[2]]);
        double ra = sqrt(rng_uniform(&rng)), rb = rng_uniform(&rng);
        vec3 p = v3_add(v3_scale(p0, 1.0 - ra),
                        v3_add(v3_scale(p1, ra * (1.0 - rb)), v3_scale(p2, ra * rb)));
        vec3 nrm = v3_from_floats(&m->normals[3 * t]);
        bool two = o->type == OBJECT_SHELL || o->two_sided;
        if (two && rng_uniform(&rng) < 0.5)
            nrm = v3_scale(nrm, -1.0);
        vec3 tb, bb;
        v3_basis(nrm, &tb, &bb);
        double mu = sqrt(1.0 - rng_uniform(&rng)), phi = 2.0 * M_PI * rng_uniform(&rng);
        double s = sqrt(fmax(0.0, 1.0 - mu * mu));
        vec3 d =
            v3_normalize(v3_madd(v3_madd(v3_scale(nrm, mu), s * cos(phi), tb), s * sin(phi), bb));
        p = v3_madd(p, offset_m, nrm);
        pool[r] =
            (bench_ray){{(float)p.x, (float)p.y, (float)p.z}, {(float)d.x, (float)d.y, (float)d.z}};
    }
    free(cdf);
    free(obj_of);
    free(tri_of);
    return THZ_OK;
}

thz_status bench_probe_run(const thz_scene *scene, uint64_t n_rays, int threads,
                           bench_probe_result *out, thz_error *err)
{
    memset(out, 0, sizeof *out);
    thz_status st = THZ_OK;
    RTCDevice dev = NULL;
    RTCScene rtc = NULL;
    bench_ray *pool = NULL;
    double t0 = omp_get_wtime();
    /* the program's kernels (accel_create caps them at AVX2 unless told otherwise) */
    const char *isa = NULL;
    st = accel_max_isa(&isa, err);
    if (st != THZ_OK)
        return st;
    char config[48];
    snprintf(config, sizeof config, "max_isa=%s", isa);
    dev = rtcNewDevice(config);
    if (!dev)
        return thz_error_set(err, THZ_ERR_INTERNAL, "probe: cannot create the Embree device");
    rtc = rtcNewScene(dev);
    /* As src/accel: robust traversal, high build quality (its filter flag aside). */
    rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double max_abs = 0.0;
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_mesh *m = &scene->objects[i].mesh;
        if (m->n_triangles == 0)
            continue;
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->bbox_min_m[k]);
            hi[k] = fmax(hi[k], m->bbox_max_m[k]);
            max_abs = fmax(max_abs, fmax(fabs(m->bbox_min_m[k]), fabs(m->bbox_max_m[k])));
        }
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->positions, 0,
                                   3 * sizeof(float), m->n_vertices);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices, 0,
                                   3 * sizeof(uint32_t), m->n_triangles);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(rtc, g, (unsigned)i);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(rtc);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) {
        st = thz_error_set(err, THZ_ERR_INTERNAL, "probe: Embree failed to build the scene");
        goto cleanup;
    }
    out->seconds_build = omp_get_wtime() - t0;

    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    double offset =
        fmax(fmax(1e-6 * sqrt(dx * dx + dy * dy + dz * dz), 16.0 * FLT_EPSILON * max_abs), 1e-9);
    size_t n_pool = n_rays < BENCH_PROBE_POOL ? (size_t)n_rays : BENCH_PROBE_POOL;
    if (n_pool == 0)
        n_pool = 1;
    pool = thz_malloc_array(n_pool, sizeof *pool);
    if (!pool) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "probe: out of memory for the rays");
        goto cleanup;
    }
    st = bench_probe_pool(scene, pool, n_pool, offset, err);
    if (st != THZ_OK)
        goto cleanup;

    int nt = threads > 0 ? threads : omp_get_max_threads();
    long n_chunks = (long)((n_rays + BENCH_PROBE_CHUNK - 1) / BENCH_PROBE_CHUNK);
    uint64_t hits = 0;
    t0 = omp_get_wtime();
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1) reduction(+ : hits)
    for (long c = 0; c < n_chunks; c++) {
        uint64_t first = (uint64_t)c * BENCH_PROBE_CHUNK;
        uint64_t last = first + BENCH_PROBE_CHUNK < n_rays ? first + BENCH_PROBE_CHUNK : n_rays;
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (uint64_t i = first; i < last; i++) {
            const bench_ray *r = &pool[i % n_pool];
            struct RTCRayHit rh;
            rh.ray.org_x = r->org[0];
            rh.ray.org_y = r->org[1];
            rh.ray.org_z = r->org[2];
            rh.ray.dir_x = r->dir[0];
            rh.ray.dir_y = r->dir[1];
            rh.ray.dir_z = r->dir[2];
            rh.ray.tnear = 0.0f;
            rh.ray.tfar = INFINITY;
            rh.ray.time = 0.0f;
            rh.ray.mask = 0xffffffffu;
            rh.ray.id = 0;
            rh.ray.flags = 0;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rtc, &ctx, &rh);
            hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
    }
    out->seconds = omp_get_wtime() - t0;
    out->rays = n_rays;
    out->hits = hits;
    out->pool = n_pool;
cleanup:
    free(pool);
    if (rtc)
        rtcReleaseScene(rtc);
    rtcReleaseDevice(dev);
    return st;
}
