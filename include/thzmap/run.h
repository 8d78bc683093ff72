/* thzmap public API: runs (include thzmap/thzmap.h, which includes this).
 *
 * A run has two phases (physics.md): the photon phase fires photons per channel into
 * photon maps (a thz_photons), the rendering phase turns them into the images of a
 * sensor (a thz_image). thz_simulate does both for every sensor into a thz_run, as
 * `thzmap simulate` does; thz_render_run renders from existing photons, as `thzmap
 * render` does. Writing to disk is separate (thz_run_write, thz_image_write, and
 * thz_output for staging several writes into one atomic result).
 *
 * The same scene, settings and seed give bit-identical images, photon maps and files
 * for any thread count, in memory or written. Long calls report progress and can be
 * cancelled through the context (THZ_ERR_CANCELLED: nothing is returned or written).
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_RUN_H
#define THZMAP_RUN_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct thz_photons thz_photons;
typedef struct thz_image thz_image;
typedef struct thz_run thz_run;
typedef struct thz_output thz_output;

/* ---- settings ----------------------------------------------------------------------- */

/* What thz_simulate is about to do, told before the work starts: the estimate of a
 * short pilot (time per sample and per photon times the counts; with a target, the
 * passes from the pilot's noise). An estimate, not a promise. */
typedef struct thz_run_plan {
    double seconds_photons, seconds_render; /* estimated, s */
    /* estimated passes of the channel that needs most */
    uint32_t passes;
    /* estimated peak, bytes: what the process holds already (the scene, its ray-casting
     * structure) and what the run adds */
    uint64_t memory_bytes;
    /* what the process may have: the machine's memory, or less under an address-space
     * (ulimit -v) or cgroup limit; 0 if unknown */
    uint64_t available_bytes;
    double target_noise_k; /* the run's noise target, K; 0: none */
    /* "command line" (settings), "scene", "default" or NULL */
    const char *target_source;
    /* non-zero: photon-map's photon passes (a noise target) will stop at the memory they
     * may hold, half of available_bytes, above the target, after `passes` passes */
    int memory_stop;
} thz_run_plan;
typedef void (*thz_plan_fn)(void *user, const thz_run_plan *plan);

/* Per-run overrides of the scene's settings: zero / NULL keeps the scene's value.
 * Initialise with thz_run_settings_init (or = {0}); a NULL settings pointer means all
 * defaults. */
typedef struct thz_run_settings {
    uint64_t photons_per_channel; /* photons.per_channel; 0: the scene's */
    int has_seed;                 /* non-zero: `seed`, 0 to INT64_MAX, not photons.seed */
    uint64_t seed;
    const char *integrator; /* "photon-map", "final-gather", "path"; NULL: the scene's */
    double target_noise_k;  /* > 0: add passes to each channel until the 95th percentile
                               over pixels of the per-pixel standard error of Tb_c is at
                               most this (K); overrides render.target_noise_k (default
                               0.1 K where the scene gives no count) */
    double max_seconds;     /* > 0: stop adding passes after this (s) */
    int keep_photons;       /* thz_simulate: keep the photon maps in the run (needed to
                               write photon-map.thzpm); THZ_ERR_INPUT with the path
                               integrator, which fires none */
    uint64_t first_photon;  /* thz_photons_fire*: fire photons first_photon .. + K - 1, so that
                               maps fired with disjoint ranges merge (thz_photons_merge;
                               a range past 2^64 - 1 is refused) */
    double seconds_load;    /* reported in summary.json (timings_s.load); 0: unknown */
    thz_plan_fn plan;       /* thz_simulate and thz_render_run: called once with the
                               estimate before the work (its pilot costs a moment: only
                               when set); may be NULL */
    void *plan_user;
} thz_run_settings;

THZ_API void thz_run_settings_init(thz_run_settings *settings);

/* ---- the photon phase ----------------------------------------------------------------- */

