/* The files the `lines` model reads (atm_lines.c), read once per process: a sequence's
 * frames each load their scene, and each frame read and parsed the same catalogues again
 * (0.25 s a frame, nine tenths of a `lines` scene's load). atm_inputs_acquire hands out
 * the inputs read from a set of paths, shared and read-only, from a cache of the last
 * ATM_INPUTS_CACHED sets (about 6 MB each); a file is read again when its device, inode,
 * size or modification time differ from those it was read with. Thread-safe. Internal to
 * src/atmosphere/. */
#ifndef THZ_ATMOSPHERE_ATM_INPUTS_H
#define THZ_ATMOSPHERE_ATM_INPUTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "atmosphere/atm_catalog.h"
#include "core/error.h"

#define ATM_INPUTS_CACHED 2

/* The files, in this order; the continuum's path is "" when the model has none. */
enum {
    ATM_IN_H2O,
    ATM_IN_O2,
    ATM_IN_O2_COUPLED,
    ATM_IN_Q_H2O,
    ATM_IN_Q_O2,
    ATM_IN_CONTINUUM,
    ATM_IN_FILES
};

/* What they hold, as read. */
typedef struct atm_inputs {
    raw_catalog h2o, o2, o2_coupled; /* o2 without the lines the coupled table has */
    partition_sums q_h2o, q_o2;
    /* MT_CKD on a uniform grid from 0 in steps of cont_step_cm1 (n_cont 0: none) */
    size_t n_cont;
    double cont_step_cm1;
    double *c_foreign, *c_self, *self_texp;
    uint64_t read_id; /* the read's number in this process, 1 up: another for every read
                         (what the tables cached from these inputs are keyed by) */
} atm_inputs;

/* The inputs read from paths (each a regular file the caller has checked), valid until
 * atm_inputs_release(*out). On failure the message names the file (and line). */
thz_status atm_inputs_acquire(const char *const paths[ATM_IN_FILES], const atm_inputs **out,
                              thz_error *err);
void atm_inputs_release(const atm_inputs *in);

#endif
