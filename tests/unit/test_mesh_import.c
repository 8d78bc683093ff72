/* Mesh import: the same tetrahedron from OBJ, PLY (ASCII, binary little- and big-endian)
 * and STL (ASCII and binary) gives 4 welded vertices, 4 triangles, the exact area and
 * outward normals; quads are triangulated; vertices of points and lines are dropped
 * and -0.0 welds with 0; the winding check finds a flipped face, the open-edge count a
 * hole; a format only assimp
 * reads (glTF) gives the same tetrahedron; missing, empty and garbage files and formats
 * assimp does not read either are refused with the file named; a large STL's weld puts
 * its positions in (x, y, z) order, each corner where it was, also after the process used
 * a team of OpenMP threads. The malformed-file corpus is tests/cli/test_bad_meshes.sh. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "core/order.h"
#include "scene/mesh_import.h"
#include "scene/mesh_import_internal.h"
#include "scene/primitives.h"
#include "scene/scene.h"

#define MESHES THZ_SOURCE_DIR "/tests/inputs/meshes/"

/* Unit right tetrahedron: three right triangles of area 1/2 and one equilateral
 * triangle of edge sqrt 2. */
/* The winding conflicts mesh_import_defects counts. */
static size_t winding_conflicts(const thz_mesh *m)
{
    mesh_defects d;
    assert_true(mesh_import_defects(m, &d));
    return d.winding_conflicts;
}

static const double tetra_area = 1.5 + 0.8660254037844386;

static void check_outward(const thz_mesh *m, const double centre[3])
{
    for (size_t t = 0; t < m->n_triangles; t++) {
        double c[3] = {0, 0, 0}, dot = 0;
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                c[k] += m->positions[3 * m->indices[3 * t + (size_t)v] + (size_t)k] / 3.0;
        for (int k = 0; k < 3; k++)
            dot += m->normals[3 * t + (size_t)k] * (c[k] - centre[k]);
        assert_true(dot > 0);
    }
}

static void check_tetra(const char *file, double z_offset)
{
    thz_mesh m;
    thz_error err = {0};
    thz_status st = mesh_import(file, NULL, &m, &err);
    if (st != THZ_OK)
        fail_msg("%s: %s", file, err.message);
    assert_true(mesh_finalize(&m));
    assert_int_equal(m.n_triangles, 4);
    assert_int_equal(m.n_vertices, 4);
    assert_true(fabs(m.total_area_m2 - tetra_area) < 1e-6);
    const double centre[3] = {0.25, 0.25, 0.25 + z_offset};
    check_outward(&m, centre);
    assert_int_equal(winding_conflicts(&m), 0);
    assert_true(fabs(m.bbox_min_m[2] - z_offset) < 1e-6);
    assert_true(fabs(m.bbox_max_m[2] - (1 + z_offset)) < 1e-6);
    for (int k = 0; k < 4; k++)
        assert_true(m.positions[3 * m.n_vertices + (size_t)k] == 0.0f);
    mesh_fini(&m);
}

static void test_formats(void **state)
{
    (void)state;
    check_tetra(MESHES "tetra.obj", 0);
    check_tetra(MESHES "tetra.ply", 0);
    check_tetra(MESHES "tetra_ascii.stl", 0);
    check_tetra(MESHES "tetra_binary.stl", 0);
    check_tetra(MESHES "tetra_binary_le.ply", 0);
    check_tetra(MESHES "tetra_binary_be.ply", 0);
    /* a format the mesh check does not cover, read by assimp alone (its node's
     * translation of 2 along z applied) */
    check_tetra(MESHES "tetra.gltf", 2.0);
    /* an OBJ with a UTF-8 byte-order mark (its first 'v' line was dropped) */
    char bom[] = "/tmp/thz-test-bom-XXXXXX.obj";
    int fd = mkstemps(bom, 4);
    assert_true(fd >= 0);
    FILE *out = fdopen(fd, "wb");
    assert_non_null(out);
    fputs("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
          out);
    fclose(out);
    check_tetra(bom, 0);
    unlink(bom);
}