/* Statistics of one channel's photon phase (summary.json "channels"). */
typedef struct thz_photon_stats {
    uint64_t fired, stored, hits, reflected, transmitted, absorbed, escaped;
    uint64_t back_face_hits, terminated, bounce_capped, rays;
    double emitted_power_w_per_hz;  /* band mean P_A of the scene's sources */
    double fired_power_w_per_hz;    /* sum of the photons' initial powers */
    double absorbed_power_w_per_hz; /* the energy balance: absorbed + escaped + */
    double escaped_power_w_per_hz;  /* atmosphere + terminated = fired */
    double atmosphere_power_w_per_hz;
    double terminated_power_w_per_hz;
    double mean_bounces;
    double reference_temperature_k; /* T0 of a deviation map (final-gather), 0: map of L */
    double seconds;                 /* wall time of the phase (0 when read from a file) */
} thz_photon_stats;

/* Fires the photons of every channel (integrator, photon count, seed and first_photon
 * from settings over the scene). *out owns the maps; `scene` must outlive it. */
THZ_API thz_status thz_photons_fire(thz_context *ctx, const thz_scene *scene,
                                    const thz_run_settings *settings, thz_photons **out,
                                    thz_error *err);
/* The same for channel `channel` only. The other channels hold no map: such photons
 * merge and give statistics, but rendering and saving refuse them (THZ_ERR_INPUT). */
THZ_API thz_status thz_photons_fire_channel(thz_context *ctx, const thz_scene *scene,
                                            const thz_run_settings *settings, size_t channel,
                                            thz_photons **out, thz_error *err);
/* Reads a photon-map file (.thzpm) made from `scene`; refuses one made from another
 * scene geometry, material or channel set (THZ_ERR_INPUT) or a damaged one. `scene`
 * must outlive *out. */
THZ_API thz_status thz_photons_load(thz_context *ctx, const thz_scene *scene, const char *path,
                                    thz_photons **out, thz_error *err);
/* The same for channel `channel` alone (for a view of its photons: the other channels'
 * records are checked and dropped, and hold no map, as after thz_photons_fire_channel;
 * their statistics are read). THZ_ERR_INPUT when the scene has no such channel. */
THZ_API thz_status thz_photons_load_channel(thz_context *ctx, const thz_scene *scene,
                                            const char *path, size_t channel, thz_photons **out,
                                            thz_error *err);
/* Writes every channel's map to `path` (.thzpm, what `render` reads); THZ_ERR_INPUT
 * when a channel has no map. Written beside `path` and renamed over it once whole: a
 * reader of the previous file keeps it whole, and a failed save leaves it as it was
 * (what is not a regular file, such as /dev/null, is written through in place). */
THZ_API thz_status thz_photons_save(const thz_photons *photons, const char *path, thz_error *err);
/* Merges n photon sets of one scene, seed and integrator, fired with disjoint photon
 * ranges (or for different channels), into one of all their photons (*out; the parts
 * stay the caller's). Parts of different scene handles merge when the scenes fit one
 * another as thz_render_run's photons must; *out belongs to part 0's scene. Each channel
 * of *out holds the parts' photons of that channel; its photons_per_channel is per
 * channel the sum over the parts that hold the channel, and the largest of these sums
 * when they differ between channels. THZ_ERR_INPUT when a part is given twice, or when
 * two parts hold the same photons of a channel: a map fired here knows its photons
 * (first_photon .. + K - 1), a simulation's kept map (thz_run_photons) its
 * 0 .. fired - 1, a merged map the union of its parts'; a loaded map does not know its
 * photons, so that check cannot see them. */
THZ_API thz_status thz_photons_merge(thz_context *ctx, const thz_photons *const *parts, size_t n,
                                     thz_photons **out, thz_error *err);
THZ_API void thz_photons_destroy(thz_photons *photons);

THZ_API size_t thz_photons_channel_count(const thz_photons *photons);
/* Whether channel c holds a map (1) or not (0). */
THZ_API int thz_photons_has_channel(const thz_photons *photons, size_t c);
/* The seed and photons per channel they were fired with (merged photons: see
 * thz_photons_merge; thz_photons_stats' `fired` is each channel's own count). */
