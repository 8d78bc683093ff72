/* Plausibility checks of a loaded scene: the mistakes that load without an error and
 * give wrong answers that look right (temperatures in degrees Celsius, a mesh in
 * millimetres in a room in metres, GHz given as THz, a sensor outside the enclosure or
 * inside a solid, a solid whose normals point inwards, an object outside the room,
 * non-emitting absorbing air, a background no ray can see). Each adds
 * a scene warning (validate prints them; simulate prints and records them).
 *
 * Geometry is judged from the meshes alone: an object is closed when every edge (by
 * vertex position) is shared by exactly two triangles; a closed object with inward
 * normals (negative signed volume) is an enclosure; a point is inside a closed mesh
 * when a ray from it crosses the mesh an odd number of times.
 */
#ifndef THZ_SCENE_SCENE_CHECKS_H
#define THZ_SCENE_SCENE_CHECKS_H

#include <stdbool.h>
#include <stddef.h>

#include "scene/scene.h"

/* Frequencies thzmap's models are meant for; channels outside get a warning. */
#define SCENE_CHECK_MIN_THZ 0.05
#define SCENE_CHECK_MAX_THZ 10.0
/* An object whose bounding box diagonal exceeds this times the enclosure's (or, without
 * one, the median object's) is taken for a unit mistake. */
#define SCENE_CHECK_SCALE_RATIO 100.0
/* An object (not an enclosure) larger than this times the enclosure around the sensors
 * cannot stand in it: a 0.2 m slab drawn in millimetres in a room 7.7 m across is 32
 * times the room, which the ratio of 100 let pass. */
#define SCENE_CHECK_ENCLOSURE_RATIO 10.0
/* A scene farther from the origin than about 8 times its size: the single-precision step
 * of its coordinates exceeds this fraction of its bounding box's diagonal. A closed room
 * 10 m across at 300 K read 300 K in every pixel 100 m from the origin (16 seeds); 1 km
 * out 2 of 16 seeds had a pixel off, 3 km out 15, by up to 3.7 K (rays leaving near a
 * concave corner, rounded to single precision, started behind the next wall), and 2 of
 * 16 by up to 2.4 K once accel_intersect looked past such a wall (a hit point past its
 * triangle's edge by that rounding, the ray then started outside the room). */
#define SCENE_CHECK_PRECISION 1e-6

/* What the loader knew of the atmosphere block, beyond the scene. */
typedef struct scene_check_inputs {
    bool non_emitting_air; /* "emitting": false given */
    bool background_given; /* background_temperature_k given */
} scene_check_inputs;

/* What the checks know of each object's mesh: closed or not, its signed volume, its size.
 * Computed once per load (scene_checks_objects): the closedness sorts every edge, seconds
 * for millions of triangles. */
typedef struct check_object check_object;

/* Per object of scene, for the two calls below while its meshes stay as they are; NULL on
 * allocation failure. Freed with free(). */
check_object *scene_checks_objects(const thz_scene *scene);

/* The innermost enclosure containing every sensor, or SIZE_MAX when there is none (then
 * rays can leave the scene). */
size_t scene_checks_enclosure(const thz_scene *scene, const check_object *info);

/* Writes into buf (of size bytes) "; channel \"NAME\" is at F THz, beyond the 0.05 to 10
 * THz thzmap's models are meant for: frequency_thz is in THz (F GHz = f THz)" for the first
 * channel beyond SCENE_CHECK_MAX_THZ, else "": a refusal that comes before validate's
 * warning about such channels (a GHz value given in THz) appends it, since it hides the
 * warning. */
void scene_checks_ghz_hint(const thz_scene *scene, char *buf, size_t size);

/* Writes into buf " (a table beyond 10 THz: are its frequencies in GHz? ...)" when a table
 * starting at table_lo_hz lies wholly beyond SCENE_CHECK_MAX_THZ while the channel at
 * centre_hz that leaves it lies within (a GHz column headed frequency_thz), else "": for
 * the warnings that a channel's band leaves a table. */
void scene_checks_ghz_table_hint(double table_lo_hz, double centre_hz, char *buf, size_t size);

/* Adds the warnings (and marks misplaced sensors); enclosure: scene_checks_enclosure's.
 * False only on allocation failure. */
bool scene_checks_run(thz_scene *scene, const check_object *info, size_t enclosure,
                      const scene_check_inputs *in);

#endif
