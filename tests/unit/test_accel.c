/* Ray casting: hits, sides, misses, thread safety, and the self-intersection rule on a
 * 0.1 mm shell (two parallel rectangles 0.1 mm apart inside a 10 m room): a ray leaving
 * one surface at normal or grazing angles, from anywhere including the triangles'
 * shared edge, hits the other surface and never the one it leaves. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../physics/photon_scenes.h"
#include "accel/accel.h"
#include "core/rng.h"
#include "core/sampling.h"

#define GAP_M 1e-4

typedef struct fixture {
    thz_scene *scene;
    accel *acc;
    size_t lower, upper, room;
} fixture;

/* Lower rectangle at z = z0 (normal +z), upper at z0 + 0.1 mm (normal -z, facing it),
 * both 3 m x 3 m centred at (x0, y0), inside a 10 m room. */
static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->scene = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(f->scene, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    double x0 = 3.0, y0 = -2.0, z0 = 4.0;
    f->lower = ps_object(f->scene, OBJECT_SOLID, m, 300, 0, true);
    ps_face(f->scene, f->lower, v3(x0, y0, z0), v3(1.5, 0, 0), v3(0, 1.5, 0));
    f->upper = ps_object(f->scene, OBJECT_SOLID, m, 300, 0, true);
    ps_face(f->scene, f->upper, v3(x0, y0, z0 + GAP_M), v3(0, 1.5, 0), v3(1.5, 0, 0));
    f->room = ps_object(f->scene, OBJECT_SOLID, m, 300, 0, false);
    ps_box(f->scene, f->room, v3(-5, -5, 0), v3(5, 5, 10), true);
    ps_finalize(f->scene);
    thz_error err;
    assert_int_equal(accel_create(f->scene, &f->acc, &err), THZ_OK);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    accel_destroy(f->acc);
    scene_destroy(f->scene);
    free(f);
    return 0;
}

/* A hit record for a point on triangle `tri` of `object` (as if a ray had arrived). */
static accel_hit at(uint32_t object, uint32_t tri, vec3 p)
{
    accel_hit h = {.object = object, .triangle = tri, .position_m = p, .side = 0, .cos_theta = 1};
    return h;
}

