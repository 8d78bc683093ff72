/* Ray casting with Embree 3: one triangle geometry per object (geomID = object index),
 * sharing the scene's float positions and indices, robust traversal and high build
 * quality.
 *
 * Self-intersection rule. A ray leaving a surface is protected twice:
 *  1. the (object, triangle) it leaves from is never returned: a ray whose closest hit
 *     is that triangle is cast again with a context filter function that rejects it,
 *     so the leaving triangle can never be hit again at t ~ 0 whatever the rounding;
 *  2. its origin is moved off the surface along the geometric normal, towards the side
 *     the ray leaves on, by eps = max(1e-6 * bbox diagonal, 16 * FLT_EPSILON *
 *     largest |coordinate|, 1e-9 m). The second term keeps the offset above the float
 *     spacing of the coordinates (Embree works in single precision), so a neighbouring
 *     triangle sharing an edge is not hit through rounding. For scenes up to ~50 m the
 *     offset stays well below 0.1 mm, so both surfaces of a 0.1 mm shell are resolved
 *     (tests/unit/test_accel.c checks exactly that).
 *
 * Threads. Embree builds on thzmap's own OpenMP threads (rtcJoinCommitScene with as
 * many user threads as processors), never on TBB workers: TBB turns a worker it cannot
 * start (no memory for the thread's stack or TLS) into std::terminate, which would end
 * the process with no message and the output's staging files beside OUTDIR (issue 20;
 * docs/reliability.md). libgomp's own failure to start a thread ends in exit(), which
 * the CLI's exit handler cleans up after. The number of build threads is the number of
 * processors this process may use whatever --threads says, as TBB's default was, so the
 * structure (and every hit) is the same for any --threads. Whether Embree's structure
 * depends on the number of build threads (MPI ranks bound to fewer cores than one process
 * gets) is not known; the MPI tests compare processes on one machine.
 *
 * Processors. Embree picks its kernels by the processor's instruction sets (SSE, AVX2,
 * AVX-512: different SIMD widths), and their hit distances and barycentric coordinates
 * differ in the last bits between those sets and between processors of one set (an AMD
 * and an Intel machine with SSE4.2's kernels). thzmap takes from Embree only which
 * triangle is hit and computes the point and distance itself (accel_intersect), so the
 * photons' paths and the images are the same bytes whatever the kernels (test_environment.sh,
 * test_deviation_photons). What can still differ is the rare ray that meets the edge two
 * triangles share within single-precision rounding: other kernels, or another maker's
 * processor, may return either triangle, and the point moves in its last bits (the
 * paper's case, SSE4.2's kernels against AVX-512's: 1 or 2 of 24,576 values differed
 * with path and final-gather; with photon-map none at 1 M photons a channel and one at
 * 10 M, by 0.4 %, a photon having crossed the edge of a pixel's gather). THZMAP_EMBREE_MAX_ISA caps
 * the set Embree may use, so that machines run the same kernels; unset, the cap is AVX2: every
 * processor with AVX2 (2013 on) runs the same kernels, and AVX-512's were no faster for thzmap's
 * single rays (the paper's case, 2 threads: 11.45-11.92 s either way; SSE4.2's 12.8 s)
 * (docs/scene-format.md "Reproducibility").
 */
#include "accel/accel.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/threads.h"

struct accel {
    const thz_scene *scene;
    RTCDevice device;
    RTCScene rtc;
};

/* Back faces met on their edge that a ray may pass over (accel_intersect): a box's
 * corner joins three faces, each of two triangles. */
#define ACCEL_EDGE_RECASTS 4

/* The context passed to rtcIntersect1: Embree's context first, then what to ignore. */
typedef struct accel_context {
    struct RTCIntersectContext base;
    uint32_t ignore_object;
    uint32_t ignore_triangle;
    uint32_t n_edges; /* back faces met on their edge, passed over too */
    uint32_t edge_object[ACCEL_EDGE_RECASTS], edge_triangle[ACCEL_EDGE_RECASTS];
} accel_context;

/* Context filter: rejects the hit on the triangle the ray leaves from, and on the back
 * faces met on their edge. The hit layout is Embree's RTCHitN (SOA): primID at word
 * 5N + i, geomID at 6N + i. */
