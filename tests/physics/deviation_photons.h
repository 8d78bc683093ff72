/* What the deviation-map tests share (test_deviation_photons.c: the T0 = 0 checksums, the
 * thread count and the memory estimate; test_deviation_power.c: the power each kind of
 * source fires): a photon-phase run of a scene's channel 0 with reference temperature
 * t0_k. Header-only (static inline), as photon_scenes.h. */
#ifndef THZ_TESTS_DEVIATION_PHOTONS_H
#define THZ_TESTS_DEVIATION_PHOTONS_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon_scenes.h"

static inline void fire(const thz_scene *s, double t0_k, int threads, photon_map **map,
                        photon_stats *st)
{
    ps_fire(s, &(photon_phase_options){.threads = threads, .reference_temperature_k = t0_k}, map,
            st);
}

#endif
