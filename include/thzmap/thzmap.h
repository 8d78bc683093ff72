/* thzmap public API.
 *
 * A reentrant library: no globals, every state hangs off a handle. Fallible functions
 * return a thz_status and fill a caller-supplied thz_error (which may be NULL). Long
 * runs report progress through a callback that can also cancel them.
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

/* Status codes. THZ_ERR_INPUT means the user's input (scene, mesh, CSV, options) is
 * wrong; the CLI exits 2 for it and 1 for every other error. */
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
 * (line:column or JSON path) where it applies. */
typedef struct thz_error {
    thz_status status;
    char message[1024];
} thz_error;

/* Progress of a long run. `stage` is a static string ("photons", "render", ...). */
typedef struct thz_progress {
    const char *stage;
    size_t channel; /* index of the channel being processed */
    size_t n_channels;
    uint64_t done;  /* units of work done in this stage and channel */
    uint64_t total; /* units of work in this stage and channel */
} thz_progress;

/* Called from the thread that started the run, never from worker threads. Return
 * non-zero to cancel: the run then stops soon and returns THZ_ERR_CANCELLED. */
typedef int (*thz_progress_fn)(void *user, const thz_progress *progress);

typedef struct thz_scene thz_scene;

THZ_API const char *thz_version(void);
THZ_API const char *thz_status_name(thz_status status);

/* Loads and validates a scene file (format thzmap-scene/1). On success *out owns the
 * scene; destroy it with thz_scene_destroy. */
THZ_API thz_status thz_scene_load(const char *path, thz_scene **out, thz_error *err);
THZ_API void thz_scene_destroy(thz_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
