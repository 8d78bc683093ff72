/* Object transforms: composition of scale, rotations and translation, and their
 * application to meshes (with the winding flip for mirroring maps). */
#include "scene/transform.h"

#include <math.h>
#include <string.h>

#include "scene/primitives.h"

scene_transform transform_identity(void)
{
    scene_transform t;
    memset(&t, 0, sizeof t);
    for (int i = 0; i < 3; i++)
        t.m[i][i] = 1.0;
    return t;
}

static void transform_matmul(double out[3][3], double a[3][3], double b[3][3])
{
    double r[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    memcpy(out, r, sizeof r);
}

/* Rotation by deg about axis (0 x, 1 y, 2 z), right-handed. Exact for multiples of
 * 90 degrees, so that axis-aligned scenes stay exactly axis-aligned. */
static void transform_rotation(double r[3][3], int axis, double deg)
{
    double c, s;
    double q = deg / 90.0;
    if (q == floor(q)) {
        long k = ((long)fmod(q, 4.0) + 4) % 4;
        static const double cs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
        c = cs[k][0];
        s = cs[k][1];
    } else {
        double a = deg * M_PI / 180.0;
        c = cos(a);
        s = sin(a);
    }
    memset(r, 0, 9 * sizeof r[0][0]);
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    r[axis][axis] = 1.0;
    r[i][i] = c;
    r[i][j] = -s;
    r[j][i] = s;
    r[j][j] = c;
}

scene_transform transform_make(const double scale[3], const double rotate_deg[3],
                               const double translate_m[3])
{
    scene_transform t = transform_identity();
    for (int i = 0; i < 3; i++)
        t.m[i][i] = scale[i];
    for (int axis = 0; axis < 3; axis++) {
        double r[3][3];
        transform_rotation(r, axis, rotate_deg[axis]);
        transform_matmul(t.m, r, t.m); /* later rotations act on the earlier result */
    }
    for (int i = 0; i < 3; i++)
        t.translate_m[i] = translate_m[i];
    return t;
}

void transform_apply_point(const scene_transform *t, const double p[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = t->m[i][0] * p[0] + t->m[i][1] * p[1] + t->m[i][2] * p[2] + t->translate_m[i];
    memcpy(out, r, sizeof r);
}

double transform_determinant(const scene_transform *t)
{
    const double(*m)[3] = (const double(*)[3])t->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

void transform_apply_mesh(const scene_transform *t, thz_mesh *mesh)
{
    for (size_t v = 0; v < mesh->n_vertices; v++) {
        float *p = &mesh->positions[3 * v];
        double d[3] = {p[0], p[1], p[2]};
        transform_apply_point(t, d, d);
        for (int k = 0; k < 3; k++)
            p[k] = primitive_to_float(d[k]);
    }
    if (transform_determinant(t) < 0.0) {
        for (size_t i = 0; i < mesh->n_triangles; i++) {
            uint32_t tmp = mesh->indices[3 * i + 1];
            mesh->indices[3 * i + 1] = mesh->indices[3 * i + 2];
            mesh->indices[3 * i + 2] = tmp;
        }
    }
}
