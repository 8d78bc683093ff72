/* thzmap: the public C API of the passive multispectral THz scene simulator.
 *
 * Everything the `thzmap` program does, in memory: a context (threads, progress and
 * cancellation, warnings), scenes (from a file or a JSON string) with read access,
 * the photon phase as a handle, rendering into image handles whose planes are float
 * arrays, whole runs, and writing results to a directory. docs/api.md is the tour (the
 * docs/ named in these headers are installed as PREFIX/share/doc/thzmap/).
 *
 * Conventions, as in Embree's rtcore_device.h:
 *   - opaque handles; the function that creates one says so, its _destroy frees it,
 *     and _destroy(NULL) does nothing;
 *   - fallible functions return a thz_status and fill a caller-supplied thz_error
 *     (may be NULL); on failure every out-handle is set to NULL. A NULL out-handle,
 *     info struct or handle is refused with THZ_ERR_INPUT (e.g. "thz_simulate: no place
 *     for the run"); functions returning a value give a neutral one (0, NULL, NaN) and
 *     void ones do nothing. The context is the exception: a NULL thz_context is the
 *     defaults (every core, no progress or warning callbacks, no MPI);
 *   - parameters are borrowed; strings and arrays returned by accessors belong to the
 *     handle they came from and live as long as it;
 *   - photons, runs and images (a run's or thz_render_sensor's) and a scene's thz_atm
 *     borrow the scene they were made from: destroy them, and finish writing them
 *     (thz_run_write, thz_image_write, thz_output_add_*, thz_photons_save), before the
 *     scene. Their accessors' strings are their own (thz_image_sensor_name is a copy);
 *   - no globals: handles are independent. A handle may be used from any thread, but
 *     by one thread at a time, except that a scene is read-only after loading and
 *     may be shared by concurrent runs;
 *   - no varargs, plain structs and float/double arrays (for ctypes and cffi).
 * Units are in the names (scene-format.md): _hz, _thz, _k, _m, _w_per_hz, _s.
 */
#ifndef THZMAP_THZMAP_H
#define THZMAP_THZMAP_H

#include <stddef.h>
#include <stdint.h>

#if defined(THZ_BUILDING_LIBRARY)
#define THZ_API __attribute__((visibility("default")))
#else
#define THZ_API
#endif

#define THZ_VERSION_STRING "0.1.0"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- status and errors ------------------------------------------------------------ */

/* THZ_ERR_INPUT means the user's input (scene, mesh, CSV, options) is wrong; the CLI
 * exits 2 for it and 1 for every other error. */
typedef enum thz_status {
    THZ_OK = 0,
    THZ_ERR_INPUT = 2,
    THZ_ERR_IO,
    THZ_ERR_NOMEM,
    THZ_ERR_LIMIT,
    THZ_ERR_CANCELLED,
    THZ_ERR_INTERNAL
} thz_status;

/* An error: the status and a one-line message naming the file and the position
 * (line:column or JSON path) where it applies. The message is valid UTF-8 without
 * control characters: bytes of a refused input that are neither appear as \xNN. */
typedef struct thz_error {
    thz_status status;
    char message[1024];
} thz_error;

/* "0.1.0"; static. */
THZ_API const char *thz_version(void);
/* The source revision built: the git commit, 40 lowercase hex digits, with "-dirty"
 * appended when tracked files differed from it; "unknown" when built from outside a git
 * checkout (an archive) or without git; or what the build was given (-DTHZ_REVISION).
 * Read from git at every build (cmake/revision.cmake); static, never NULL. */
THZ_API const char *thz_revision(void);
/* "bad input", "cancelled", ...; static, never NULL. */
THZ_API const char *thz_status_name(thz_status status);

/* ---- context ---------------------------------------------------------------------- */

