/* One batch run's state, shared by the files that run it: batch_run.c runs the frames
 * (thz_batch_run); batch_json.c writes batch.json and each frame's frame.json, and reads
 * a frame.json back to tell a finished frame; batch_outdir.c creates and locks OUTDIR and
 * cleans up after a killed commit. Nothing here is public.
 */
#ifndef THZ_BATCH_BATCH_RUN_STATE_H
#define THZ_BATCH_BATCH_RUN_STATE_H

#include <stdbool.h>
#include <stddef.h>

#include <jansson.h>

#include "batch/batch_internal.h"

typedef enum frame_state { FRAME_PENDING, FRAME_REUSED, FRAME_COMPUTED, FRAME_FAILED } frame_state;

/* How a frame computed by this call got its photons (batch.json's frames[].photons). */
enum { BATCH_PHOTONS_FIRED = 0, BATCH_PHOTONS_REUSED, BATCH_PHOTONS_NONE };

typedef struct batch_state {
    const thz_sequence *seq;
    const char *outdir;
    frame_state *state;
    double *seconds;     /* per frame computed by this call, s */
    size_t *base;        /* per frame: the frame whose photons it renders from (batch_reuse.c) */
    size_t *rank;        /* per frame: the MPI rank that computes it (0: this process) */
    int *reused_photons; /* per frame computed by this call: BATCH_PHOTONS_* */
    batch_photon_cache cache;  /* the photons of the current base frame */
    json_t *movies;            /* the movies' descriptions (batch.json "movies") */
    char movies_skipped[1024]; /* why there are none or some are missing ("": none is) */
    const thz_batch_options *opt;
    thz_progress_fn run_progress; /* the caller's progress callback on ctx, restored after */
    void *run_progress_user;
    size_t frame;       /* the frame running */
    double frame_share; /* the share of it done, 0..1, never falling */
    int photons_seen;   /* it fires photons (then they are half of each channel) */
    double t0, seconds_frames, seconds_movies;
    double json_at_s, json_cost_s; /* batch.json: when last written, how long that took */
    size_t computed, reused;
    size_t fired, rerendered; /* photon phases run, frames rendered from kept photons */
} batch_state;

/* ---- batch_run.c ---- */

/* The monotonic clock, s. */
double batch_now_s(void);

/* ---- batch_json.c: batch.json and frame.json ---- */

/* Whether frame f's directory holds a finished frame with the same inputs, and, when it
 * was rendered from another frame's photons, that frame is still its base (b->base). */
int batch_frame_done(const batch_state *b, size_t f);
/* Writes OUTDIR/batch.json (a temporary file, then a rename) from b. */
thz_status batch_write_json(batch_state *b, thz_error *err);
/* Whether batch.json is due after a frame: once a second at most, and at most a tenth
 * of the time spent (a long sequence's file is megabytes, and writing it after every
 * frame made 20 000 frames take 2.3 times as long per frame as 100); always after the
 * last frame and after one that failed or was cancelled. The frame directories, not
 * batch.json, tell a later batch what is done. */
bool batch_json_due(const batch_state *b, size_t f, thz_status st);
/* Rewrites a finished frame's frame.json (a temporary file, then a rename) where it says
 * other than this sequence's frame.json for it would: its number, time and sweep value
 * as this sequence has them (a changed fps or frames per sweep value keeps the frames
 * whose scenes did not change); photons_reused_from_frame stays how its files were made,
 * numbered as this sequence numbers frames (batch_frame_done kept it only when that is
 * its base). */
thz_status batch_frame_refresh(const batch_state *b, size_t f, thz_error *err);
/* frame.json: which frame this directory is and the hash of its inputs (and the scene
 * it was run with, to rerun it by hand). No timings: it is the same in every run. */
char *batch_frame_json(const thz_sequence *seq, size_t f, long reused_from);

/* ---- batch_outdir.c: OUTDIR ---- */

/* mkdir -p */
thz_status batch_mkdirs(const char *dir, thz_error *err);
/* Takes OUTDIR's batch lock (held until fd is closed or the process ends). */
thz_status batch_lock(const char *outdir, int *fd, thz_error *err);
/* A batch killed inside a frame's commit after the exchange (while the replaced frame's
 * files were being deleted) leaves them and the lock beside a frame that is finished,
 * which no later run opens again: opening each finished frame's output and closing it
 * without a commit cleans them up (thz_output_open removes what a dead run left). Only
 * in the directories (OUTDIR, sweep-NN/) that hold such names; best effort: a frame
 * another process holds is left for later. */
void batch_clean_finished(const batch_state *b);

#endif