static void test_quads(void **state)
{
    (void)state;
    thz_mesh m;
    thz_error err = {0};
    assert_int_equal(mesh_import(MESHES "cube_quads.obj", NULL, &m, &err), THZ_OK);
    assert_true(mesh_finalize(&m));
    assert_int_equal(m.n_triangles, 12);
    assert_true(fabs(m.total_area_m2 - 6.0) < 1e-6);
    const double centre[3] = {0.5, 0.5, 0.5};
    check_outward(&m, centre);
    assert_int_equal(winding_conflicts(&m), 0);
    mesh_fini(&m);
}

/* The example pyramid and the quad cube give what the importer gave before the mesh
 * check was added (vertices, triangles, bounding box and area recorded then). */
static void test_examples_unchanged(void **state)
{
    (void)state;
    const struct {
        const char *file;
        size_t vertices, triangles;
        double bbox[6], area_m2;
    } want[] = {
        {THZ_SOURCE_DIR "/examples/meshes/pyramid.obj", 5, 6, {-1, -1, 0, 1, 1, 1.5}, 11.2111026},
        {MESHES "cube_quads.obj", 8, 12, {0, 0, 0, 1, 1, 1}, 6.0},
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        thz_mesh m;
        thz_error err = {0};
        if (mesh_import(want[i].file, NULL, &m, &err) != THZ_OK)
            fail_msg("%s", err.message);
        assert_true(mesh_finalize(&m));
        assert_int_equal(m.n_vertices, want[i].vertices);
        assert_int_equal(m.n_triangles, want[i].triangles);
        for (int k = 0; k < 3; k++) {
            assert_true(m.bbox_min_m[k] == want[i].bbox[k]);
            assert_true(m.bbox_max_m[k] == want[i].bbox[3 + k]);
        }
        assert_true(fabs(m.total_area_m2 - want[i].area_m2) < 1e-6);
        mesh_fini(&m);
    }
}

static void test_bad_winding(void **state)
{
    (void)state;
    thz_mesh m;
    thz_error err = {0};
    assert_int_equal(mesh_import(MESHES "tetra_bad_winding.obj", NULL, &m, &err), THZ_OK);
    assert_int_equal(m.n_triangles, 4);
    /* the flipped face runs all three of its edges the same way as its neighbours */
    assert_int_equal(winding_conflicts(&m), 3);
    mesh_fini(&m);
}

/* A repeated triangle (either way round) and one of no area are counted as such; the
 * repeat is no winding conflict (it was reported as "inconsistent winding"). */
static void test_repeats_and_no_area(void **state)
{
    (void)state;
    char dir[] = "/tmp/thz-test-mesh-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/m.obj", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    /* a tetrahedron, one face twice (the second the other way round, as coincident faces
     * of a scan are), and a face whose corners lie on one line */
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 2 0 0\n"
          "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\nf 1 2 4\nf 1 4 2\nf 1 2 5\n",
          f);
    fclose(f);
    thz_mesh m;
    thz_error err = {0};
    if (mesh_import(path, NULL, &m, &err) != THZ_OK)
        fail_msg("%s", err.message);
    assert_true(mesh_finalize(&m));
    mesh_defects d;
    assert_true(mesh_import_defects(&m, &d));
    assert_int_equal(d.repeated, 2);
    assert_int_equal(d.degenerate, 1);
    assert_int_equal(d.winding_conflicts, 0);
    assert_int_equal(d.open_edges, 0); /* the repeats and the flat face leave it closed */
    mesh_fini(&m);
    unlink(path);
    rmdir(dir);
}

/* The open edges of `obj_text` (an OBJ file's text) as mesh_import_defects counts them. */
static size_t open_edges(const char *obj_text)
{
    char dir[] = "/tmp/thz-test-mesh-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/m.obj", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(obj_text, f);
    fclose(f);
    thz_mesh m;
    thz_error err = {0};
    if (mesh_import(path, NULL, &m, &err) != THZ_OK)
        fail_msg("%s", err.message);
    mesh_defects d;
    assert_true(mesh_import_defects(&m, &d));
    mesh_fini(&m);
    unlink(path);
    rmdir(dir);
    return d.open_edges;
}

