/* Object transforms (scene-format.md "objects"): scale, then rotations about x, y and
 * z, then translation, as one affine map p' = M p + t in double precision. A map
 * with a negative determinant (an odd number of negative scale factors) mirrors the
 * object; applying it to a mesh then reverses every triangle's winding so that the
 * normals, which follow the winding, still point outwards.
 */
#ifndef THZ_SCENE_TRANSFORM_H
#define THZ_SCENE_TRANSFORM_H

#include <stdbool.h>

#include "scene/scene.h"

typedef struct scene_transform {
    double m[3][3]; /* linear part, row-major: p'_i = sum_j m[i][j] p_j + t_i */
    double translate_m[3];
} scene_transform;

/* The identity map. */
scene_transform transform_identity(void);

/* The map scale -> rotate about x by rotate_deg[0] -> about y by rotate_deg[1] ->
 * about z by rotate_deg[2] -> translate. Rotations are right-handed (counter-clockwise
 * seen from the positive axis). */
scene_transform transform_make(const double scale[3], const double rotate_deg[3],
                               const double translate_m[3]);

/* out = T(p); out may alias p. */
void transform_apply_point(const scene_transform *t, const double p[3], double out[3]);

/* Determinant of the linear part; negative for a mirroring map. */
double transform_determinant(const scene_transform *t);

/* Maps every vertex of mesh (positions only) and, if the map mirrors, reverses the
 * winding of every triangle. Call mesh_finalize afterwards for normals and areas. */
void transform_apply_mesh(const scene_transform *t, thz_mesh *mesh);

#endif
