/* thzmap public API: analysis of simulated images (include thzmap/thzmap.h, which
 * includes this): reading a run's ENVI cubes back, material recognition against the
 * object_id truth (`thzmap classify`), and the choice of channel frequencies that best
 * separate a scene's targets (`thzmap bands`). docs/analysis.md describes the methods.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_ANALYSIS_H
#define THZMAP_ANALYSIS_H

#ifdef __cplusplus
extern "C" {
#endif

/* ---- cubes -------------------------------------------------------------------------- */

/* An image of float32 values, band-sequential: read from an ENVI file (either byte
 * order), or made of the caller's values. The classifiers take either kind. */
typedef struct thz_cube thz_cube;

/* Reads DIR/STEM.hdr and DIR/STEM.img (e.g. stem "cam.brightness_temperature").
 * THZ_ERR_INPUT naming the file (and the header's line) when one is missing, too large
 * (header 1 MiB, data 16 GiB), or not what its header says. */
THZ_API thz_status thz_cube_read(const char *dir, const char *stem, thz_cube **out, thz_error *err);
/* A cube of the caller's values: `bands` planes of rows x columns, laid out as
 * thz_cube_data gives them (value(band, row, col) at [(band * rows + row) * columns +
 * col]), copied (data stays the caller's). `name` (NULL: "cube") stands for the file stem
 * in messages and in the classification's source, e.g. "spectra" or "truth". A truth for
 * thz_classify_cube is such a cube of one band holding object indices (-1: none) as
 * floats. Any float value is taken, as from a file: thz_classify_cube refuses one that is
 * not finite. No wavelength (thz_cube_wavelength_ghz gives NULL), no object names.
 * THZ_ERR_INPUT beginning with the name when data is NULL, a size is 0, bands is above
 * 2^20, or the values' bytes overflow a size_t. */
THZ_API thz_status thz_cube_create(const char *name, uint32_t columns, uint32_t rows, size_t bands,
                                   const float *data, thz_cube **out, thz_error *err);
/* Gives the cube the `object names` thz_classify_cube names a truth's classes by (name i:
 * object index i), copies of names[0 .. n-1], replacing any it had (n 0: none).
 * THZ_ERR_INPUT for a NULL cube, names NULL with n > 0, or a NULL or empty name; the cube
 * keeps its names then. */
THZ_API thz_status thz_cube_set_object_names(thz_cube *cube, const char *const *names, size_t n,
                                             thz_error *err);
THZ_API void thz_cube_destroy(thz_cube *cube);
THZ_API uint32_t thz_cube_columns(const thz_cube *cube);
THZ_API uint32_t thz_cube_rows(const thz_cube *cube);
THZ_API size_t thz_cube_bands(const thz_cube *cube);
/* value(band, row, col) at [(band * rows + row) * columns + col]; owned by the cube. */
THZ_API const float *thz_cube_data(const thz_cube *cube);
/* The `wavelength` list in GHz (`bands` values) when the header gives it in GHz, else NULL. */
THZ_API const double *thz_cube_wavelength_ghz(const thz_cube *cube);
/* The `object names` list of an object_id image: count, and name i (NULL past the end). */
THZ_API size_t thz_cube_object_name_count(const thz_cube *cube);
THZ_API const char *thz_cube_object_name(const thz_cube *cube, size_t i);

/* ---- classification ----------------------------------------------------------------- */

typedef struct thz_classify_options {
    const char *method;    /* "sam" (default; refused on a cube of 1 band), "mahalanobis",
                              "lda", "matched-filter", "ace" */
    double train_fraction; /* of each class's pixels that train, 0 < f < 1; default 0.5 */
    uint64_t seed;         /* chooses the training pixels and the added noise, 0 to INT64_MAX;
                              default 1 */
    double netd_k;         /* > 0: first add Gaussian noise of this standard deviation (K)
                              to every value (a sensor's NETD on a noise-free run); 0: none */
} thz_classify_options;

THZ_API void thz_classify_options_init(thz_classify_options *opt);
/* The methods' names, i = 0, 1, ...; NULL past the last. */
THZ_API const char *thz_classify_method(size_t i);

typedef struct thz_classification thz_classification;