/* Progress of a long run. `stage` is a static string: "prepare" (done/total in objects
 * whose back-side sources a deviation map needs, once per run before the first channel's
 * photons, channel 0; only where there are such objects: one-sided solids), "photons"
 * (done/total in photons of the channel), "render" (rows of a sensor), "output" (0/1,
 * then 1/1), "read" (thz_photons_load and _load_channel: a channel's stored photons in
 * the file, 0 of them before its records are read and all once its map is built). A channel's
 * "photons" and "render" first report done = 0 when they start (a clock of the stage
 * starts there, as summary.json's photon_phase_s and render_s do); each further render
 * pass, and each further sensor, reports its rows from 0 again. thz_bands_select reports
 * "bands" alone: `channel` is the render (the nominal one, then the nuisances'),
 * `n_channels` the renders (0 until their count is known), done/total its candidate
 * channels. thz_sequence_load_ctx reports "frames": done/total frames checked. */
typedef struct thz_progress {
    const char *stage;
    size_t channel; /* index of the channel being processed */
    size_t n_channels;
    uint64_t done;  /* units of work done in this stage and channel */
    uint64_t total; /* units of work in this stage and channel */
} thz_progress;

/* Called on the thread that started the run, never from worker threads. Return
 * non-zero to cancel: the run then stops soon and returns THZ_ERR_CANCELLED. */
typedef int (*thz_progress_fn)(void *user, const thz_progress *progress);

/* A run warning (one line, no newline), on the thread that started the run; the text
 * is valid during the call only. Run warnings also go into summary.json. */
typedef void (*thz_warning_fn)(void *user, const char *message);

/* What a run is done with: threads, callbacks. Cheap; one per thread of the caller. */
typedef struct thz_context thz_context;

/* Creates a context (all cores, no callbacks). NULL only when out of memory. */
THZ_API thz_context *thz_context_create(void);
THZ_API void thz_context_destroy(thz_context *ctx);
/* The most threads a context may run with (the CLI's --threads limit). */
#define THZ_MAX_THREADS 4096

/* OpenMP threads of the runs started with ctx; 0 (the default) means all cores, and a
 * negative count means 0. Runs give bit-identical results for any thread count. The
 * count is stored as given; the calls that run with ctx (thz_simulate, thz_render_*,
 * thz_photons_fire*, _load*, _merge, thz_batch_run, thz_bands_select, thz_mpi_serve*)
 * refuse more than THZ_MAX_THREADS with THZ_ERR_INPUT before any work (OpenMP itself
 * fails on such counts by exiting the process). */
THZ_API void thz_context_set_threads(thz_context *ctx, int threads);
THZ_API int thz_context_threads(const thz_context *ctx);
/* The progress callback (NULL: none); `user` is passed back to it. */
THZ_API void thz_context_set_progress(thz_context *ctx, thz_progress_fn fn, void *user);
/* The warning callback (NULL: none; the library never prints). */
THZ_API void thz_context_set_warning(thz_context *ctx, thz_warning_fn fn, void *user);
/* Under an address-space limit (RLIMIT_AS, `ulimit -v`), libgomp ends the process when
 * it cannot map a new thread's stack ("Thread creation failed"). Call this first, from
 * the thread that will call the library: it starts `threads` OpenMP threads now (0:
 * OpenMP's default), or as many as fit in half the room the limit leaves (each maps its
 * stack, OMP_STACKSIZE or the C library's default, and a 64 MiB malloc arena), at least
 * 1, so that later work of no more threads finds them started and a shortage of memory
 * is an ordinary THZ_ERR_NOMEM. Returns `threads` when they all fit, else the count
 * started, which it also makes what 0 (all cores) stands for. Without a limit it starts
 * nothing and returns `threads`. */
THZ_API int thz_threads_prepare(int threads);
/* OMP_STACKSIZE as libgomp reads it, in bytes; 0 when unset or not a size. */
THZ_API uint64_t thz_omp_stack_bytes(void);
/* The status and message of the last failed call that took ctx (THZ_OK and "" if
 * none); the message is valid until the next call with ctx. */
THZ_API thz_status thz_context_last_status(const thz_context *ctx);
THZ_API const char *thz_context_last_message(const thz_context *ctx);

#ifdef __cplusplus
}
#endif

/* The parts, in the order their types build on each other. Each part includes this file
 * before its own guard, so any part included alone brings in all of them, in this order. */
#include "thzmap/scene.h"
#include "thzmap/run.h"
#include "thzmap/atmosphere.h"
#include "thzmap/batch.h"
#include "thzmap/materials.h"
#include "thzmap/analysis.h"
#include "thzmap/mpi.h"

#endif