/* Edges of one triangle only: a closed tetrahedron has none, one without its fourth face
 * the three of its rim, a lone triangle three, a square of two triangles four (the
 * diagonal is shared); a face wound the wrong way shares its edges all the same (a
 * winding conflict, not a hole). A 1.3 M-triangle OBJ cut at 30 MB of 49 was imported
 * with 454 061 triangles and no warning before these were counted. */
static void test_open_edges(void **state)
{
    (void)state;
    const char *v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    char text[256];
    snprintf(text, sizeof text, "%sf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n", v);
    assert_int_equal(open_edges(text), 0);
    snprintf(text, sizeof text, "%sf 1 3 2\nf 1 2 4\nf 2 3 4\n", v);
    assert_int_equal(open_edges(text), 3);
    snprintf(text, sizeof text, "%sf 1 2 3\n", v);
    assert_int_equal(open_edges(text), 3);
    assert_int_equal(open_edges("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n"), 4);
    snprintf(text, sizeof text, "%sf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 3 4\n", v);
    assert_int_equal(open_edges(text), 0);
}

/* Lexicographic order of two positions, as the weld defines it (floats compared). */
static int position_cmp(const float *x, const float *y)
{
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* 400,000 triangles of a binary STL (1.2 M corners, each its own vertex there) whose
 * coordinates come from 9 values, negatives and -0 among them: after the import every
 * position is unique and in (x, y, z) order, and each triangle's corners are the file's.
 * The process first sorts with a team of two OpenMP threads: the weld runs in the import's
 * forked child, where a team of two would wait for the parent's threads for ever (the
 * child would be killed at its time limit and the import fail). */
static void test_weld_order(void **state)
{
    (void)state;
    size_t nk = (size_t)1 << 21;
    uint64_t *keys = malloc(nk * sizeof *keys);
    assert_non_null(keys);
    uint64_t r = 12345;
    for (size_t i = 0; i < nk; i++) {
        r = r * 6364136223846793005u + 1442695040888963407u;
        keys[i] = r;
    }
    order_sort_u64_threads(keys, nk, 2);
    for (size_t i = 1; i < nk; i++)
        assert_true(keys[i - 1] <= keys[i]);
    free(keys);

    enum { NT = 400000 };
    static const float values[9] = {-2.5f, -1.0f, -0.0f, 0.0f, 1e-30f, 0.5f, 1.0f, 3.25f, 7.0f};
    float *corners = malloc((size_t)NT * 9 * sizeof *corners);
    assert_non_null(corners);
    char path[] = "/tmp/thz-test-weld-XXXXXX.stl";
    int fd = mkstemps(path, 4);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "wb");
    assert_non_null(f);
    char header[80] = {0};
    uint32_t n = NT;
    assert_int_equal(fwrite(header, 1, 80, f), 80);
    assert_int_equal(fwrite(&n, 4, 1, f), 1);
    for (size_t t = 0; t < NT; t++) {
        float rec[12] = {0}; /* the normal (0: assimp computes none from it), 3 corners */
        for (int j = 0; j < 9; j++) {
            r = r * 6364136223846793005u + 1442695040888963407u;
            rec[3 + j] = corners[9 * t + (size_t)j] = values[(r >> 33) % 9];
        }
        uint16_t attr = 0;
        assert_int_equal(fwrite(rec, sizeof rec, 1, f), 1);
        assert_int_equal(fwrite(&attr, 2, 1, f), 1);
    }
    assert_int_equal(fclose(f), 0);

    thz_mesh m;
    thz_error err = {0};
    if (mesh_import(path, NULL, &m, &err) != THZ_OK)
        fail_msg("%s", err.message);
    unlink(path);
    assert_int_equal(m.n_triangles, NT);
    assert_int_equal(m.n_vertices, 8 * 8 * 8); /* -0 and 0 one value: 8 a coordinate */
    for (size_t v = 1; v < m.n_vertices; v++)
        assert_true(position_cmp(&m.positions[3 * (v - 1)], &m.positions[3 * v]) < 0);
    for (size_t i = 0; i < 3 * m.n_vertices; i++)
        assert_false(signbit(m.positions[i]) && m.positions[i] == 0.0f);
    for (size_t t = 0; t < NT; t++)
        for (int c = 0; c < 3; c++)
            assert_int_equal(position_cmp(&m.positions[3 * (size_t)m.indices[3 * t + (size_t)c]],
                                          &corners[9 * t + 3 * (size_t)c]),
                             0);
    mesh_fini(&m);
    free(corners);
}

