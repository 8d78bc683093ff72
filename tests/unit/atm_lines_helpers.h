/* What the `lines` model's unit tests share (test_atm_lines.c, test_atm_lines_tables.c):
 * the ITU-R reference air and a lines atmosphere that must initialise. Header-only
 * (static inline), as scene_load_helpers.h. */
#ifndef THZ_TESTS_ATM_LINES_HELPERS_H
#define THZ_TESTS_ATM_LINES_HELPERS_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "atmosphere/atm_internal.h"
#include "atmosphere/atmosphere.h"

/* The ITU-R validation conditions: 1013.25 hPa dry air, 288.15 K, 7.5 g/m^3. */
static inline atm_air_state reference_air(double rho_g_m3)
{
    atm_air_state air;
    thz_error err = {0};
    double t = 288.15, e = rho_g_m3 * t / 216.7;
    assert_int_equal(
        atm_air_state_init(&air, t, 1013.25 + e, ATM_HUMIDITY_DENSITY_G_M3, rho_g_m3, &err),
        THZ_OK);
    return air;
}

/* atm: the lines model of air with options o (NULL: the defaults); a refusal fails the
 * test. */
static inline void init_lines(thz_atmosphere *atm, const atm_air_state *air,
                              const atm_lines_options *o)
{
    thz_error err = {0};
    memset(atm, 0, sizeof *atm);
    thz_status st = atmosphere_init_lines(atm, air, o, &err);
    if (st != THZ_OK)
        fail_msg("%s", err.message);
}

#endif