/* Classifies every pixel of `cube` whose `truth` (a one-band cube of object indices,
 * -1 where nothing is hit, as S.object_id) is >= 0; the classes are the objects the
 * truth shows, named by its object names (else "object N"). Either cube may be read
 * (thz_cube_read) or made (thz_cube_create: spectra pooled over several runs, say).
 * opt NULL: thz_classify_options_init's defaults. *out owns the result; the cubes stay
 * the caller's. THZ_ERR_INPUT, naming the cube by its stem or name, when the two differ
 * in size, the truth has more than one band, holds a value other than -1 or a whole
 * number 0 to 2^24 - 1, or shows fewer than two objects, or a value of `cube` is not
 * finite (named by band, row and column, from 1). */
THZ_API thz_status thz_classify_cube(const thz_cube *cube, const thz_cube *truth,
                                     const thz_classify_options *opt, thz_classification **out,
                                     thz_error *err);
/* The same on a run directory (what `thzmap simulate` wrote): sensor S's
 * S.measured_brightness_temperature when there is one, else S.brightness_temperature,
 * against S.object_id. A sensor the run lacks (neither cube there): THZ_ERR_INPUT,
 * naming the sensors the run has (by its *.brightness_temperature.hdr files). */
THZ_API thz_status thz_classify_run(const char *run_dir, const char *sensor,
                                    const thz_classify_options *opt, thz_classification **out,
                                    thz_error *err);
THZ_API void thz_classification_destroy(thz_classification *c);

typedef struct thz_classification_info {
    const char *method;
    const char *sensor; /* NULL for thz_classify_cube */
    const char *source; /* the cube's file stem, e.g. "cam.brightness_temperature", or the
                           name it was made with */
    size_t n_classes;
    uint32_t columns, rows;
    uint64_t pixels; /* classified: the truth is >= 0; the confusion matrix sums to this */
    uint64_t training_pixels, held_out_pixels;
    double accuracy;          /* over every classified pixel, 0..1 */
    double held_out_accuracy; /* over the held-out pixels, 0..1 (NaN: none) */
} thz_classification_info;

THZ_API void thz_classification_get_info(const thz_classification *c, thz_classification_info *out);
/* Class k's object index (-1 when k is out of range) and name ("object N" when the
 * truth has no names). */
THZ_API long thz_classification_class_object(const thz_classification *c, size_t k);
THZ_API const char *thz_classification_class_name(const thz_classification *c, size_t k);
/* Class k's pixels assigned to it / its pixels, and its ROC area one against the rest
 * on the held-out pixels (NaN when k is out of range or not defined). */
THZ_API double thz_classification_class_accuracy(const thz_classification *c, size_t k);
THZ_API double thz_classification_auc(const thz_classification *c, size_t k);
/* [truth class * n_classes + assigned class], pixel counts. */
THZ_API const uint64_t *thz_classification_confusion(const thz_classification *c);
/* Per pixel (rows x columns, row 0 at the top) the object index of the assigned class,
 * -1 where the truth is -1. */
THZ_API const int32_t *thz_classification_map(const thz_classification *c);
/* Per pixel (as _map) 1 where the pixel trained the class statistics (a seeded
 * train_fraction of each class, at least one pixel), 0 where it was held out or not
 * classified: the split that held_out_accuracy and the AUCs are measured on. */
THZ_API const uint8_t *thz_classification_training(const thz_classification *c);
/* classification.json as text (owned by c). */
THZ_API const char *thz_classification_json(const thz_classification *c);
/* Writes classification.json, S.class.hdr/.img (ENVI float32: object index per pixel,
 * -1 where nothing is hit) and S.class.png into outdir, atomically (thz_output); S is
 * the sensor, or "cube" for thz_classify_cube. */
THZ_API thz_status thz_classification_write(const thz_classification *c, const char *outdir,
                                            thz_error *err);

/* ---- band selection ----------------------------------------------------------------- */

/* The most channels thz_bands_select chooses (opt->count). */
#define THZ_BANDS_MAX_COUNT 32

