/* Writing a run's results (scene-format.md "Outputs").
 *
 * Atomic results: every file of a run is written into a staging directory beside OUTDIR
 * and the finished run replaces OUTDIR's previous one in a single directory exchange, so
 * that a failed, interrupted or killed run leaves OUTDIR holding the previous results or
 * the new ones, each whole (docs/reliability.md; output_commit.c has the steps). Files
 * of OUTDIR that the run does not write are kept. A lock keeps a second run out of an
 * OUTDIR in use, and a run cleans up what a killed run left beside its OUTDIR.
 */
#ifndef THZ_IO_OUTPUT_H
#define THZ_IO_OUTPUT_H

#include <stddef.h>
#include <stdint.h>

#include "core/cancel.h"
#include "core/error.h"
#include "photon/photon_stats.h"
#include "run/run_noise.h"
#include "scene/scene.h"
#include "sensor/images.h"
#include "thzmap/run.h"

typedef struct output_stage output_stage;

/* Takes OUTDIR's lock (THZ_ERR_IO naming the process that holds it), cleans up what
 * killed runs left, and creates a fresh staging directory: beside OUTDIR, or inside it
 * when OUTDIR is a mount point or the working directory. Creates missing parents (and
 * removes them again if the run fails). OUTDIR itself appears only on commit. */
thz_status output_stage_create(const char *outdir, output_stage **out, thz_error *err);

/* The directory writers write into (the staging directory). */
const char *output_stage_dir(const output_stage *stage);

/* A writer's error names the staging directory's file, a name the user never sees: the
 * same message naming OUTDIR's file instead ("OUTDIR/S.radiance.img: write failed: ...").
 * Any other message is left as it is. */
void output_stage_error_names_outdir(const output_stage *stage, thz_error *err);

/* Claims for this run the names of OUTDIR's files that it may write: the commit keeps
 * no earlier run's file of a claimed name that this run did not write (a sensor's
 * measured cubes once its noise is gone, the figures of channels it no longer has,
 * bands-air.png of a scene whose air attenuated), so that what OUTDIR holds under a
 * claimed name is this run's alone. output_stage_claim: one file name;
 * output_stage_claim_sensor: every name the files of sensor `sensor` may have
 * (output_sensor_file). OUTDIR's other files stay. THZ_ERR_NOMEM, or THZ_ERR_INPUT for a
 * sensor name too long for a file name (the loader's limit keeps them shorter). */
thz_status output_stage_claim(output_stage *stage, const char *name, thz_error *err);
thz_status output_stage_claim_sensor(output_stage *stage, const char *sensor, thz_error *err);

/* Makes the staged files OUTDIR's results (replacing files of the same name, removing
 * the claimed ones the run did not write, keeping the others) and removes the staging
 * directory. All or nothing: on failure (e.g.
 * OUTDIR holds a directory where the run writes a file) OUTDIR keeps exactly the
 * previous results, and the error says so. */
thz_status output_stage_commit(output_stage *stage, thz_error *err);

/* Removes the staging directory and whatever it holds if not committed, releases the
 * lock; frees. NULL: nothing. */
void output_stage_destroy(output_stage *stage);

/* The name of a sensor's file, "S.<quantity><ext>" with every '/' of the sensor's name
 * replaced by '_' so that the file lands in its directory: the one rule by which runs
 * name their files and readers (classify, the GUI) find them. False when it does not
 * fit in size bytes. */
bool output_file_name(char *buf, size_t size, const char *sensor, const char *quantity,
                      const char *ext);

/* The quantity of a plane in its files' names ("S.<quantity>.hdr"; the visual plane's
 * file is S.visual.png): thz_plane_name's answer. NULL for no plane. */
const char *output_plane_name(thz_plane plane);

/* Whether `name` is a name output_write_sensor may give a file of the sensor whose file
 * names begin with `stem` ("S.": output_file_name of quantity "" and no extension). */
bool output_sensor_file(const char *stem, const char *name);

/* Writes every file of sensor `sensor` into dir: the ENVI images S.radiance,
 * S.power, S.brightness_temperature, S.normalized (and S.radiance_stderr when
 * images->radiance_stderr is set), S.temperature, S.distance, S.object_id; S.visual.png;
 * S.band-NN.png per channel (its brightness temperature in K, NN from 01);
 * S.spectra.png (mean normalised radiance per object in view against frequency); when
 * the images hold measured planes (sensor/measure.h), S.measured_radiance,
 * S.measured_brightness_temperature and S.measured-band-NN.png, titled with the model.
 * Checks PLplot's pngcairo device before writing anything (THZ_ERR_IO if missing).
 * The PNG figures are drawn last, by up to `threads` child processes at once (0: one
 * per processor; io/plot.h's batch): the same files for any count. `cancel` (may be
 * NULL) stops them (THZ_ERR_CANCELLED). */
thz_status output_write_sensor(const char *dir, const thz_scene *scene, size_t sensor,
                               const sensor_images *images, int threads, const cancel_check *cancel,
                               thz_error *err);

/* What summary.json reports beyond the scene. */
typedef struct run_summary {
    const char *command;    /* "simulate" or "render" */
    const char *integrator; /* "photon-map", ... */
    uint64_t seed;
    uint64_t photons_per_channel;
    int threads;
    int mpi_ranks;                     /* processes that shared the run (docs/mpi.md); 1: alone */
    const photon_stats *channel_stats; /* n_channels entries, or NULL (render) */
    const run_noise *noise;            /* n_channels entries, or NULL */
    const run_noise *object_noise;     /* [channel * n_objects + object], or NULL */
    const char *target_source;         /* "command line", "scene", "default", NULL */
    const uint32_t *passes;            /* n_channels entries: render passes, or NULL */
    const double *seconds_render_channel; /* n_channels entries: render time (s), or NULL */
    double target_noise_k;                /* the run's noise target (K), 0: none */
    uint64_t *back_face_samples;          /* per sensor: samples that saw a back face, or NULL */
    double seconds_load, seconds_accel, seconds_photons, seconds_render, seconds_output;
    size_t n_run_warnings;
    const char *const *run_warnings;
} run_summary;

/* Writes dir/summary.json: version, scene name, seed, per-channel photons fired and
 * stored, emitted power P_A, run statistics and energy balance, timings, warnings. */
thz_status summary_write(const char *dir, const thz_scene *scene, const run_summary *summary,
                         thz_error *err);

/* The same document as text (malloc'd; NULL with err set when out of memory). */
char *summary_text(const thz_scene *scene, const run_summary *summary, thz_error *err);

#endif