static void test_hit_side_and_distance(void **state)
{
    fixture *f = *state;
    accel_hit h;
    /* From above, straight down: the upper rectangle's normal points down, so the ray
     * arrives on its back (side 1). */
    assert_true(accel_intersect(f->acc, v3(3.1, -2.1, 6.0), v3(0, 0, -1), INFINITY, ACCEL_NO_OBJECT,
                                0, &h));
    assert_int_equal(h.object, f->upper);
    assert_int_equal(h.side, 1);
    assert_float_equal(h.distance_m, 2.0 - GAP_M, 1e-5);
    assert_float_equal(h.cos_theta, 1.0, 1e-6);
    assert_float_equal(h.position_m.z, 4.0 + GAP_M, 1e-6);
    /* From below, up: the lower rectangle's back side. */
    assert_true(
        accel_intersect(f->acc, v3(3.1, -2.1, 1.0), v3(0, 0, 1), INFINITY, ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.object, f->lower);
    assert_int_equal(h.side, 1);
    /* Into the room's wall from inside at 60 degrees: front side, cos = 0.5. */
    vec3 d = v3(sqrt(3.0) / 2.0, 0, 0.5);
    assert_true(accel_intersect(f->acc, v3(0, 0, 1.0), d, INFINITY, ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.object, f->room);
    assert_int_equal(h.side, 0);
    assert_float_equal(h.cos_theta, sqrt(3.0) / 2.0, 1e-6);
    assert_float_equal(h.position_m.x, 5.0, 1e-5);
    /* max_distance limits the search. */
    assert_false(accel_intersect(f->acc, v3(0, 0, 1.0), v3(1, 0, 0), 4.0, ACCEL_NO_OBJECT, 0, &h));
}

/* The ignored triangle is never returned, even where it is the closest hit (from a
 * point 0.1 m below it, far beyond the origin offset): the next surface is. Ignoring
 * another triangle changes nothing. */
static void test_ignored_closest(void **state)
{
    fixture *f = *state;
    accel_hit h, g;
    vec3 o = v3(3.3, -2.1, 3.9), up = v3(0, 0, 1);
    assert_true(accel_intersect(f->acc, o, up, INFINITY, ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.object, f->lower);
    assert_true(accel_intersect(f->acc, o, up, INFINITY, h.object, h.triangle ^ 1u, &g));
    assert_int_equal(g.object, f->lower);
    assert_int_equal(g.triangle, h.triangle);
    assert_float_equal(g.distance_m, h.distance_m, 0.0);
    assert_true(accel_intersect(f->acc, o, up, INFINITY, h.object, h.triangle, &g));
    assert_int_equal(g.object, f->upper);
    assert_int_equal(g.side, 0);
    assert_float_equal(g.distance_m, 0.1 + GAP_M, 1e-5);
    /* and with a limit short of the next surface, nothing */
    assert_false(accel_intersect(f->acc, o, up, 0.1 + 0.5 * GAP_M, h.object, h.triangle, &g));
    /* Only that triangle: the next surface may be another of its object's (a ray into the
     * room from outside, its near wall ignored, meets the far wall 10 m on). */
    vec3 out = v3(-6.0, 0.3, 2.1), east = v3(1, 0, 0);
    assert_true(accel_intersect(f->acc, out, east, INFINITY, ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.object, f->room);
    assert_float_equal(h.distance_m, 1.0, 1e-6);
    assert_true(accel_intersect(f->acc, out, east, INFINITY, h.object, h.triangle, &g));
    assert_int_equal(g.object, f->room);
    assert_int_equal(g.side, 0);
    assert_float_equal(g.distance_m, 11.0, 1e-6);
}

/* Leaves the lower rectangle upwards from point p (on triangle tri) in direction dir and
 * checks that it hits the upper rectangle's front side after GAP/mu. */
static void check_leave(const fixture *f, uint32_t tri, vec3 p, vec3 dir)
{
    accel_hit from = at((uint32_t)f->lower, tri, p), h;
    vec3 o = accel_offset_origin(f->acc, &from, dir);
    assert_true(o.z > p.z);
    assert_true(o.z - p.z < 0.25 * GAP_M);
    assert_true(accel_intersect(f->acc, o, dir, INFINITY, (uint32_t)f->lower, tri, &h));
    assert_int_equal(h.object, f->upper);
    assert_int_equal(h.side, 0);
    assert_float_equal(h.distance_m * dir.z, GAP_M, 0.3 * GAP_M);

    /* And back down from the upper one. */
    vec3 down = v3(dir.x, dir.y, -dir.z);
    accel_hit from2 = h;
    vec3 o2 = accel_offset_origin(f->acc, &from2, down);
    assert_true(accel_intersect(f->acc, o2, down, INFINITY, h.object, h.triangle, &h));
    assert_int_equal(h.object, f->lower);
    assert_int_equal(h.side, 0);
}

static void test_thin_shell_normal_and_grazing(void **state)
{
    fixture *f = *state;
    /* mu from 1 down to cos(89.99 deg) = 1.7e-4: path 0.1 mm .. 0.57 m. */
    const double mus[] = {1.0, 0.7, 0.2, 0.05, 0.01, 1.7453e-3, 1.7453e-4};
    for (size_t i = 0; i < sizeof mus / sizeof mus[0]; i++) {
        double mu = mus[i], s = sqrt(1.0 - mu * mu);
        for (int a = 0; a < 8; a++) {
            double phi = a * M_PI / 4.0 + 0.1;
            vec3 dir = v3(s * cos(phi), s * sin(phi), mu);
            /* Near the centre of triangle 0 (corner (-,-)) and triangle 1 (corner (+,+)). */
            check_leave(f, 0, v3(3.0 + 0.2, -2.0 - 0.05, 4.0), dir);
            check_leave(f, 1, v3(3.0 + 0.05, -2.0 + 0.2, 4.0), dir);
        }
    }
}

/* Points on the quad's diagonal, the edge the two triangles share: whichever triangle
 * the ray leaves from, it must not hit the other one. */
static void test_shared_edge(void **state)
{
    fixture *f = *state;
    rng_stream rng;
    rng_init(&rng, 7, 0, RNG_PURPOSE_TEST, 0);
    for (int i = 0; i < 2000; i++) {
        double t = 0.1 + 0.8 * rng_uniform(&rng);
        vec3 p = v3(3.0 - 0.5 + t, -2.0 - 0.5 + t, 4.0);
        double mu = fmax(1e-3, rng_uniform(&rng));
        vec3 dir = sampling_direction(v3(0, 0, 1), mu, rng_uniform(&rng));
        check_leave(f, (uint32_t)(i & 1), p, dir);
    }
}

/* Thread safety: the same rays from many threads give the same hits. */
static void test_threads(void **state)
{
    fixture *f = *state;
    enum { N = 20000 };
    static accel_hit serial[N], parallel[N];
    static bool hs[N], hp[N];
    for (int pass = 0; pass < 2; pass++) {
#pragma omp parallel for num_threads(pass ? 2 : 1) schedule(dynamic, 64)
        for (int i = 0; i < N; i++) {
            rng_stream rng;
            rng_init(&rng, 3, 0, RNG_PURPOSE_TEST, (uint64_t)i);
            vec3 o =
                v3(8 * rng_uniform(&rng) - 4, 8 * rng_uniform(&rng) - 4, 1 + 8 * rng_uniform(&rng));
            vec3 d = v3_normalize(
                v3(rng_uniform(&rng) - 0.5, rng_uniform(&rng) - 0.5, rng_uniform(&rng) - 0.5));
            if (pass == 0)
                hs[i] = accel_intersect(f->acc, o, d, INFINITY, ACCEL_NO_OBJECT, 0, &serial[i]);
            else
                hp[i] = accel_intersect(f->acc, o, d, INFINITY, ACCEL_NO_OBJECT, 0, &parallel[i]);
        }
    }
    for (int i = 0; i < N; i++) {
        assert_true(hs[i]); /* a closed room: every ray hits */
        assert_int_equal(hs[i], hp[i]);
        assert_int_equal(serial[i].object, parallel[i].object);
        assert_int_equal(serial[i].triangle, parallel[i].triangle);
        assert_true(serial[i].distance_m == parallel[i].distance_m);
    }
}

/* The offset is the hit's own, not the scene's: two rectangles `gap` apart near the
 * origin, with a room 2 km across (its offset was 1e-6 of the diagonal, 3.5 mm) or a
 * small box 1e7 m away (16 float epsilons of that coordinate, 19 m) in the scene: a ray
 * leaving the lower one upwards hits the upper one at the gap. */
static void check_gap_in(double gap, bool far_box)
{
    thz_scene *s = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t lower = ps_object(s, OBJECT_SOLID, m, 300, 0, true);
    ps_face(s, lower, v3(0.3, -0.2, 0.5), v3(0.1, 0, 0), v3(0, 0.1, 0));
    size_t upper = ps_object(s, OBJECT_SOLID, m, 300, 0, true);
    ps_face(s, upper, v3(0.3, -0.2, 0.5 + gap), v3(0, 0.1, 0), v3(0.1, 0, 0));
    size_t room = ps_object(s, OBJECT_SOLID, m, 300, 0, false);
    if (far_box) {
        ps_box(s, room, v3(-5, -5, -5), v3(5, 5, 5), true);
        size_t box = ps_object(s, OBJECT_SOLID, m, 300, 0, false);
        ps_box(s, box, v3(1e7, 0, 0), v3(1e7 + 1, 1, 1), false);
    } else {
        ps_box(s, room, v3(-1000, -1000, -1000), v3(1000, 1000, 1000), true);
    }
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    /* from both triangles of the lower rectangle, straight up and at 37 and 82 degrees */
    const vec3 points[] = {v3(0.27, -0.22, 0.5), v3(0.33, -0.18, 0.5)};
    const vec3 dirs[] = {v3(0, 0, 1), v3(0.6, 0, 0.8), v3(0, -0.99, sqrt(1 - 0.99 * 0.99))};
    uint32_t first = 0;
    for (size_t k = 0; k < 2; k++) {
        accel_hit from, h;
        assert_true(accel_intersect(acc, v3(points[k].x, points[k].y, 0.4), v3(0, 0, 1), INFINITY,
                                    ACCEL_NO_OBJECT, 0, &from));
        assert_int_equal(from.object, lower);
        if (k == 1) /* one point on each */
            assert_int_not_equal(from.triangle, first);
        first = from.triangle;
        from.position_m = points[k];
        for (size_t i = 0; i < sizeof dirs / sizeof *dirs; i++) {
            vec3 o = accel_offset_origin(acc, &from, dirs[i]);
            assert_true(o.z > points[k].z && o.z - points[k].z < 0.25 * gap);
            assert_true(
                accel_intersect(acc, o, dirs[i], INFINITY, (uint32_t)lower, from.triangle, &h));
            assert_int_equal(h.object, upper);
            assert_float_equal(h.distance_m * dirs[i].z, gap, 0.3 * gap);
        }
    }
    accel_destroy(acc);
    scene_destroy(s);
}

/* A ray whose origin, rounded to single precision, lies on a wall of a closed room 3 km
 * from the origin (as one leaving near a concave corner does) and heads into the room:
 * it met that wall's back at t = 0 (radiance 0: a furnace's pixels read up to 3.7 K
 * low); it goes on to the far wall's front, also at a grazing angle. */
static void test_back_of_the_wall_it_starts_on(void **state)
{
    (void)state;
    thz_scene *s = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(s, 0.1, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, m, 300, 0, false);
    ps_box(s, room, v3(2995, -5, -5), v3(3005, 5, 5), true);
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    accel_hit h;
    vec3 dir = v3_normalize(v3(-0.6, 0.1, 0.8));
    assert_true(accel_intersect(acc, v3(3005.0, 0.3, 0.2), dir, INFINITY, ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.side, 0);
    assert_true(h.distance_m > 1.0);
    /* The same at a grazing angle (cos 0.01), its origin one float step (2^-12 m) behind the
     * wall: the wall's back lies 2.4 cm along the ray, beyond the 1.1 cm (32 float epsilons
     * at 3 km) allowed for the origin's rounding, though its plane lies within them; a side
     * wall's front is met all the same. */
    vec3 graze = v3_normalize(v3(-0.01, 0.6, 0.8));
    assert_true(accel_intersect(acc, v3(3005.0 + 1.0 / 4096.0, 0.3, 0.2), graze, INFINITY,
                                ACCEL_NO_OBJECT, 0, &h));
    assert_int_equal(h.side, 0);
    assert_true(h.distance_m > 1.0);
    accel_destroy(acc);
    scene_destroy(s);
}

/* Rays through a closed box's silhouette edges, from a point level with the box's middle
 * (x and z of the edges in a ratio that single precision keeps): each meets the face
 * before the edge or passes; none is given the back of the face behind it (such pixels
 * read 0 K and blamed the mesh's normals). */
static void test_silhouette_edge(void **state)
{
    (void)state;
    thz_scene *s = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, m, 290, 0, false);
    ps_box(s, room, v3(-4, -4, -4), v3(4, 4, 4), true);
    size_t box = ps_object(s, OBJECT_SOLID, m, 310, 0, false);
    ps_box(s, box, v3(-1.25, -0.05, -0.25), v3(-0.75, 0.45, 0.25), false);
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    const vec3 origin = v3(0, -2, 0);
    int backs = 0, fronts = 0;
    for (int i = 0; i <= 400; i++) {
        double y = -0.05 + 0.5 * i / 400.0;
        for (int top = 0; top < 2; top++) { /* the +x face's top and bottom edges */
            vec3 dir = v3_normalize(v3_sub(v3(-0.75, y, top ? 0.25 : -0.25), origin));
            accel_hit h;
            assert_true(accel_intersect(acc, origin, dir, INFINITY, ACCEL_NO_OBJECT, 0, &h));
            backs += h.side == 1;
            fronts += h.object == box && h.side == 0;
        }
    }
    assert_int_equal(backs, 0);
    assert_true(fronts > 0); /* the edges are met, not all passed by */
    accel_destroy(acc);
    scene_destroy(s);
}

/* A ray from behind a one-sided plate through the edge its two triangles share (the
 * inside of the plate) meets the plate's back there: the recast that looks for a face
 * met from its front at the edge (test_silhouette_edge) looks no farther than the edge,
 * and keeps the back face when it finds none (not the room's ceiling 3 m on). */
static void test_back_of_a_plate_on_its_inner_edge(void **state)
{
    (void)state;
    thz_scene *s = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t room = ps_object(s, OBJECT_SOLID, m, 290, 0, false);
    ps_box(s, room, v3(-4, -4, -4), v3(4, 4, 4), true);
    size_t plate = ps_object(s, OBJECT_SOLID, m, 310, 0, false);
    ps_face(s, plate, v3(0, 0, 1), v3(1, 0, 0), v3(0, 1, 0)); /* normal +z */
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    const double on_diagonal[] = {-0.5, 0.25, 0.75};
    for (size_t i = 0; i < sizeof on_diagonal / sizeof *on_diagonal; i++) {
        double a = on_diagonal[i];
        accel_hit h;
        assert_true(
            accel_intersect(acc, v3(a, a, 0), v3(0, 0, 1), INFINITY, ACCEL_NO_OBJECT, 0, &h));
        assert_int_equal(h.object, plate);
        assert_int_equal(h.side, 1);
        assert_float_equal(h.distance_m, 1.0, 1e-9);
    }
    accel_destroy(acc);
    scene_destroy(s);
}

/* The offset exceeds single precision's rounding of the hit's largest coordinate (Embree
 * takes the origin in single precision) whichever axis holds it: hits 3 km out along x,
 * y and z on a face normal to z are lifted by more than 4 float steps (2.4e-4 m each),
 * and by less than a centimetre. */
static void test_offset_beyond_rounding(void **state)
{
    fixture *f = *state;
    const vec3 points[] = {v3(3000.3, 0.2, 0.5), v3(0.3, -3000.2, 0.5), v3(0.3, 0.2, 3000.5)};
    for (size_t i = 0; i < sizeof points / sizeof *points; i++) {
        accel_hit from = at((uint32_t)f->lower, 0, points[i]);
        vec3 o = accel_offset_origin(f->acc, &from, v3(0, 0, 1));
        double step = ldexp(1.0, -12); /* float spacing from 2048 to 4096 */
        assert_true(o.z - points[i].z > 4.0 * step);
        assert_true(o.z - points[i].z < 0.01);
        assert_true(o.x == points[i].x && o.y == points[i].y);
    }
}

static void test_offset_is_the_hits(void **state)
{
    (void)state;
    check_gap_in(2e-3, false);
    check_gap_in(1e-4, true);
}

/* A ray at a grazing angle (|cos| < 0.01) to a tilted plate 6 m across meets it where it
 * meets the plane of the triangle's corners, to double precision: for such rays accel.c
 * takes that plane from the corners, not from the normal rounded to float, which tilts it
 * by ~1e-7 rad and slides the point along the ray by ~1e-7 of the plate's size over |cos|
 * (0.1 mm here at cos 0.003). Without that branch (a mutant) every test passed. */
static void test_grazing_point_on_the_corners_plane(void **state)
{
    (void)state;
    thz_scene *s = ps_scene(0.35, 0.01, 1000, 1);
    size_t m = ps_material(s, 0.0, 0.0, -1.0, TRANSMISSION_DIFFUSE);
    size_t plate = ps_object(s, OBJECT_SOLID, m, 300, 0, true);
    ps_face(s, plate, v3(1.0, 2.0, 3.0), v3(3.0, 0.3, 0.7), v3(-0.2, 2.9, 1.3));
    ps_finalize(s);
    accel *acc;
    thz_error err;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    const thz_mesh *mesh = &s->objects[plate].mesh;
    double worst = 0.0;
    for (uint32_t tri = 0; tri < 2; tri++) {
        const uint32_t *idx = &mesh->indices[3 * tri];
        vec3 p0 = v3_from_floats(&mesh->positions[3 * (size_t)idx[0]]);
        vec3 p1 = v3_from_floats(&mesh->positions[3 * (size_t)idx[1]]);
        vec3 p2 = v3_from_floats(&mesh->positions[3 * (size_t)idx[2]]);
        vec3 n = v3_normalize(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
        /* far corners of the triangle, where a tilted plane through p0 is furthest off */
        vec3 target = v3_add(v3_scale(p0, 0.1), v3_add(v3_scale(p1, 0.45), v3_scale(p2, 0.45)));
        vec3 e1 = v3_normalize(v3_sub(p1, p0)), e2 = v3_normalize(v3_cross(n, e1));
        const double mus[] = {0.009, 0.003, 0.001};
        for (size_t i = 0; i < sizeof mus / sizeof mus[0]; i++)
            for (int a = 0; a < 8; a++) {
                double phi = a * M_PI / 4.0 + 0.3, mu = mus[i], st = sqrt(1.0 - mu * mu);
                vec3 along = v3_add(v3_scale(e1, cos(phi)), v3_scale(e2, sin(phi)));
                /* from the front side (n), down onto the target, 0.2 m away */
                vec3 dir = v3_sub(v3_scale(along, st), v3_scale(n, mu));
                vec3 o = v3_madd(target, -0.2, dir);
                accel_hit h;
                assert_true(accel_intersect(acc, o, dir, INFINITY, ACCEL_NO_OBJECT, 0, &h));
                assert_int_equal(h.object, plate);
                double off = v3_length(v3_sub(h.position_m, target));
                worst = off > worst ? off : worst;
                assert_true(off <= 1e-10);
                assert_float_equal(h.distance_m, 0.2, 1e-10);
            }
    }
    printf("# grazing hits: the farthest %.2e m from where the ray meets the corners' plane\n",
           worst);
    accel_destroy(acc);
    scene_destroy(s);
}

/* THZMAP_EMBREE_MAX_ISA (docs/scene-format.md "Reproducibility"): unset or empty, the cap
 * is AVX2, so that every processor with AVX2 runs the same kernels; each of Embree's
 * names is taken as it is; anything else is refused, naming the variable. */
static void test_max_isa(void **state)
{
    (void)state;
    const char *isa = NULL;
    thz_error err;
    assert_int_equal(unsetenv("THZMAP_EMBREE_MAX_ISA"), 0);
    assert_int_equal(accel_max_isa(&isa, &err), THZ_OK);
    assert_string_equal(isa, "avx2");
    const char *names[] = {"sse2", "sse4.2", "avx", "avx2", "avx512", ""};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        assert_int_equal(setenv("THZMAP_EMBREE_MAX_ISA", names[i], 1), 0);
        isa = NULL;
        assert_int_equal(accel_max_isa(&isa, &err), THZ_OK);
        assert_string_equal(isa, names[i][0] ? names[i] : "avx2");
    }
    const char *bad[] = {"avx5", "AVX2", "sse4", "avx2 "};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(setenv("THZMAP_EMBREE_MAX_ISA", bad[i], 1), 0);
        assert_int_equal(accel_max_isa(&isa, &err), THZ_ERR_INPUT);
        assert_non_null(strstr(err.message, "THZMAP_EMBREE_MAX_ISA"));
    }
    assert_int_equal(unsetenv("THZMAP_EMBREE_MAX_ISA"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_hit_side_and_distance, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ignored_closest, setup, teardown),
        cmocka_unit_test_setup_teardown(test_thin_shell_normal_and_grazing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_shared_edge, setup, teardown),
        cmocka_unit_test_setup_teardown(test_threads, setup, teardown),
        cmocka_unit_test(test_offset_is_the_hits),
        cmocka_unit_test_setup_teardown(test_offset_beyond_rounding, setup, teardown),
        cmocka_unit_test(test_back_of_a_plate_on_its_inner_edge),
        cmocka_unit_test(test_back_of_the_wall_it_starts_on),
        cmocka_unit_test(test_silhouette_edge),
        cmocka_unit_test(test_grazing_point_on_the_corners_plane),
        cmocka_unit_test(test_max_isa),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