typedef struct thz_bands_options {
    size_t count;               /* K, channels to choose, 1 to THZ_BANDS_MAX_COUNT (required) */
    double from_thz;            /* candidate centres from .. to, both included; default 0.1 */
    double to_thz;              /* default 1.5 */
    double step_ghz;            /* default 10 */
    double relative_width;      /* of every candidate; 0: the scene's first channel's (of a
                                   measured response: its FWHM / centre, at most 0.5) */
    const char *sensor;         /* NULL: the scene's first */
    const char *const *targets; /* n_targets object names (not NULL; else THZ_ERR_INPUT);
                                   n_targets 0: every object the sensor sees */
    size_t n_targets;
    int has_netd;  /* non-zero: netd_k for every candidate; 0: the sensor's noise (its netd_k
                      interpolated in frequency to the candidates, or its radiometer NETD
                      for each candidate's bandwidth), or netd_k when it has none */
    double netd_k; /* K, >= 0; default 0.5 */
    double target_temperature_range_k;  /* each target's temperature varies within +- this
                                           (uniformly, independently), K; default 2 */
    double ambient_temperature_range_k; /* the other objects' and the air's temperature
                                           (also when it follows the enclosure's)
                                           together, +- K; default 2 */
    double humidity_range;              /* the air's humidity within +- this fraction of the scene's
                                           value (0.2: +- 20 %); default 0.2 */
    uint32_t paths_per_sample;          /* path integrator paths per sample; default 16 */
    int has_seed;                       /* non-zero: `seed` instead of the scene's */
    uint64_t seed;                      /* 0 to INT64_MAX, like photons.seed */
    uint64_t exhaustive_limit;          /* search every subset when there are at most this many of
                                           sizes 1..K (default 2000000), else SFFS */
    /* Channel widths searched too: every centre is a candidate with each of these n_widths
     * relative widths (FWHM / centre, 0 < w <= 0.5, distinct); a chosen set holds each
     * centre at most once. n_widths 0: relative_width alone. */
    const double *relative_widths;
    size_t n_widths;
    double thickness_range; /* every shell's thickness within +- this fraction of its own
                               (0.2: +- 20 %), 0 <= f < 1; default 0 (not varied) */
    double angle_range_deg; /* the viewing angle within +- this: the sensor turned about its
                               up axis around its look_at_m point (about its own position
                               when it gives a direction), 0 <= a <= 90 degrees; default 0 */
    const char *root;       /* NULL (default), or the directory the scene and every file it names
                               must lie under (thz_scene_load_within; thzmap serve --root) */
} thz_bands_options;

THZ_API void thz_bands_options_init(thz_bands_options *opt);

/* The candidate centres opt's from_thz, to_thz and step_ghz give: from_thz + i x step
 * up to to_thz (a step landing within 1e-9 of a step of to_thz counts), so a client can
 * check `count` before thz_bands_select loads the scene. 0 when opt is NULL or the
 * range or step is not valid (0 < from <= to, step > 0, all finite). */
THZ_API double thz_bands_candidate_centres(const thz_bands_options *opt);

typedef struct thz_bands thz_bands;

/* Chooses opt->count channel centres (with their widths when opt->n_widths > 0) among
 * the candidates for the scene file at `scene_path`: renders the scene (path
 * integrator) with the candidates as its channels, nominal and with each nuisance
 * changed, takes each class's pixels from the object_id truth, and searches the set
 * that maximises the worst pair's Bhattacharyya distance (docs/analysis.md). Progress
 * and cancellation through ctx. */
THZ_API thz_status thz_bands_select(thz_context *ctx, const char *scene_path,
                                    const thz_bands_options *opt, thz_bands **out, thz_error *err);
THZ_API void thz_bands_destroy(thz_bands *b);

typedef struct thz_bands_info {
    size_t n_candidates, count, n_classes; /* candidates: centres x widths */
    const char *search;                    /* "exhaustive" or "sffs" */
    double score; /* worst-pair Jeffries-Matusita distance of the chosen set, 0..2 */
} thz_bands_info;
THZ_API void thz_bands_get_info(const thz_bands *b, thz_bands_info *out);
/* The chosen centre i (ascending), THz; NaN past the end. */
THZ_API double thz_bands_selected_thz(const thz_bands *b, size_t i);
/* The relative width (FWHM / centre) of chosen channel i, aligned with
 * thz_bands_selected_thz; NaN past the end. */
THZ_API double thz_bands_selected_relative_width(const thz_bands *b, size_t i);
/* The best set's worst-pair Jeffries-Matusita distance with k = 1..count channels. */
THZ_API double thz_bands_score(const thz_bands *b, size_t k);
/* bands.json as text (owned by b). */
THZ_API const char *thz_bands_json(const thz_bands *b);
/* Writes bands.json, bands-score.png, bands-spectra.png and bands-air.png into outdir,
 * atomically (thz_output). */
THZ_API thz_status thz_bands_write(const thz_bands *b, const char *outdir, thz_error *err);

#ifdef __cplusplus
}
#endif
#endif
