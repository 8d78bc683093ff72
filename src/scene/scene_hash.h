/* Fingerprints of everything in a scene that determines its photon maps, so that
 * `render` can refuse a photon map made from another scene (scene-format.md).
 *
 * Three 64-bit hashes, so that a refusal can say what differs:
 *  - geometry: every object's type, sidedness, thickness and mesh (vertex positions
 *    and triangle indices, bit for bit);
 *  - optics: every object's material index and temperature, every material's spectra
 *    (R, alpha_M, eps) and transmission mode, the atmosphere (model, spectrum, air
 *    state, the prepared alpha tables of the line-by-line models, emission, extent);
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

#include <stdint.h>

#include "scene/scene.h"

typedef struct scene_hash {
    uint64_t geometry;
    uint64_t optics;
    uint64_t channels;
} scene_hash;

void scene_hash_compute(const thz_scene *scene, scene_hash *out);

#endif
