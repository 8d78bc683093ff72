/* The mesh file check's limits that the malformed-file corpus (tests/cli/test_bad_meshes.sh)
 * cannot hold in small files: the triangle count after triangulation (and its count for
 * good files), the largest polygon accepted, the total triangulation work, and a binary
 * STL over the triangle limit (a sparse file, mapped: only its header is read). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "scene/mesh_check.h"

#define MESHES THZ_SOURCE_DIR "/tests/inputs/meshes/"

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)size + 1);
    assert_int_equal(fread(buf, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    *n = (size_t)size;
    return buf;
}

static void test_good_files_counted(void **state)
{
    (void)state;
    const struct {
        const char *file;
        mesh_format format;
        uint64_t triangles;
    } good[] = {
        {MESHES "tetra.obj", MESH_FORMAT_OBJ, 4},
        {MESHES "cube_quads.obj", MESH_FORMAT_OBJ, 12},
        {MESHES "tetra_points_lines.obj", MESH_FORMAT_OBJ, 4},
        {MESHES "tetra.ply", MESH_FORMAT_PLY, 4},
        {MESHES "tetra_binary_le.ply", MESH_FORMAT_PLY, 4},
        {MESHES "tetra_binary_be.ply", MESH_FORMAT_PLY, 4},
        {MESHES "tetra_ascii.stl", MESH_FORMAT_STL, 4},
        {MESHES "tetra_binary.stl", MESH_FORMAT_STL, 4},
        {THZ_SOURCE_DIR "/examples/meshes/pyramid.obj", MESH_FORMAT_OBJ, 6},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        size_t n;
        char *data = slurp(good[i].file, &n);
        mesh_format f;
        thz_error err = {0};
        assert_int_equal(mesh_check_format(good[i].file, NULL, &f, &err), THZ_OK);
        assert_int_equal(f, good[i].format);
        uint64_t triangles = 0;
        if (mesh_check(data, n, f, good[i].file, &triangles, &err) != THZ_OK)
            fail_msg("%s", err.message);
        assert_int_equal(triangles, good[i].triangles);
        free(data);
    }
}

/* An OBJ of `polygons` faces of n vertices each (and n vertices). */
static char *polygon_obj(unsigned n, unsigned polygons, size_t *size)
{
    size_t cap = (size_t)n * 32 + (size_t)polygons * n * 6 + 64, len = 0;
    char *s = malloc(cap);
    for (unsigned i = 0; i < n; i++)
        len += (size_t)snprintf(s + len, cap - len, "v %u 0 0\n", i);
    for (unsigned p = 0; p < polygons; p++) {
        len += (size_t)snprintf(s + len, cap - len, "f");
        for (unsigned i = 0; i < n; i++)
            len += (size_t)snprintf(s + len, cap - len, " %u", i + 1);
        len += (size_t)snprintf(s + len, cap - len, "\n");
    }
    *size = len;
    return s;
}

static void test_polygon_limits(void **state)
{
    (void)state;
    size_t n;
    uint64_t triangles = 0;
    thz_error err = {0};
    /* the largest polygon accepted, and one more vertex refused */
    char *s = polygon_obj(MESH_MAX_POLYGON_VERTICES, 1, &n);
    assert_int_equal(mesh_check(s, n, MESH_FORMAT_OBJ, "big.obj", &triangles, &err), THZ_OK);
    assert_int_equal(triangles, MESH_MAX_POLYGON_VERTICES - 2);
    free(s);
    s = polygon_obj(MESH_MAX_POLYGON_VERTICES + 1, 1, &n);
    assert_int_equal(mesh_check(s, n, MESH_FORMAT_OBJ, "big.obj", NULL, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "a polygon of 1025 vertices"));
    free(s);
    /* 1000-gons: 268 fit in the work limit (268e6 <= 2^28 = 268.4e6), the 269th does not */
    s = polygon_obj(1000, 268, &n);
    assert_int_equal(mesh_check(s, n, MESH_FORMAT_OBJ, "many.obj", &triangles, &err), THZ_OK);
    assert_int_equal(triangles, 268u * 998u);
    free(s);
    s = polygon_obj(1000, 269, &n);
    assert_int_equal(mesh_check(s, n, MESH_FORMAT_OBJ, "many.obj", NULL, &err), THZ_ERR_INPUT);
    if (!strstr(err.message, "many.obj:1269:") || !strstr(err.message, "269000000 vertex pairs"))
        fail_msg("%s", err.message);
    free(s);
}

/* A binary STL whose size matches a count just over the triangle limit: refused by its
 * header alone. The file is sparse and mapped, so it costs neither disk nor memory. */
static void test_stl_triangle_limit(void **state)
{
    (void)state;
    char path[] = "/tmp/thz-mesh-check-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    uint64_t count = (uint64_t)MESH_MAX_TRIANGLES + 1;
    size_t size = (size_t)(84 + 50 * count);
    unsigned char header[84] = "binary STL";
    for (int i = 0; i < 4; i++)
        header[80 + i] = (unsigned char)(count >> (8 * i));
    assert_int_equal(write(fd, header, sizeof header), (ssize_t)sizeof header);
    assert_int_equal(ftruncate(fd, (off_t)size), 0);
    const char *data = mmap(NULL, size, PROT_READ, MAP_PRIVATE, fd, 0);
    assert_true(data != MAP_FAILED);
    thz_error err = {0};
    assert_int_equal(mesh_check(data, size, MESH_FORMAT_STL, "huge.stl", NULL, &err),
                     THZ_ERR_INPUT);
    if (!strstr(err.message, "huge.stl: byte 80: 16777217 triangles, more than the limit of "
                             "16777216"))
        fail_msg("%s", err.message);
    munmap((void *)(uintptr_t)data, size);
    close(fd);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_files_counted),
        cmocka_unit_test(test_polygon_limits),
        cmocka_unit_test(test_stl_triangle_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