THZ_API uint64_t thz_photons_seed(const thz_photons *photons);
THZ_API uint64_t thz_photons_per_channel(const thz_photons *photons);
/* Fills *out with channel c's statistics; THZ_ERR_INPUT when c is out of range. */
THZ_API thz_status thz_photons_stats(const thz_photons *photons, size_t c, thz_photon_stats *out);

/* A stored photon of a channel's map, for display (the paper's Fig. 3). */
typedef struct thz_photon_point {
    float position_m[3];  /* hit point, world space, m */
    float direction[3];   /* unit direction of travel as it arrived */
    float power_w_per_hz; /* spectral power it carried there (negative in deviation maps) */
    uint32_t object;      /* index of the object hit */
} thz_photon_point;
/* The photons stored in channel c's map (0 when it has none). */
THZ_API size_t thz_photons_count(const thz_photons *photons, size_t c);
/* Copies photons first .. first + n - 1 of channel c (in the map's order, grouped by
 * object) into out[n]; returns how many were copied (fewer past the end; 0 when out is
 * NULL). */
THZ_API size_t thz_photons_points(const thz_photons *photons, size_t c, size_t first, size_t n,
                                  thz_photon_point *out);

/* ---- images ------------------------------------------------------------------------- */

/* The planes of a sensor's image (scene-format.md "Outputs"). Row 0 is the top of the
 * picture, column 0 the left. Channel cubes (RADIANCE .. NORMALIZED, MEASURED_*) have one band per
 * channel, band-sequential: value(c, row, col) at [(c * rows + row) * columns + col]. */
typedef enum thz_plane {
    THZ_PLANE_RADIANCE = 0,           /* L_c, W m^-2 sr^-1 Hz^-1 */
    THZ_PLANE_RADIANCE_STDERR,        /* standard error of L_c (absent: not estimated) */
    THZ_PLANE_POWER,                  /* P_c on the pixel, W */
    THZ_PLANE_BRIGHTNESS_TEMPERATURE, /* Tb_c, K */
    THZ_PLANE_NORMALIZED,             /* N_c = L_c / B(T_ref), 1 */
    THZ_PLANE_TEMPERATURE,            /* 1 band: temperature of the surface seen, K (-1: none) */
    THZ_PLANE_DISTANCE,               /* 1 band: distance to the surface seen, m (-1: none) */
    THZ_PLANE_OBJECT_ID,              /* 1 band: object index as float, -1: nothing hit */
    THZ_PLANE_VISUAL_RGB,             /* 3 bands, pixel-interleaved: [(row * columns + col)
                                       * 3 + k], shaded colour 0..1 */
    /* The sensor as built (scene-format.md "Sensors: optics and noise"), channel cubes;
     * absent (NULL) unless the sensor has a PSF or noise: */
    THZ_PLANE_MEASURED_RADIANCE,               /* L_c through the PSF, plus noise */
    THZ_PLANE_MEASURED_BRIGHTNESS_TEMPERATURE, /* Tb_c of the measured L_c, K */
    THZ_PLANE_COUNT
} thz_plane;

/* Renders sensor `sensor` of the scene: from `photons` (their seed, every channel; made
 * for this scene or one that fits it, as for thz_render_run), or
 * with photons NULL for the path integrator (seed from settings or the scene). With a
 * noise target, passes stop on the 95th percentile of this sensor's error. *out owns the image,
 * which borrows the scene (destroy or write it first). */
THZ_API thz_status thz_render_sensor(thz_context *ctx, const thz_scene *scene,
                                     const thz_photons *photons, size_t sensor,
                                     const thz_run_settings *settings, thz_image **out,
                                     thz_error *err);
THZ_API void thz_image_destroy(thz_image *image);

THZ_API uint32_t thz_image_columns(const thz_image *image);
THZ_API uint32_t thz_image_rows(const thz_image *image);
THZ_API size_t thz_image_channel_count(const thz_image *image);
/* The sensor's index in its scene and its name (the image's own copy: valid after the
 * scene is destroyed, until the image or its run is). */
THZ_API size_t thz_image_sensor(const thz_image *image);
THZ_API const char *thz_image_sensor_name(const thz_image *image);
/* The plane's values (owned by the image) and its band count (1, 3 or the channels)
 * in *n_bands (may be NULL); NULL (and 0 bands) when the plane is absent. */
