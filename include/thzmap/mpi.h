/* Runs shared by MPI processes (docs/mpi.md), for programs launched by mpirun or srun.
 *
 * The library never initialises, finalises or aborts MPI: the program calls
 * MPI_Init_thread (MPI_THREAD_FUNNELED is enough: only the thread that calls these
 * functions and the runs uses MPI), destroys its contexts, then calls MPI_Finalize; when a
 * call fails on any rank, the program ends the job (MPI_Abort), since the other ranks may
 * be waiting for it. Every rank loads the same scene with the same run settings. In a
 * build with MPI, the calls below made before MPI_Init_thread (or after MPI_Finalize)
 * return THZ_ERR_INTERNAL ("MPI: not initialised").
 *
 * Rank 0 calls thz_context_set_mpi and then thz_simulate, thz_render_run or thz_batch_run
 * as one process would: each photon phase is split by batches of photons across the ranks
 * and gathered in photon order, and each render pass by pixel tiles, each rank rendering
 * its tiles from the same photon map (rank 0 sends it), so that rank 0's run (images,
 * photon maps, statistics) is bit-identical to one process's with the same seed. The
 * other ranks call thz_mpi_serve (thz_mpi_serve_batch for a batch), which returns when
 * rank 0 destroys its context. A batch deals whole frames to the ranks when it can, each
 * computed alone and sent to rank 0 (docs/mpi.md "Batch frames"). Only rank 0 writes.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_MPI_H
#define THZMAP_MPI_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when this library was built with MPI support, else 0. */
THZ_API int thz_mpi_supported(void);

/* For a SIGINT or SIGTERM handler (async-signal-safe; process-wide): a call of this
 * process waiting for other ranks stops waiting and returns THZ_ERR_CANCELLED, so that
 * rank 0 can clean up before it ends the job (a rank that has stopped or died would keep
 * it waiting until mpirun kills it). A run that is computing is stopped by its progress
 * callback, as without MPI. It stays in force for the rest of the process (the job is to
 * end: the program calls MPI_Abort). A no-op without MPI support. */
THZ_API void thz_mpi_interrupt(void);

/* Rank 0: simulate runs on ctx share their photon phases with the other ranks of
 * MPI_COMM_WORLD. Collective with the other ranks' thz_mpi_serve. THZ_ERR_INPUT without
 * MPI support. */
THZ_API thz_status thz_context_set_mpi(thz_context *ctx, thz_error *err);

/* Ranks other than 0: fire this rank's share of every photon phase rank 0 asks for (the
 * scene with `settings`' overrides; ctx's thread count) until rank 0 destroys its
 * context. A failure (a scene that differs from rank 0's, out of memory) returns it. */
THZ_API thz_status thz_mpi_serve(thz_context *ctx, const thz_scene *scene,
                                 const thz_run_settings *settings, thz_error *err);

/* Ranks other than 0 of a batch (thz_batch_run on rank 0 with thz_context_set_mpi), until
 * rank 0 destroys its context: when rank 0 deals whole frames (at least as many photon
 * groups to run as ranks), computes this rank's frames alone on ctx's threads and sends
 * each to rank 0, which writes them; else, for each frame rank 0 runs, loads the frame's
 * scene from seq (the same sequence file) and serves its photon phases and render passes
 * as thz_mpi_serve does. A frame that fails here is reported to rank 0 (whose
 * thz_batch_run returns the failure) and this call keeps waiting for rank 0. */
struct thz_sequence;
THZ_API thz_status thz_mpi_serve_batch(thz_context *ctx, const struct thz_sequence *seq,
                                       thz_error *err);

/* Bytes this rank sent and received through ctx for shared photon phases and render
 * tiles (photon maps broadcast included). */
THZ_API uint64_t thz_context_mpi_bytes(const thz_context *ctx);

#ifdef __cplusplus
}
#endif

#endif