static void accel_filter(const struct RTCFilterFunctionNArguments *args)
{
    const accel_context *ctx = (const accel_context *)args->context;
    const unsigned *words = (const unsigned *)args->hit;
    unsigned n = args->N;
    for (unsigned i = 0; i < n; i++) {
        if (args->valid[i] == 0)
            continue;
        unsigned geom = words[6 * n + i], prim = words[5 * n + i];
        if (geom == ctx->ignore_object && prim == ctx->ignore_triangle)
            args->valid[i] = 0;
        for (uint32_t k = 0; k < ctx->n_edges; k++)
            if (geom == ctx->edge_object[k] && prim == ctx->edge_triangle[k])
                args->valid[i] = 0;
    }
}

/* Whether Embree's hit lies on its triangle's edge, to single precision. */
static bool accel_on_edge(const struct RTCRayHit *rh)
{
    const float e = 64.0f * FLT_EPSILON;
    return rh->hit.u <= e || rh->hit.v <= e || 1.0f - rh->hit.u - rh->hit.v <= e;
}

static const char *accel_error_name(enum RTCError e)
{
    switch (e) {
    case RTC_ERROR_NONE:
        return "no error";
    case RTC_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
        return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
        return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
        return "cancelled";
    default:
        return "unknown error";
    }
}

static thz_status accel_check_device(RTCDevice device, const char *what, thz_error *err)
{
    enum RTCError e = rtcGetDeviceError(device);
    if (e == RTC_ERROR_NONE)
        return THZ_OK;
    return thz_error_set(err, e == RTC_ERROR_OUT_OF_MEMORY ? THZ_ERR_NOMEM : THZ_ERR_INTERNAL,
                         "ray casting: Embree failed while %s: %s", what, accel_error_name(e));
}

/* The instruction sets THZMAP_EMBREE_MAX_ISA may name, as Embree spells them. */
static const char *const accel_isas[] = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
#define ACCEL_N_ISAS (sizeof accel_isas / sizeof accel_isas[0])

thz_status accel_max_isa(const char **isa, thz_error *err)
{
    *isa = "avx2";
    const char *v = getenv("THZMAP_EMBREE_MAX_ISA");
    if (!v || !v[0])
        return THZ_OK;
    for (size_t i = 0; i < ACCEL_N_ISAS; i++)
        if (strcmp(v, accel_isas[i]) == 0) {
            *isa = accel_isas[i];
            return THZ_OK;
        }
    return thz_error_set(err, THZ_ERR_INPUT,
                         "THZMAP_EMBREE_MAX_ISA: expected one of sse2, sse4.2, avx, avx2, "
                         "avx512 (or unset), got \"%.40s\"",
                         v);
}

