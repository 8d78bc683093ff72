/* Sequences and batches (include/thzmap/batch.h): what a loaded sequence holds, and
 * what the files of src/batch/ share. batch_sequence.c loads and checks a sequence and
 * builds every frame's scene text, from the scene files batch_scenes.c loads, the
 * keyframes batch_keyframes.c gathers and the sweep batch_sweep.c reads (batch_blame.c
 * names a bad value where the sequence sets it; batch_sequence_build.h);
 * batch_frames.c gives the frames out; batch_interp.c interpolates; batch_hash.c hashes
 * a frame's inputs; batch_run.c runs the frames, into OUTDIR (batch_outdir.c) with
 * batch.json and each frame's frame.json (batch_json.c; batch_run_state.h); batch_deal.c
 * computes a frame and deals frames to MPI ranks; batch_movie.c
 * makes the movies from the frames' cubes, through batch_encode.c (the only file that
 * includes FFmpeg). Nothing here is public.
 */
#ifndef THZ_BATCH_BATCH_INTERNAL_H
#define THZ_BATCH_BATCH_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "scene/scene_hash.h"
#include "thzmap/batch.h"
#include "thzmap/thzmap.h"

struct thz_sequence {
    char *path;          /* the sequence file as given */
    char *root;          /* NULL, or the real path its files are confined to (load_within) */
    size_t n_scenes;     /* scene files: 1 ("scene"), or the length of "scenes" */
    int scene_list;      /* "scenes": frame i of each sweep value is scene i */
    char **scene_paths;  /* per scene file, resolved against the sequence's directory */
    char **scene_dirs;   /* per scene file, its directory: relative paths in its frames */
    double fps;          /* frames per second */
    size_t frames;       /* per sweep value */
    size_t n_sweeps;     /* sweep values (1 without a sweep) */
    int has_sweep;       /* frame directories under sweep-NN/ */
    int sweep_digits;    /* NN's digits: 2, more where there are more than 100 values */
    size_t n_frames;     /* frames * n_sweeps */
    char **frame_json;   /* per frame: the scene text (compact, keys in document order) */
    char **frame_dir;    /* per frame: "frame-NNNNN" or "sweep-NN/frame-NNNNN" */
    uint64_t *hash;      /* per frame: hash of its inputs */
    json_t **sweep_json; /* per sweep value: its values by key, the sequence file's own
                            ({"atmosphere.relative_humidity": 0.5, ...}); NULL: no sweep */
    char **sweep_label;  /* per sweep value: "atmosphere.relative_humidity = 0.5, ..."
                            (numbers in their shortest form: 0.1, not 0.10000000000000001) */
    char *movies_unmade; /* NULL, or why some sensors' movies cannot be made (too large) */
};

/* "sweep-NN" (sweep_digits digits) of sweep value s into buf. */
void batch_sweep_dir(const thz_sequence *seq, size_t s, char *buf, size_t size);

/* The scene file of frame f (its index into scene_paths and scene_dirs). */
size_t batch_frame_scene(const thz_sequence *seq, size_t f);

/* Reads the sequence's "scene" or "scenes" (root: the sequence document; errors name
 * label, the sequence file, and the JSON path) into seq's scene_paths, scene_dirs,
 * n_scenes and scene_list, and their documents into *docs (n_scenes; free with
 * batch_scenes_free, also after a failure). Refuses both keys, neither, an empty list,
 * and keyframes or frames with a list; with seq->root, scene files outside it
 * (load_file_check). */
thz_status batch_scenes_load(const char *label, const json_t *root, const char *seq_dir,
                             thz_sequence *seq, json_t ***docs, thz_error *err);
void batch_scenes_free(json_t **docs, size_t n);

/* The keyframe segment j (0 .. k-2) holding time_s and the weight u in [0, 1] of its
 * end (held beyond the ends: u = 0 before the first, 1 after the last). */
void batch_segment(const double *t, size_t k, double time_s, size_t *j, double *u);

/* 64-bit FNV-1a of n bytes, continuing from h (start with BATCH_HASH_INIT). */
#define BATCH_HASH_INIT UINT64_C(14695981039346656037)
uint64_t batch_hash_bytes(uint64_t h, const void *data, size_t n);
/* Continues h over the content of every file that doc (a frame's scene) names in its
 * "file" and "*_file" keys, relative to scene_dir; cache maps a path to its hash (hex),
 * so each file is read once. An unreadable file hashes as 0 (the scene loader reports
 * it). */
uint64_t batch_hash_files(json_t *cache, const char *scene_dir, const json_t *doc, uint64_t h);

