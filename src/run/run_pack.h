/* A finished run as bytes (run_pack) and back (run_unpack), so that a run computed in one
 * process can be written by another: batch frames dealt to MPI ranks reach rank 0 this
 * way (docs/mpi.md "Batch frames").
 *
 * The bytes hold everything run_write and the run's totals read: every selected sensor's
 * images (all planes, the measured ones when present, the noise seed), per channel the
 * photon-phase statistics, noise figures, passes and render times, per object the noise
 * figures, per sensor the back-face samples, the warnings, the timings, the run's options
 * that summary.json reports (threads, load time, noise target, time limit) and the totals.
 * Not the photon maps: an unpacked run keeps none (it cannot write photon-map.thzpm).
 * The scene is not in the bytes either: the receiver loads the same scene (the same text)
 * itself and unpack checks that its channel, sensor and object counts and the images'
 * sizes agree.
 *
 * The format is native (byte order, sizes of the plain-data structs): sender and receiver
 * are the same thzmap build on one machine or a homogeneous cluster; a header with a
 * magic and those sizes refuses anything else. Packing the same run gives the same bytes,
 * and run_pack(run_unpack(b)) == b byte for byte (tests/unit/test_run_pack.c).
 */
#ifndef THZ_RUN_RUN_PACK_H
#define THZ_RUN_RUN_PACK_H

#include <stddef.h>
#include <stdint.h>

#include "run/run.h"

/* The bytes of a finished run into *data (malloc'd, *size bytes; free()). */
thz_status run_pack(const run_state *rs, uint8_t **data, size_t *size, thz_error *err);

/* Fills rs (finalise with run_state_fini) from `size` bytes of run_pack for `scene` (the
 * scene with the run's overrides, borrowed: it must outlive rs and not move).
 * THZ_ERR_INPUT for bytes that are damaged, short, from another build or another scene;
 * rs is left empty on failure. */
thz_status run_unpack(const thz_scene *scene, const void *data, size_t size, run_state *rs,
                      thz_error *err);

#endif
