/* The public API's handles (include/thzmap/) over the internal stages: what each
 * handle holds, and the helpers the src/api/ files share. Nothing here is public. */
#ifndef THZ_API_API_H
#define THZ_API_API_H

#include <stdbool.h>

#include "core/error.h"
#include "io/envi.h"
#include "photon/photon_map.h"
#include "photon/photon_stats.h"
#include "run/run.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "thzmap/thzmap.h"

struct thz_context {
    int threads;
    thz_progress_fn progress;
    void *progress_user;
    thz_warning_fn warning;
    void *warning_user;
    thz_error last;        /* the last failure of a call that took this context */
    struct mpi_team *team; /* rank 0 of an MPI run (api_mpi.c), else NULL */
    uint64_t mpi_bytes;    /* the other ranks: bytes their finished team moved */
    bool mpi_alone;        /* rank 0 while a batch deals frames: its runs share nothing */
};

/* Photons first .. first + count - 1 of a channel. */
typedef struct api_photon_span {
    size_t channel;
    uint64_t first, count;
} api_photon_span;

/* Photon maps of every channel of a scene (a channel may have none). */
struct thz_photons {
    const thz_scene *scene; /* borrowed: the scene the caller fired or loaded them for */
    thz_scene effective;    /* shallow copy of *scene with the overrides they were fired with */
    size_t n_channels;
    photon_map **maps;   /* per channel, NULL: none */
    photon_stats *stats; /* per channel */
    uint64_t seed;
    uint64_t photons_per_channel;
    /* The photons each channel's map holds, as ranges (thz_photons_merge refuses parts
     * whose ranges of a channel overlap): one a channel when fired here or kept by a
     * simulation (photons 0 .. fired - 1), the union of the parts' when merged from parts
     * that all know theirs; none (n_spans 0) for a loaded map, which does not know its
     * range. Owned (a run's by the run). */
    api_photon_span *spans;
    size_t n_spans;
    bool owned; /* maps and stats belong to this handle (not to a thz_run) */
};

struct thz_image {
    const thz_scene *scene; /* the (effective) scene it was rendered in; borrowed */
    size_t sensor;
    char *sensor_name;        /* owned: the accessor's string outlives the scene */
    const sensor_images *img; /* borrowed from a run */
    float *object_id;         /* object_id as float, -1: nothing hit */
    struct thz_run *run;      /* a standalone image owns its run (the planes live there) */
};

struct thz_run {
    const thz_scene *scene; /* borrowed: the caller's */
    thz_scene effective;    /* shallow copy with the run's overrides; rs.scene points here */
    run_state rs;
    thz_image *images;   /* per rendered sensor, borrowing rs.images */
    thz_photons photons; /* the kept maps (borrowed from rs), if any */
    bool has_photons;
    char *summary;
};

/* A cube read from disk (thz_cube_read) or made of the caller's values (thz_cube_create):
 * api_cube.c fills it, api_classify.c reads it. */
struct thz_cube {
    envi_cube c;
    char *stem; /* the file stem, or the name it was made with: what messages call it */
    bool wavelength_ghz;
};

/* Applies the settings' overrides to a shallow copy of `scene` (the copy shares every
 * array with it and must not be destroyed). THZ_ERR_INPUT for an unknown integrator. */
thz_status api_effective_scene(const thz_scene *scene, const thz_run_settings *settings,
                               thz_scene *out, thz_error *err);

/* The context's team of MPI ranks for shared photon phases, NULL when alone or built
 * without MPI; api_mpi_release ends it (thz_context_destroy). */
const struct photon_phase_team *api_mpi_phase_team(const thz_context *ctx);
/* The same team's side of render passes shared by pixel tiles. */
const struct render_team *api_mpi_render_team(const thz_context *ctx);
void api_mpi_release(thz_context *ctx);
/* Rank 0 of a batch: the other ranks load scene `scene` (a frame of the sequence they
 * serve, thz_mpi_serve_batch) for the runs that follow. Nothing when alone. */
thz_status api_mpi_next_scene(thz_context *ctx, size_t scene, thz_error *err);

/* Rank 0 of a batch dealing whole frames (docs/mpi.md "Batch frames"): the ranks of the
 * context's team (1 when alone); api_mpi_deal sends every rank the list of frames to
 * compute (each computes its share, batch_deal_serve) and makes rank 0's own runs share
 * nothing until api_mpi_deal_end; api_mpi_receive takes rank `rank`'s next frame (*data
 * malloc'd: run_pack's bytes after batch_deal.c's header, or when *status is not THZ_OK
 * the error message). Nothing and THZ_OK when alone. */
size_t api_mpi_ranks(const thz_context *ctx);
thz_status api_mpi_deal(thz_context *ctx, const uint64_t *frames, size_t n, thz_error *err);
void api_mpi_deal_end(thz_context *ctx);
thz_status api_mpi_receive(thz_context *ctx, size_t rank, uint64_t *frame, thz_status *status,
                           void **data, size_t *size, thz_error *err);

/* THZ_ERR_INPUT when ctx (may be NULL) holds more threads than THZ_MAX_THREADS; `what`
 * names the call in the message. Every call that runs with a context's threads checks. */
thz_status api_check_threads(const thz_context *ctx, const char *what, thz_error *err);

/* run_options from a context and settings. */
void api_run_options(const thz_context *ctx, const thz_run_settings *settings, run_options *opt);

/* A run computed elsewhere (a batch frame dealt to another MPI rank), from run_pack's
 * bytes (run/run_pack.h) for `scene` (borrowed, the frame's scene as this process loaded
 * it): images and summary as the computing process had them, no photons. */
thz_status api_run_unpack(const thz_scene *scene, const void *data, size_t size, thz_run **out,
                          thz_error *err);

/* Records a failure in ctx (may be NULL) and returns st. */
thz_status api_done(thz_context *ctx, thz_status st, const thz_error *err);

/* The caller's error, or `local` when the caller passed NULL (so ctx still gets the
 * message). */
static inline thz_error *api_err(thz_error *err, thz_error *local)
{
    thz_error_clear(local);
    return err ? err : local;
}

/* Builds the image handles of a finished run (borrowing its planes). */
thz_status api_image_init_borrowed(thz_image *image, const thz_scene *scene, size_t sensor,
                                   const sensor_images *img, thz_error *err);
void api_image_fini(thz_image *image);

#endif
