/* Processes sharing a run over MPI (docs/mpi.md): the one module that includes <mpi.h>,
 * compiled only when CMake finds MPI.
 *
 * Rank 0 (the lead) runs simulate as one process would; its photon phases go through
 * the team (photon/phase.h "a phase shared by processes"): the lead broadcasts each
 * phase's request, every rank fires its share of the batches, and the lead gathers the
 * shares in rank order. Its render passes go through the team too (sensor/render_tiles.h):
 * the lead sends each channel's photon map, every rank renders its pixel tiles of each
 * pass, and the lead copies the others' tiles into its images. The other ranks (members)
 * only serve requests: mpi_team_serve loops until the lead's mpi_team_destroy tells them
 * to stop. Only the lead writes. The caller initialises MPI (MPI_THREAD_FUNNELED: only the thread
 * that created the team calls MPI) and finalises it after destroying the team; the library never
 * aborts: a failed rank returns its error, and the program ends the job (MPI_Abort).
 *
 * Waiting ranks poll (MPI_Test, then sleep up to 5 ms) rather than spin, so that ranks
 * oversubscribing a machine leave its cores to the ranks that work.
 */
#ifndef THZ_MPI_MPI_TEAM_H
#define THZ_MPI_MPI_TEAM_H

#include <stddef.h>
#include <stdint.h>

#include "accel/accel.h"
#include "core/error.h"
#include "photon/phase.h"
#include "scene/scene.h"
#include "sensor/render_tiles.h"

typedef struct mpi_team mpi_team;

/* Collective over MPI_COMM_WORLD (every rank calls it): the team of all its ranks, on a
 * communicator of its own. */
thz_status mpi_team_create(mpi_team **out, thz_error *err);

/* Async-signal-safe: every wait of this process's teams ends with THZ_ERR_CANCELLED
 * (thz_mpi_interrupt). */
void mpi_team_interrupt(void);

/* The lead tells the members to stop (their mpi_team_serve returns THZ_OK); every rank
 * frees its communicator. NULL does nothing. */
void mpi_team_destroy(mpi_team *team);

size_t mpi_team_rank(const mpi_team *team);
size_t mpi_team_size(const mpi_team *team);

/* The lead's side of shared photon phases (valid while the team lives). */
const photon_phase_team *mpi_team_phase(const mpi_team *team);

/* The lead's side of render passes shared by pixel tiles (sensor/render_tiles.h). */
const render_team *mpi_team_render(const mpi_team *team);

/* A member's side: fires its share of each photon phase the lead broadcasts, and renders
 * its tiles of each render pass, from scene and acc (the same scene, with the same
 * overrides, as the lead's), with `threads` OpenMP threads, and sends them to the lead;
 * returns THZ_OK when the lead stops the team. */
thz_status mpi_team_serve(mpi_team *team, const thz_scene *scene, const accel *acc, int threads,
                          uint64_t *next_scene, thz_error *err);

/* Runs of several scenes (batch frames): the lead's mpi_team_next_scene makes the
 * members' mpi_team_serve return THZ_OK with *next_scene = scene (the caller's index);
 * they load that scene and serve again. When the lead stops the team, *next_scene is
 * MPI_TEAM_STOPPED. next_scene NULL: one scene, a change of scene is an error. */
#define MPI_TEAM_STOPPED UINT64_MAX
thz_status mpi_team_next_scene(mpi_team *team, uint64_t scene, thz_error *err);

/* Work dealt whole (batch frames, docs/mpi.md "Batch frames"): the lead's mpi_team_deal
 * broadcasts n items (the caller's indices, the same list to every member); a member's
 * mpi_team_serve (with next_scene) then returns THZ_OK with *next_scene = MPI_TEAM_DEALT
 * and mpi_team_dealt gives the list (owned by the team, valid until the next serve).
 * Each member computes the items the caller's rule gives it on its own, and sends each
 * result (or its failure: a status and the message) to the lead with
 * mpi_team_send_result, in its own order; the lead takes member r's next result with
 * mpi_team_receive_result (waiting, polling, until r sends it). A member's send waits
 * until the lead takes it. */
#define MPI_TEAM_DEALT (UINT64_MAX - 1)
thz_status mpi_team_deal(mpi_team *team, const uint64_t *items, size_t n, thz_error *err);
const uint64_t *mpi_team_dealt(const mpi_team *team, size_t *n);
/* status THZ_OK: data is the item's result; else data is the error message. */
thz_status mpi_team_send_result(mpi_team *team, uint64_t item, thz_status status, const void *data,
                                size_t size, thz_error *err);
/* *data (malloc'd, *size bytes, followed by a '\0') is member `rank`'s next result, for
 * `*item`, or when *status is not THZ_OK its error message. */
thz_status mpi_team_receive_result(mpi_team *team, size_t rank, uint64_t *item, thz_status *status,
                                   void **data, size_t *size, thz_error *err);

/* Bytes this rank sent and received through the team so far. */
uint64_t mpi_team_bytes(const mpi_team *team);

#endif
