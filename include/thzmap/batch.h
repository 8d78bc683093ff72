/* thzmap public API: sequences, sweeps and movies (include thzmap/thzmap.h, which
 * includes this).
 *
 * A thz_sequence is a loaded and checked "thzmap-sequence/1" file (scene-format.md,
 * "Sequences, sweeps and movies"): a scene and keyframes interpolated in time (linear;
 * rotations by quaternion slerp; held beyond the ends), or a plain list of scene files
 * (one frame each, as it is), and an optional sweep that runs
 * the whole sequence once per value. Its frames are numbered 0 .. count - 1 over all
 * sweep values (sweep-major). Each frame is a complete scene: its JSON text, or the
 * loaded scene, on request.
 *
 * thz_batch_run runs every frame as `thzmap simulate` would, into
 * OUTDIR/[sweep-NN/]frame-NNNNN/ (each committed atomically, with its frame.json naming
 * the hash of the frame's inputs), writes OUTDIR/batch.json and the movies
 * [sweep-NN/]S.band-NN.mp4. Run again on the same OUTDIR it skips every frame whose
 * frame.json carries the same input hash, so a killed batch resumes where it stopped.
 * A frame whose scene differs from the previous frame's only in its sensors is rendered
 * (as thz_render_run) from the photons of the first frame of that run, fired once.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_BATCH_H
#define THZMAP_BATCH_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct thz_sequence thz_sequence;

/* Loads a sequence file and its scene and checks both: the sequence's keys and values
 * (errors name the file and JSON path, e.g. `seq.json: keyframes[1].objects.person:
 * the scene has no object named "person"`), and that every frame's scene loads (errors
 * name the frame). THZ_ERR_INPUT for bad input, also for more than 100000 frames in
 * all (frames per sweep value x sweep values). *out owns the sequence. */
THZ_API thz_status thz_sequence_load(const char *path, thz_sequence **out, thz_error *err);
/* The same confined to the directory `root` (NULL: not confined), as
 * thz_scene_load_within (thzmap/scene.h): the sequence file, the scene files it names
 * (absolute names refused, errors at their JSON path, e.g. `scenes[1]`) and every file
 * those scenes name must lie under root; thz_sequence_frame_scene keeps to it too. */
THZ_API thz_status thz_sequence_load_within(const char *path, const char *root, thz_sequence **out,
                                            thz_error *err);
/* The same, reporting through ctx's progress callback (ctx may be NULL: none) as it
 * builds and checks the frames, which loads each frame's scene (milliseconds each:
 * minutes for the largest sequences): stage "frames", done of total frames checked (0
 * before the first, total once all are), channel and n_channels 0; non-zero from the
 * callback cancels (THZ_ERR_CANCELLED). root as in thz_sequence_load_within (NULL: not
 * confined). */
THZ_API thz_status thz_sequence_load_ctx(thz_context *ctx, const char *path, const char *root,
                                         thz_sequence **out, thz_error *err);
THZ_API void thz_sequence_destroy(thz_sequence *seq);

/* Frames over all sweep values; sweep values (1 without a sweep); frames per sweep value. */
THZ_API size_t thz_sequence_frame_count(const thz_sequence *seq);
THZ_API size_t thz_sequence_sweep_count(const thz_sequence *seq);
THZ_API size_t thz_sequence_frames_per_sweep(const thz_sequence *seq);

typedef struct thz_frame_info {
    size_t sweep;    /* index of the sweep value (0 without a sweep) */
    size_t index;    /* frame index within its sweep value */
    double time_s;   /* index / fps */
    const char *dir; /* "frame-00003" or "sweep-01/frame-00003" (owned by seq) */
    uint64_t hash;   /* hash of the frame's inputs: its scene text and the files it names */
} thz_frame_info;

/* Fills *out for frame i (0 .. count - 1); THZ_ERR_INPUT when out of range. */
THZ_API thz_status thz_sequence_frame(const thz_sequence *seq, size_t i, thz_frame_info *out);

