/* Fingerprints of everything in a scene that determines its photon maps, so that
 * `render` can refuse a photon map made from another scene (scene-format.md).
 *
 * Three 64-bit hashes, so that a refusal can say what differs:
 *  - geometry: every object's type, sidedness, thickness and mesh (vertex positions
 *    and triangle indices, bit for bit);
 *  - optics: every object's material index and temperature, every material's spectra
 *    (R, alpha_M, eps), transmission mode, lobe and complex index, the atmosphere
 *    (model, spectrum, air state, the prepared alpha tables of the line-by-line models,
 *    emission, extent);
 *  - channels: the channels' centres and widths, and measured responses' tables (nothing
 *    for a Gaussian, so that its hash is what it was before tables existed).
 * Names, colours, sensors, render settings and the photon count, seed and
 * min_relative_power are left out: they change neither what a photon map means nor
 * whether it fits the scene (a map fired with `--photons N` is valid for any render).
 * The hash is FNV-1a-like over 64-bit words with a final avalanche: for detecting
 * mistakes, not adversaries.
 */
#ifndef THZ_SCENE_SCENE_HASH_H
#define THZ_SCENE_SCENE_HASH_H

#include <stdbool.h>
#include <stdint.h>

#include "scene/scene.h"

typedef struct scene_hash {
    uint64_t geometry;
    uint64_t optics;
    uint64_t channels;
} scene_hash;

void scene_hash_compute(const thz_scene *scene, scene_hash *out);

/* Whether photon maps made from a scene of hashes `made`, n_objects objects and
 * n_channels channels fit `scene`: THZ_OK, else THZ_ERR_INPUT saying what differs (the
 * geometry, the channel count, the channels, or the materials, temperatures and
 * atmosphere), the message starting with `maps` (what the maps are, e.g. "photon map
 * PATH") and ending with `remedy`. The one test of "made from the same scene": a .thzpm
 * file's header against the scene rendering it, and photons fired or loaded for another
 * scene handle against the one thz_render_run is given. */
thz_status scene_hash_fit(const scene_hash *made, uint64_t n_objects, uint64_t n_channels,
                          const thz_scene *scene, const char *maps, const char *remedy,
                          thz_error *err);

/* The geometry's hash, the bulk of the work (every vertex and index, about 0.3 s for
 * 16.7 M triangles), is computed once per scene and kept in its memo: a scene's meshes
 * do not change after loading, and every photon phase, render channel and photon-map file
 * of an MPI run asks again. Safe when threads ask at once (they compute the same value).
 * NULL on allocation failure. */
struct scene_hash_memo *scene_hash_memo_create(void);
void scene_hash_memo_destroy(struct scene_hash_memo *memo);

/* One fingerprint of all that the processes of an MPI run must share to compute the same
 * photons and pixels: the three hashes above, the sensors' geometry and optics (size,
 * pose, field, oversampling, aperture, PSF) and the photon and render settings the
 * members use (not the photon count and seed, which the photon phase checks); the render
 * settings (integrator, gather rays, paths) only when `render`, so that a photon phase
 * shared by processes that would render differently reaches the render's own check. The lead sends
 * it with each request; a member whose scene differs refuses (else it would render other images, or
 * tiles of another size). */
uint64_t scene_hash_run(const thz_scene *scene, bool render);

#endif