/* Reads band `channel` of an ENVI float32 cube of `columns * rows * channels` values
 * into out (columns * rows); THZ_ERR_IO naming the file when it is missing or short. */
thz_status batch_read_band(const char *path, uint32_t columns, uint32_t rows, size_t channels,
                           size_t channel, float *out, thz_error *err);

/* Encodes the movies of every sweep value, sensor and channel from the frames' cubes in
 * outdir ([sweep-NN/]S.band-NN.mp4, each written to a temporary name and renamed), on
 * one colour scale per sensor and channel over all frames; appends their descriptions
 * to `movies` (a JSON array, batch.json's "movies"). Deterministic: the same frames give
 * the same bytes. When the frames do not all have the same sensors (names and sizes)
 * and channels (frequencies and widths), writes none and says why in skipped; a sensor
 * too large for the encoder (batch_movie_sizes) gets none and skipped says so (else
 * skipped[0] = '\0'). */
/* Whether every sensor of scene (frame 0's) makes a movie the encoder accepts (1);
 * else 0 and why, naming each sensor that does not, in why. */
int batch_movie_sizes(const thz_scene *scene, char *why, size_t size);

thz_status batch_movies_write(const thz_sequence *seq, const char *outdir, json_t *movies,
                              char *skipped, size_t skipped_size, thz_error *err);

/* ---- batch_reuse.c: photons shared by frames that differ only in their sensors ---- */

/* base[f] for every frame: the first frame of the run of consecutive frames whose scene
 * texts equal f's but for "sensors" (f itself when the previous frame differs more). */
thz_status batch_photon_bases(const thz_sequence *seq, size_t *base, thz_error *err);

/* The photons of one base frame, kept while the frames after it reuse them: either the
 * base frame's own run (fired by thz_simulate with keep_photons) or, when a resumed
 * batch starts after the base, fired again from the base's scene. */
typedef struct batch_photon_cache {
    size_t base;        /* the frame they belong to; SIZE_MAX: none */
    thz_scene *scene;   /* the base's scene (the photons point to it) */
    thz_run *run;       /* the base frame's run, holding its photons; or NULL */
    thz_photons *fired; /* fired again by batch_render_reused; or NULL */
    bool hashed;        /* hash holds the base scene's photon-map fingerprint */
    scene_hash hash;    /* (computed once per base, at its first reuse) */
} batch_photon_cache;

void batch_photon_cache_clear(batch_photon_cache *c);
/* Takes the base frame's scene and run (with kept photons) into the cache; *scene and
 * *run become NULL. */
void batch_photon_cache_keep(batch_photon_cache *c, size_t base, thz_scene **scene, thz_run **run);
/* Renders `scene` (a frame whose base is `base`) from the base's photons (*reused = 1),
 * firing them into the cache first when it holds another base's (*fired = 1 then). When
 * the frame's photon-map fingerprint differs from the base's (a sensor moved into another
 * enclosure changes an emitting air's default temperature), simulates the frame instead
 * (*reused = 0, *fired = 1). */
thz_status batch_render_reused(thz_context *ctx, const thz_sequence *seq, batch_photon_cache *c,
                               size_t base, const thz_scene *scene, thz_run **run, int *reused,
                               int *fired, thz_error *err);

/* ---- batch_deal.c: frames computed apart from their writing; frames dealt to ranks -- */

/* One frame on its way from its scene to its files. */
typedef struct batch_frame {
    thz_scene *scene; /* the frame's scene */
    thz_run *run;     /* its run, once computed */
    int reused;       /* rendered from its base frame's photons */
    int fired;        /* fired photons: its own, or (resuming) its base's again */
    int keep;         /* the next frame renders from its photons: keep scene and run */
} batch_frame;

/* Loads frame f's scene into *fr (emptied first) and decides, from its integrator and
 * base[], whether it renders from its base's photons and whether its own are kept. */
thz_status batch_frame_load(const thz_sequence *seq, const size_t *base, size_t f, batch_frame *fr,
                            thz_error *err);
/* Computes fr->run as one process does: `thzmap simulate` (keeping the photons when
 * fr->keep), or `thzmap render` from the base's photons in cache (batch_render_reused,
 * which updates fr->reused and fr->fired). */
thz_status batch_frame_compute(thz_context *ctx, const thz_sequence *seq, const size_t *base,
                               batch_photon_cache *cache, size_t f, batch_frame *fr,
                               thz_error *err);
/* After the frame is written or sent: its scene and run go into the cache when ok and
 * fr->keep, else are freed; *fr is empty after. */
void batch_frame_fini(batch_frame *fr, batch_photon_cache *cache, size_t f, int ok);