/* The frame's scene as JSON text (compact, keys in document order), written into buf like
 * snprintf: returns the length without the NUL (0, and an empty text in buf, when i is out
 * of range). Its relative file paths are relative to the directory of the frame's scene
 * file. */
THZ_API size_t thz_sequence_frame_json(const thz_sequence *seq, size_t i, char *buf, size_t size);

/* Loads frame i's scene (*out owns it), within the sequence's root if it has one. */
THZ_API thz_status thz_sequence_frame_scene(const thz_sequence *seq, size_t i, thz_scene **out,
                                            thz_error *err);

/* Progress of a batch: before checking each frame to run against the memory
 * (stage "check", before anything is written), before each frame (stage "frame"), while it runs
 * (stage "run", as often as the frame's run reports progress), before the movies ("movie") and once
 * at the end ("done"; frame == n_frames for these two). */
typedef struct thz_batch_progress {
    size_t frame; /* index of the frame about to be run or running (n_frames: done) */
    size_t n_frames;
    size_t computed;   /* frames computed so far by this call */
    size_t reused;     /* frames found finished in OUTDIR and skipped */
    double seconds;    /* wall time of this call so far, s */
    const char *stage; /* "check", "frame", "run", "movie", "done" */
    /* (added after the fields above, for callers built earlier) the share of the whole
     * batch done, 0..1, never falling: (frames done + the share of the running frame)
     * / n_frames; a frame's share counts its channels equally, photons (when it fires
     * any) the first half of each and rendering the second. */
    double fraction;
} thz_batch_progress;
/* Return non-zero to cancel (THZ_ERR_CANCELLED; finished frames stay). */
typedef int (*thz_batch_progress_fn)(void *user, const thz_batch_progress *progress);

typedef struct thz_batch_options {
    thz_batch_progress_fn progress; /* may be NULL */
    void *progress_user;
    int no_movies; /* non-zero: frames and batch.json only */
    /* May be NULL. Else the batch keeps there the output directory of the frame it is
     * running (NULL between frames), so that a handler run at exit (a library such as
     * libgomp may call exit() when it cannot allocate) can thz_output_destroy it and
     * leave no staging directory or lock behind; the thzmap program does. */
    thz_output **open_output;
} thz_batch_options;

/* What a batch did. */
typedef struct thz_batch_result {
    size_t n_frames, computed, reused, movies;
    double seconds; /* wall time, s */
} thz_batch_result;

/* Runs the sequence into outdir (created if missing) with ctx's threads and callbacks
 * (a frame's run reports through ctx's progress callback; returning non-zero there
 * cancels too; the batch replaces ctx's callback while it runs and restores it). Each
 * frame's scene warnings and run warnings go to ctx's warning callback, frame by frame.
 * When the frames do not all have the same sensors and channels there are no movies:
 * ctx's warning callback says why; a sensor too large for the encoder (a movie frame
 * above 16384 pixels a side with libx264) has none, which it says before the frames. One batch at a
 * time per outdir (THZ_ERR_IO naming the other process). opt and result may be NULL. */
THZ_API thz_status thz_batch_run(thz_context *ctx, const thz_sequence *seq, const char *outdir,
                                 const thz_batch_options *opt, thz_batch_result *result,
                                 thz_error *err);

/* ---- interpolation (exposed for tests and tools) ------------------------------------ */

/* Linear interpolation of n values between keyframes: times t[0] < ... < t[k-1] (s),
 * values v[j * n + m]; at time `time_s` (held beyond the ends) into out[n]. */
THZ_API void thz_interp_linear(const double *t, const double *v, size_t k, size_t n, double time_s,
                               double *out);
/* The same for rotations given as rotate_deg triples (rotations about x, then y, then z):
 * spherical linear interpolation of their quaternions (the shorter arc), back to a
 * triple in the same convention. */
THZ_API void thz_interp_rotation(const double *t, const double *rotate_deg, size_t k, double time_s,
                                 double out_deg[3]);

#ifdef __cplusplus
}
#endif
#endif