THZ_API const float *thz_image_plane(const thz_image *image, thz_plane plane, size_t *n_bands);
/* The plane's file quantity ("radiance", "object_id", "visual", ...); static. */
THZ_API const char *thz_plane_name(thz_plane plane);

/* Writes the image's files (S.radiance, ... ENVI; S.visual.png, S.band-NN.png,
 * S.spectra.png) into `dir` (created if missing), atomically like a run: ctx's threads
 * bound the figure processes and its progress callback hears the "output" stage (done 0
 * then 1 of 1) and may cancel it (THZ_ERR_CANCELLED, `dir` as it was). */
THZ_API thz_status thz_image_write(thz_context *ctx, const thz_image *image, const char *dir,
                                   thz_error *err);

/* ---- whole runs ----------------------------------------------------------------------- */

/* `thzmap simulate` in memory: per channel the photon phase (none for path), then every
 * sensor rendered. *out owns the images, the photons if settings->keep_photons, and the
 * summary; it borrows the scene, which must outlive it (thz_run_write reads it). */
THZ_API thz_status thz_simulate(thz_context *ctx, const thz_scene *scene,
                                const thz_run_settings *settings, thz_run **out, thz_error *err);
/* What thz_simulate checks before its first photon, alone (a batch checks every frame
 * before it runs one): THZ_ERR_LIMIT, with the message thz_simulate would give, when
 * the run would not fit in the memory the process may have. Builds the scene's
 * ray-casting structure and fires a pilot of photons per channel to estimate; keeps
 * nothing. */
THZ_API thz_status thz_simulate_check(thz_context *ctx, const thz_scene *scene,
                                      const thz_run_settings *settings, thz_error *err);
/* `thzmap render` in memory: every sensor (sensor -1) or only sensor `sensor` (0 ..
 * count - 1; any other index is refused with THZ_ERR_INPUT) rendered from `photons`
 * (NULL only for path). The run's seed and photon count are the photons'. `photons` may
 * have been made for another scene handle whose geometry, channels, materials,
 * temperatures and atmosphere are `scene`'s (one that differs in its sensors: a new
 * viewpoint), as `render --photon-map` takes a file; else THZ_ERR_INPUT says which
 * differs. Their own scene must be alive (photons never outlive it); the run holds
 * nothing of the photons once made, and borrows `scene` as thz_simulate's does. */
THZ_API thz_status thz_render_run(thz_context *ctx, const thz_scene *scene,
                                  const thz_photons *photons, long sensor,
                                  const thz_run_settings *settings, thz_run **out, thz_error *err);
/* The same from a photon-map file (.thzpm) made from `scene`, read one channel at a time
 * as the render comes to it: it holds one channel's map, not every channel's as
 * thz_photons_load + thz_render_run do (what `thzmap render --photon-map` runs). Refuses
 * the file as thz_photons_load does, before any work; damage in a later channel's
 * records is found when that channel is read, and fails the run then. */
THZ_API thz_status thz_render_file(thz_context *ctx, const thz_scene *scene, const char *path,
                                   long sensor, const thz_run_settings *settings, thz_run **out,
                                   thz_error *err);
THZ_API void thz_run_destroy(thz_run *run);

/* The rendered sensors: count, and image i (borrowed from the run; NULL if out of range). */
THZ_API size_t thz_run_image_count(const thz_run *run);
THZ_API const thz_image *thz_run_image(const thz_run *run, size_t i);
/* The run's photons (borrowed), or NULL when not kept. */
THZ_API const thz_photons *thz_run_photons(const thz_run *run);
/* summary.json as text (the file thz_run_write writes, but for timings_s.output). */
THZ_API const char *thz_run_summary_json(const thz_run *run);

