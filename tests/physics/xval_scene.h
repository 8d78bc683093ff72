/* The scene of the integrators' cross-validation and honesty tests (test_integrators.c)
 * and of the photon guide's (test_guide.c): reflective solids, a diffuse and a straight
 * shell and temperature contrasts in a room. */
#ifndef THZ_TESTS_PHYSICS_XVAL_SCENE_H
#define THZ_TESTS_PHYSICS_XVAL_SCENE_H

#include <stdint.h>
#include <stdio.h>

#define XVAL_JSON                                                                                  \
    "{\"format\": \"thzmap-scene/1\", \"name\": \"cross-validation\","                             \
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"                         \
    " \"materials\": {"                                                                            \
    "   \"wall\": {\"reflectivity\": 0.2},"                                                        \
    "   \"metal\": {\"reflectivity\": 0.7},"                                                       \
    "   \"grey\": {\"reflectivity\": 0.4},"                                                        \
    "   \"foam\": {\"reflectivity\": 0.1, \"attenuation_per_m\": 150, \"transmission\": "          \
    "\"diffuse\"},"                                                                                \
    "   \"film\": {\"reflectivity\": 0.1, \"attenuation_per_m\": 100, \"transmission\": "          \
    "\"straight\"}},"                                                                              \
    " \"objects\": ["                                                                              \
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 295," \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 2, 2], \"inward\": true}},"                \
    "   {\"name\": \"heater\", \"type\": \"solid\", \"material\": \"metal\", \"temperature_k\": "  \
    "340,"                                                                                         \
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.5, 0.3, 0.5]},"                             \
    "    \"transform\": {\"rotate_deg\": [0, 0, 30], \"translate_m\": [0.45, 0.5, 0.3]}},"         \
    "   {\"name\": \"cold\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 250," \
    "    \"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.2, \"height_m\": 0.9, \"caps\": "     \
    "true},"                                                                                       \
    "    \"transform\": {\"translate_m\": [-0.4, 0.5, -1.0]}},"                                    \
    "   {\"name\": \"sleeve\", \"type\": \"shell\", \"thickness_m\": 0.003, \"material\": "        \
    "\"foam\","                                                                                    \
    "    \"temperature_k\": 305,"                                                                  \
    "    \"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.25, \"height_m\": 0.5, \"caps\": "    \
    "false},"                                                                                      \
    "    \"transform\": {\"translate_m\": [-0.4, 0.5, -0.6]}},"                                    \
    "   {\"name\": \"veil\", \"type\": \"shell\", \"thickness_m\": 0.002, \"material\": \"film\"," \
    "    \"temperature_k\": 300, \"shape\": {\"type\": \"rectangle\", \"size_m\": [0.6, 0.6]},"    \
    "    \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [0.35, 0.0, 0.3]}}],"        \
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -0.9, 0], \"direction\": [0, 1, 0],"   \
    "   \"up\": [0, 0, 1], \"fov_deg\": 80, \"resolution\": [%u, %u], \"oversampling\": %u,"       \
    "   \"aperture_m2\": 0.01, \"normalize_to_k\": 295}],"                                         \
    " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": %g, \"emitting\": false},"  \
    " \"photons\": {\"per_channel\": 300000, \"seed\": %llu}}"

static inline void xval_scene(char *json, size_t size, uint32_t res, uint32_t oversampling,
                              double alpha_per_m, uint64_t seed)
{
    snprintf(json, size, XVAL_JSON, res, res, oversampling, alpha_per_m, (unsigned long long)seed);
}

#endif
