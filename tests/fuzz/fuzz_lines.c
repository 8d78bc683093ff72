/* Fuzzes the `lines` atmosphere's file readers (src/atmosphere/atm_catalog.c and the
 * continuum's in atm_lines.c, through atm_lines_create): the first byte of the input picks
 * which file the rest replaces (below); the other files are the small fixtures of
 * tests/fuzz/data/atmosphere/. An accepted set is then evaluated across the model's
 * frequency range.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere/atm_internal.h"
#include "atmosphere/atmosphere.h"
#include "fuzz.h"

#define FIXTURE FUZZ_DIR "/data/atmosphere/"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_use_fixture_data();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    /* role of the input: the file name's extension chooses the reader (.par or CSV) */
    static const char *const names[] = {"h2o.csv", "h2o.par",  "o2.csv",  "o2.par",
                                        "o2c.csv", "qh2o.csv", "qo2.csv", "cont.csv"};
    enum { N_ROLES = sizeof names / sizeof names[0] };
    unsigned role = data[0] % N_ROLES;
    const char *path = fuzz_temp_file(names[role], data + 1, size - 1);

    atm_lines_options opt;
    atmosphere_lines_options_default(&opt);
    opt.h2o_lines_file = FIXTURE "am14_h2o_lines.csv";
    opt.o2_lines_file = FIXTURE "am14_o2_lines_uncoupled.csv";
    opt.o2_coupled_lines_file = FIXTURE "am14_o2_lines_coupled.csv";
    opt.h2o_partition_sums_file = FIXTURE "am14_h2o_partition_sums_tips2021.csv";
    opt.o2_partition_sums_file = FIXTURE "am14_o2_partition_sums_tips2021.csv";
    opt.continuum_file = FIXTURE "mt_ckd_4.2_h2o_continuum_0-520cm-1.csv";
    const char **slot[] = {&opt.h2o_lines_file,         &opt.h2o_lines_file,
                           &opt.o2_lines_file,          &opt.o2_lines_file,
                           &opt.o2_coupled_lines_file,  &opt.h2o_partition_sums_file,
                           &opt.o2_partition_sums_file, &opt.continuum_file};
    *slot[role] = path;

    thz_error err = {0};
    atm_air_state air;
    if (atm_air_state_init(&air, 288.15, 1013.25, ATM_HUMIDITY_RELATIVE, 0.5, &err) != THZ_OK)
        abort();
    thz_atmosphere atm;
    memset(&atm, 0, sizeof atm);
    thz_status st = atmosphere_init_lines(&atm, &air, &opt, &err);
    if (st != THZ_OK) {
        fuzz_report(err.message);
        if (!err.message[0])
            abort();
        return 0;
    }
    /* Direct evaluation across the model's range, not atmosphere_prepare: tabulating a
     * band costs up to 4e6 evaluations by design, however the lines were read (see
     * docs/reliability.md, "Fuzzing"); the scene harness reaches it. The band evaluator
     * below is what the tables are filled from. */
    volatile double sink = 0.0;
    for (double f = 1e9; f < 15e12; f *= 1.7)
        sink += atmosphere_alpha_direct_per_m(&atm, f);
    sink += atm_lines_grid_step_hz(atm.lines, 0.3e12, 0.4e12); /* the table's first step */
    /* what the tables are filled from (atm_lines_band.c): the lines split into near and
     * far ones, fitted over the band and a few pieces; in and beyond the band */
    atm_lines_band *band = NULL;
    if (atm_lines_band_create(atm.lines, 0.3e12, 0.4e12, 2000, &band, &err) == THZ_OK) {
        for (double f = 0.28e12; f < 0.42e12; f += 0.0113e12)
            sink += atm_lines_band_alpha_per_m(band, f);
        atm_lines_band_destroy(band);
    } else if (!err.message[0]) {
        abort();
    }
    (void)sink;
    atm_alpha_parts parts;
    atmosphere_alpha_parts(&atm, 0.5e12, &parts);
    atmosphere_fini(&atm);
    return 0;
}