/* What the closing line of the CLI reports. */
typedef struct thz_run_totals {
    size_t n_channels;
    size_t n_sensors;       /* rendered */
    uint64_t photons_fired; /* over all channels (0 for a render run) */
    uint64_t photons_stored;
    uint64_t back_face_samples;
    size_t n_warnings;            /* the run's own (summary.json adds the scene's) */
    double worst_median_stderr_k; /* largest median per-pixel standard error of Tb_c, K;
                                     these three are INFINITY when the figure falls on
                                     pixels whose error is unknown (photon-map samples
                                     short of photons: summary.json starved_pixels) */
    uint32_t max_passes;          /* most render passes of any channel */
    double seconds;               /* wall time of the run */
    double worst_p95_stderr_k;    /* largest 95th percentile of the per-pixel standard
                                     error of Tb_c over channels, K */
    long worst_object;            /* the object whose pixels' 95th percentile is largest
                                     (over channels), -1 when none was seen */
    size_t worst_object_channel;
    double worst_object_p95_stderr_k; /* K */
} thz_run_totals;
THZ_API void thz_run_get_totals(const thz_run *run, thz_run_totals *out);

/* ---- writing ---------------------------------------------------------------------------- */

typedef struct thz_write_options {
    int photon_map;          /* also photon-map.thzpm and photon-map.ply (kept photons) */
    uint64_t ply_max_points; /* photons in photon-map.ply at most; 0: 2000000 */
} thz_write_options;

/* Writes every file of the run into `outdir` (created if missing): per sensor as
 * thz_image_write, summary.json, and the photon map if asked (opt may be NULL). Files
 * appear only when all were written (thz_output); a failure or cancellation leaves
 * outdir as it was. The PNG figures are drawn in child processes (docs/reliability.md),
 * as many at once as the threads the run was made with; the files do not depend on it.
 * Records the time writing took in the summary.json it writes (the run is modified). */
THZ_API thz_status thz_run_write(thz_context *ctx, thz_run *run, const char *outdir,
                                 const thz_write_options *opt, thz_error *err);

/* An atomic result directory (docs/reliability.md): files go into a staging directory
 * beside `outdir`, which holds outdir's lock (a second output into it fails with
 * THZ_ERR_IO), and become outdir's results on thz_output_commit, all or nothing;
 * destroying an uncommitted output removes them. Outdir's other files stay, but for an
 * earlier run's files of the sensors added (thz_output_add_run, _add_image) and, when a
 * simulation is added, its photon map: those this output does not write are removed, so
 * that what outdir holds of a sensor is one run's. Open it before a long run to fail
 * early on a bad or busy outdir. */
THZ_API thz_status thz_output_open(const char *outdir, thz_output **out, thz_error *err);
THZ_API thz_status thz_output_add_run(thz_context *ctx, thz_output *output, thz_run *run,
                                      const thz_write_options *opt, thz_error *err);
/* thz_output_add_image draws the image's figures with up to one child process per
 * processor at once (it has no context). */
THZ_API thz_status thz_output_add_image(thz_output *output, const thz_image *image, thz_error *err);
/* Adds a file of the caller's (`name`: a plain file name, no '/') holding `size` bytes
 * of `data` (may be NULL when size is 0), committed with the rest (e.g. a batch frame's
 * frame.json). THZ_ERR_INPUT when the output holds that name already (added before, or
 * one of an added run's files, such as summary.json): nothing is replaced. Add a run
 * first: thz_output_add_run writes its files over any of the same names. A failed write
 * removes the file, so that it may be added again. */
THZ_API thz_status thz_output_add_file(thz_output *output, const char *name, const void *data,
                                       size_t size, thz_error *err);
/* Once committed, the output takes nothing more: thz_output_commit again and the
 * thz_output_add_* functions return THZ_ERR_INPUT ("already committed"). A run or image
 * whose writing failed part way (a full disk: THZ_ERR_IO) leaves the output failed: its
 * commit and further adds return THZ_ERR_INPUT and nothing of it reaches outdir; destroy
 * it (which removes the staged files) and open another. (thz_output_add_file's failure
 * removes its file and leaves the output as it was.) */
THZ_API thz_status thz_output_commit(thz_output *output, thz_error *err);
THZ_API void thz_output_destroy(thz_output *output);

#ifdef __cplusplus
}
#endif
#endif