/* The deal (docs/mpi.md "Batch frames"): the n frames (increasing) split into photon
 * groups, the frames with the same base (consecutive in the list); group k goes to rank
 * k mod members: owner[i] (may be NULL) for frames[i]. Returns the number of groups. */
size_t batch_deal_owners(const size_t *base, const uint64_t *frames, size_t n, size_t members,
                         size_t *owner);

/* How a member's computed frame reaches rank 0: status THZ_OK and the frame's bytes, or
 * the frame's failure and its message. */
typedef thz_status (*batch_send_fn)(void *user, uint64_t frame, thz_status status, const void *data,
                                    size_t size, thz_error *err);

/* A member rank (`member` of `members`): computes its frames of the dealt list, in order,
 * each alone on ctx's threads exactly as one process would, and sends each to rank 0.
 * A frame that fails is sent as its failure (rank 0 reports it) and ends the loop with
 * THZ_OK; only a failure to send returns an error. */
thz_status batch_deal_serve(thz_context *ctx, const thz_sequence *seq, const uint64_t *frames,
                            size_t n, size_t member, size_t members, batch_send_fn send_frame,
                            void *send_user, thz_error *err);

/* Rank 0: frame f from rank `rank` (its next one): fr's scene loaded here, its run from
 * the received bytes; *seconds the time computing it took there (its scene and its run),
 * s. A failure the rank sent comes
 * back as its status and message, with *theirs set (else false: this rank's own). */
thz_status batch_deal_receive(thz_context *ctx, const thz_sequence *seq, size_t f, size_t rank,
                              batch_frame *fr, double *seconds, bool *theirs, thz_error *err);

/* ---- batch_encode.c: one movie, frame by frame (the only code that includes FFmpeg) -- */

/* The picture of a movie frame: the Tb image scaled by `pixel` (whole pixels), its top
 * left corner at (image_x, image_y), a strip above it with the frame time, a colour
 * bar with the scale's ends at its right; width x height in all (both even). */
typedef struct movie_layout {
    uint32_t pixel, image_x, image_y, width, height;
} movie_layout;

/* The frame rates a movie plays at: a sequence's fps beyond them (a frame an hour for a
 * slow process) gives movies at the nearest end, which batch.json's movies[].fps says.
 * The encoder's rational rate (at most 100000 in numerator and denominator) holds them. */
#define MOVIE_FPS_MIN 0.01
#define MOVIE_FPS_MAX 1000.0

typedef struct movie_spec {
    const char *path; /* the .mp4 */
    uint32_t columns, rows;
    double fps;
    double frame_interval_s;   /* the sequence's time between frames (1 / its fps, which fps
                                  may clamp): the caption's decimals; 0: 1 / fps */
    double tb_min_k, tb_max_k; /* the colour scale, K */
} movie_spec;

typedef struct movie_writer movie_writer;

/* A movie's frame size against its encoder's largest (libx264: 16384 pixels a side;
 * MPEG-4 part 2, where libavcodec lacks libx264: 8190). */
typedef struct movie_limit {
    uint32_t width, height; /* the movie's frame (movie_layout_of), px */
    uint32_t max_side;      /* the encoder's largest width and height, px */
    const char *codec;      /* its name, for messages (static) */
} movie_limit;

/* Whether a sensor of columns x rows pixels makes a movie the encoder accepts; *out says
 * the sizes either way. Opens FFmpeg (to see which encoder there is) only for a frame
 * larger than 8190 pixels a side. */
int movie_fits(uint32_t columns, uint32_t rows, movie_limit *out);

void movie_layout_of(uint32_t columns, uint32_t rows, movie_layout *out);
/* The decimals of a movie caption's frame time: the fewest (at most 2 beyond the
 * interval's first significant digit) that write every multiple of the frame interval dt
 * exactly (0.25 s at 4 fps, 0.125 s at 8), else those that tell frames apart (30 fps: 2). */
int movie_time_decimals(double dt);
/* Opens the encoder on a temporary file beside spec->path. */
thz_status movie_open(const movie_spec *spec, movie_writer **out, thz_error *err);
/* Encodes the next frame: tb (columns * rows, K, row 0 at the top) at time_s. */
thz_status movie_add_frame(movie_writer *m, const float *tb, double time_s, thz_error *err);
/* Finishes the file and renames it to spec->path. */
thz_status movie_finish(movie_writer *m, thz_error *err);
/* Frees; removes the temporary file if not finished. NULL: nothing. */
void movie_destroy(movie_writer *m);
/* The encoder's name: "libx264", or "mpeg4" where libavcodec lacks libx264 (valid while
 * m lives). */
const char *movie_codec(const movie_writer *m);

#endif