thz_status accel_create(const thz_scene *scene, accel **out, thz_error *err)
{
    thz_status st = THZ_OK;
    *out = NULL;
    accel *a = thz_calloc(1, sizeof *a);
    if (!a)
        return thz_error_set(err, THZ_ERR_NOMEM, "ray casting: out of memory");
    a->scene = scene;

    if (scene->n_objects >= RTC_INVALID_GEOMETRY_ID) {
        st = thz_error_set(err, THZ_ERR_LIMIT, "ray casting: too many objects (%zu)",
                           scene->n_objects);
        goto cleanup;
    }

    /* Every build thread a user thread: TBB starts none of its own (see the top); the
     * instruction sets capped where the environment says (see the top). */
    const char *isa = NULL;
    st = accel_max_isa(&isa, err);
    if (st != THZ_OK)
        goto cleanup;
    int build_threads = omp_get_num_procs();
    /* under ulimit -v, no more than thz_threads_prepare found room for: a thread libgomp
     * cannot start ends the process */
    if (thz_address_space_limit_bytes() > 0 && build_threads > thz_threads_fitting(0))
        build_threads = thz_threads_fitting(0);
    char config[96];
    snprintf(config, sizeof config, "threads=%d,user_threads=%d,max_isa=%s", build_threads,
             build_threads, isa);
    a->device = rtcNewDevice(config);
    if (!a->device) {
        enum RTCError e = rtcGetDeviceError(NULL); /* its 128 MiB pool under ulimit -v */
        st = thz_error_set(err, e == RTC_ERROR_OUT_OF_MEMORY ? THZ_ERR_NOMEM : THZ_ERR_INTERNAL,
                           "ray casting: cannot create the Embree device: %s", accel_error_name(e));
        goto cleanup;
    }
    a->rtc = rtcNewScene(a->device);
    if (!a->rtc) {
        st = accel_check_device(a->device, "creating the scene", err);
        if (st == THZ_OK)
            st = thz_error_set(err, THZ_ERR_INTERNAL, "ray casting: cannot create the scene");
        goto cleanup;
    }
    rtcSetSceneFlags(a->rtc, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(a->rtc, RTC_BUILD_QUALITY_HIGH);

    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_mesh *m = &scene->objects[i].mesh;
        if (m->n_triangles == 0 || m->n_vertices == 0)
            continue;
        if (m->n_triangles > UINT32_MAX || m->n_vertices > UINT32_MAX) {
            st = thz_error_set(
                err, THZ_ERR_LIMIT, "ray casting: object '%s' has too many triangles (%zu)",
                scene->objects[i].name ? scene->objects[i].name : "?", m->n_triangles);
            goto cleanup;
        }
        RTCGeometry g = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!g) {
            st = accel_check_device(a->device, "creating a geometry", err);
            goto cleanup;
        }
        /* Shared buffers: the scene's positions carry the 16 bytes of padding Embree
         * reads past the last vertex. */
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->positions, 0,
                                   3 * sizeof(float), m->n_vertices);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices, 0,
                                   3 * sizeof(uint32_t), m->n_triangles);
        rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(a->rtc, g, (unsigned)i);
        rtcReleaseGeometry(g);
        st = accel_check_device(a->device, "adding a geometry", err);
        if (st != THZ_OK)
            goto cleanup;
    }
    /* Embree keeps its error per thread: a build failure is on whichever thread met it.
     * An allocation that fails on one of the threads Embree's build runs on reaches the
     * caller as "unknown error" as often as "out of memory" (test_alloc_fail, the same
     * failed allocation, 4 of 6 runs): after an unknown error the build is tried once
     * more, which reports out of memory as such where memory stays short. */
    enum RTCError build_error = RTC_ERROR_UNKNOWN;
    for (int attempt = 0; attempt < 2 && build_error == RTC_ERROR_UNKNOWN; attempt++) {
        build_error = RTC_ERROR_NONE;
#pragma omp parallel num_threads(build_threads)
        {
            rtcJoinCommitScene(a->rtc);
            enum RTCError e = rtcGetDeviceError(a->device);
            if (e != RTC_ERROR_NONE) {
#pragma omp critical /* unnamed: a named one is a global symbol of the library */
                if (build_error == RTC_ERROR_NONE || e == RTC_ERROR_OUT_OF_MEMORY)
                    build_error = e;
            }
        }
    }
    if (build_error != RTC_ERROR_NONE) {
        st = thz_error_set(
            err, build_error == RTC_ERROR_OUT_OF_MEMORY ? THZ_ERR_NOMEM : THZ_ERR_INTERNAL,
            "ray casting: Embree failed while building the acceleration structure: %s",
            accel_error_name(build_error));
        goto cleanup;
    }

    *out = a;
    a = NULL;
cleanup:
    accel_destroy(a);
    return st;
}

void accel_destroy(accel *a)
{
    if (!a)
        return;
    if (a->rtc)
        rtcReleaseScene(a->rtc);
    if (a->device)
        rtcReleaseDevice(a->device);
    free(a);
}

/* Casts rh's ray again over [tnear, tfar] (with ctx's filter, if set), forgetting its hit. */
static void accel_recast(const accel *a, accel_context *ctx, struct RTCRayHit *rh, float tnear,
                         float tfar)
{
    rh->ray.tnear = tnear;
    rh->ray.tfar = tfar;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(a->rtc, &ctx->base, rh);
}

/* The cosine between dir and the normal of the triangle rh hit (> 0: met from its back). */
static double accel_hit_cos(const accel *a, const struct RTCRayHit *rh, vec3 dir)
{
    const float *nf = &a->scene->objects[rh->hit.geomID].mesh.normals[3 * (size_t)rh->hit.primID];
    return v3_dot(dir, v3(nf[0], nf[1], nf[2]));
}