/* The weld itself merges a vertex at -0 with one at +0, leaving +0. The import never
 * hands it a -0 from the paper's formats (the node transform's + 0 makes it +0), so
 * dropping the weld's -0 -> +0 (a helper's mutant) passed every test through files: the
 * -0 corner sorts apart from the +0 one, with (-0, 5, 5) between, and stays a vertex of
 * its own (an open seam for the closedness check). */
static void test_weld_negative_zero(void **state)
{
    (void)state;
    thz_mesh m;
    thz_error err = {0};
    assert_int_equal(primitive_mesh_alloc(&m, 5, 2, &err), THZ_OK);
    const float p[15] = {-0.0f, 1, 2, -0.0f, 5, 5, 0.0f, 1, 2, 1, 0, 0, 9, 9, 9};
    memcpy(m.positions, p, sizeof p);
    const uint32_t t[6] = {0, 1, 3, 2, 3, 1}; /* vertex 4 unused: dropped */
    memcpy(m.indices, t, sizeof t);
    assert_true(mesh_import_weld(&m));
    assert_int_equal(m.n_vertices, 3);
    assert_int_equal(m.indices[0], m.indices[3]); /* the -0 corner is the +0 one */
    assert_int_equal(m.indices[1], m.indices[5]);
    assert_int_equal(m.indices[2], m.indices[4]);
    /* position order: (0, 1, 2), (0, 5, 5), (1, 0, 0), none at -0 */
    const float want[9] = {0, 1, 2, 0, 5, 5, 1, 0, 0};
    for (size_t i = 0; i < 9; i++) {
        assert_true(m.positions[i] == want[i]);
        assert_false(signbit(m.positions[i]));
    }
    assert_int_equal(m.indices[0], 0);
    mesh_fini(&m);
}

static void test_points_lines_negative_zero(void **state)
{
    (void)state;
    /* the extra vertices lie outside the unit cube; check_tetra checks 4 vertices, the
     * bounding box and outward normals */
    check_tetra(MESHES "tetra_points_lines.obj", 0);
    thz_mesh m;
    thz_error err = {0};
    assert_int_equal(mesh_import(MESHES "tetra_points_lines.obj", NULL, &m, &err), THZ_OK);
    for (size_t i = 0; i < 3 * m.n_vertices; i++)
        assert_false(signbit(m.positions[i]));
    mesh_fini(&m);
}

static void expect_refused(const char *file, const char *label, const char *what)
{
    thz_mesh m;
    thz_error err = {0};
    assert_int_equal(mesh_import(file, label, &m, &err), THZ_ERR_INPUT);
    if (!strstr(err.message, label) || !strstr(err.message, what))
        fail_msg("message '%s' lacks '%s' or '%s'", err.message, label, what);
    assert_null(m.positions);
    mesh_fini(&m);
}

static void test_refused(void **state)
{
    (void)state;
    expect_refused(MESHES "does_not_exist.obj", "does_not_exist.obj", "cannot open");
    expect_refused(MESHES "no_faces.obj", "no_faces.obj", "no triangles");
    expect_refused(MESHES "garbage.obj", "garbage.obj", "binary data");
    expect_refused(MESHES "tetra.xyz9", "tetra.xyz9",
                   "unsupported mesh format '.xyz9': thzmap reads Wavefront OBJ (.obj), PLY "
                   "(.ply) or STL (.stl), and the other formats assimp reads");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_formats),
        cmocka_unit_test(test_quads),
        cmocka_unit_test(test_examples_unchanged),
        cmocka_unit_test(test_bad_winding),
        cmocka_unit_test(test_repeats_and_no_area),
        cmocka_unit_test(test_open_edges),
        cmocka_unit_test(test_points_lines_negative_zero),
        cmocka_unit_test(test_weld_order),
        cmocka_unit_test(test_weld_negative_zero),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