bool accel_intersect(const accel *a, vec3 origin_m, vec3 dir, double max_distance_m,
                     uint32_t ignore_object, uint32_t ignore_triangle, accel_hit *hit)
{
    accel_context ctx;
    rtcInitIntersectContext(&ctx.base);
    ctx.ignore_object = ignore_object;
    ctx.ignore_triangle = ignore_triangle;
    ctx.n_edges = 0;

    struct RTCRayHit rh;
    rh.ray.org_x = (float)origin_m.x;
    rh.ray.org_y = (float)origin_m.y;
    rh.ray.org_z = (float)origin_m.z;
    rh.ray.dir_x = (float)dir.x;
    rh.ray.dir_y = (float)dir.y;
    rh.ray.dir_z = (float)dir.z;
    rh.ray.tnear = 0.0f;
    const float tfar = max_distance_m >= (double)FLT_MAX ? INFINITY : (float)max_distance_m;
    rh.ray.tfar = tfar;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;

    /* Cast without the filter first: the closest hit, if it is not the ignored
     * triangle, is the closest of the others too. Only a ray that met the triangle it
     * leaves is cast again, with the filter (a callback on every candidate hit was 3.5 %
     * of path's instructions). */
    rtcIntersect1(a->rtc, &ctx.base, &rh);
    if (ignore_object != ACCEL_NO_OBJECT && rh.hit.geomID == ignore_object &&
        rh.hit.primID == ignore_triangle) {
        ctx.base.filter = accel_filter;
        accel_recast(a, &ctx, &rh, 0.0f, tfar);
    }
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return false;

    double c = accel_hit_cos(a, &rh, dir);
    /* A face met from its back, of a solid whose back no ray can see (solids are opaque),
     * its plane closer to the origin than the origin's rounding to single precision may
     * move it: the origin of a ray leaving near a concave corner, offset off its own wall,
     * rounded onto or behind the next one (a closed room 10 m across, 3 km from the
     * origin, read some pixels up to 3.7 K low). Cast again from just beyond that face. */
    float near =
        c > 0.0 ? 32.0f * FLT_EPSILON *
                      fmaxf(fabsf(rh.ray.org_x), fmaxf(fabsf(rh.ray.org_y), fabsf(rh.ray.org_z)))
                : 0.0f; /* only for a back-side hit: not on every ray's path */
    float tnear = 0.0f;
    if (c > 0.0 && rh.ray.tfar * c < near &&
        !scene_object_side_is_front(&a->scene->objects[rh.hit.geomID], 1)) {
        if (ignore_object != ACCEL_NO_OBJECT)
            ctx.base.filter = accel_filter;
        /* just beyond that plane: not a centimetre on, where a corner's third wall may be */
        tnear = fmaxf(1.001f * rh.ray.tfar, 0.125f * near);
        accel_recast(a, &ctx, &rh, tnear, tfar);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            return false;
        c = accel_hit_cos(a, &rh, dir);
    }
    /* A face met from its back on its edge, of such a solid, where a face met from its
     * front shares the point: a ray through the edge between two faces of a box (its
     * silhouette, met exactly by a camera ray at round coordinates) may be given the face
     * behind the edge rather than the one before it (such pixels read 0 K beside a 310 K
     * box). Cast again without the back faces met there (a corner joins several): a face
     * met from its front at that distance is the hit; else (the inner edge of a plate
     * met from behind, or a ray that only grazes) the back face stays. */
    if (c > 0.0 && accel_on_edge(&rh) &&
        !scene_object_side_is_front(&a->scene->objects[rh.hit.geomID], 1)) {
        const struct RTCRayHit back = rh;
        const float t_edge = (1.0f + 64.0f * FLT_EPSILON) * rh.ray.tfar;
        ctx.base.filter = accel_filter;
        bool again = true;
        while (again) {
            ctx.edge_object[ctx.n_edges] = rh.hit.geomID;
            ctx.edge_triangle[ctx.n_edges++] = rh.hit.primID;
            accel_recast(a, &ctx, &rh, tnear, fminf(t_edge, tfar));
            c = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? accel_hit_cos(a, &rh, dir) : 0.0;
            again = c > 0.0 && ctx.n_edges < ACCEL_EDGE_RECASTS && accel_on_edge(&rh) &&
                    !scene_object_side_is_front(&a->scene->objects[rh.hit.geomID], 1);
        }
        if (!(c < 0.0)) {
            rh = back;
            c = accel_hit_cos(a, &rh, dir);
        }
    }

    const thz_mesh *m = &a->scene->objects[rh.hit.geomID].mesh;
    uint32_t tri = rh.hit.primID;
    const float *nf = &m->normals[3 * (size_t)tri];
    vec3 n = v3(nf[0], nf[1], nf[2]);

    /* Where the ray meets the triangle's plane, in double from the ray as the caller gave
     * it: on that plane to double precision however long the ray, and the same on every
     * machine. Embree's distance and barycentric coordinates are scaled by approximate
     * reciprocals (rcpps, rcp14 with a Newton step) whose last bits differ between
     * instruction sets and between processors (an AMD and an Intel machine, the same SSE4.2
     * kernels), and with them every path after the first hit. So Embree decides which
     * triangle is hit, and this where. The plane is the one through the first corner with
     * the mesh's unit normal; that normal, rounded to float, tilts it by ~1e-7 rad, so a
     * ray at a grazing angle would slide along it by ~1e-7 of the triangle's size over
     * |cos|: below |cos| = 0.01 (about 1e-4 of the rays) the plane is the corners' own,
     * from their cross product in double (a few percent slower for every ray). A ray
     * parallel to it to 1e-12 keeps Embree's point. */
    const uint32_t *idx = &m->indices[3 * (size_t)tri];
    vec3 p0 = v3_from_floats(&m->positions[3 * (size_t)idx[0]]);
    vec3 plane = n;
    double along = c;
    if (fabs(c) < 0.01) {
        vec3 p1 = v3_from_floats(&m->positions[3 * (size_t)idx[1]]);
        vec3 p2 = v3_from_floats(&m->positions[3 * (size_t)idx[2]]);
        plane = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
        along = v3_dot(dir, plane);
    }
    if (along * along > 1e-24 * v3_dot(plane, plane)) {
        double t = v3_dot(v3_sub(p0, origin_m), plane) / along;
        t = t > 0.0 ? t : 0.0;
        hit->position_m = v3_madd(origin_m, t, dir);
        hit->distance_m = t;
    } else {
        vec3 p1 = v3_from_floats(&m->positions[3 * (size_t)idx[1]]);
        vec3 p2 = v3_from_floats(&m->positions[3 * (size_t)idx[2]]);
        double u = rh.hit.u, v = rh.hit.v;
        hit->position_m =
            v3_add(v3_scale(p0, 1.0 - u - v), v3_add(v3_scale(p1, u), v3_scale(p2, v)));
        hit->distance_m = rh.ray.tfar;
    }
    hit->object = rh.hit.geomID;
    hit->triangle = tri;
    hit->side = c < 0.0 ? 0 : 1;
    double mu = fabs(c);
    hit->cos_theta = mu > 1.0 ? 1.0 : (mu > 1e-12 ? mu : 1e-12);
    return true;
}

/* The offset is the hit's own: 16 float epsilons of its largest coordinate (Embree takes
 * the origin in single precision, which rounds it by half an epsilon of that), at least
 * 1e-9 m. It was one distance for the whole scene, the larger of 1e-6 of its diagonal and
 * 16 epsilons of its largest coordinate: 3.4 mm in a hall 2 km across, more than the 2 mm
 * between a cover and the cylinder under it, whose rays then started beyond the cover
 * (the targets read 272-278 K instead of 296-301 K), and 19 m everywhere once one object
 * stood 1e7 m away. */
vec3 accel_offset_origin(const accel *a, const accel_hit *hit, vec3 dir)
{
    const thz_mesh *m = &a->scene->objects[hit->object].mesh;
    const float *nf = &m->normals[3 * (size_t)hit->triangle];
    vec3 n = v3(nf[0], nf[1], nf[2]);
    vec3 q = hit->position_m;
    double offset = fmax(16.0 * FLT_EPSILON * fmax(fabs(q.x), fmax(fabs(q.y), fabs(q.z))), 1e-9);
    return v3_madd(q, v3_dot(dir, n) >= 0.0 ? offset : -offset, n);
}
