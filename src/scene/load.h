/* Shared by the JSON loader's files (load.c: the document and its warnings; one file
 * per block: load_channels.c, load_materials.c, load_atmosphere.c, load_objects.c,
 * load_sensors.c, load_settings.c (photons and render); load_cursor.c: typed access;
 * load_files.c: the files a scene names, confined to a root when one is set),
 * and by nothing else:
 * the only code that knows JSON. A "cursor" here is a JSON value together with its
 * path in the document (`objects[2].shape.radius_m`), which every content error
 * names, beside the scene file, with what was expected.
 */
#ifndef THZ_SCENE_LOAD_H
#define THZ_SCENE_LOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>

#include "core/csv.h"
#include "core/error.h"
#include "physics/spectrum.h"
#include "scene/scene.h"

/* Parses the JSON text of file f (or, when f is NULL, the string text), rejecting
 * duplicate keys. NULL on failure: *out_of_memory then says whether memory ran out
 * (never reported as a syntax error), otherwise je holds the syntax error
 * (load_json.c). */
json_t *load_json_parse(FILE *f, const char *text, json_error_t *je, bool *out_of_memory);

/* The "format" of a scene file; format 1.1 adds optional keys only (scene-format.md): a
 * file may say so. A sequence file's (batch/), named here for the scene loader's message
 * when it is given one. */
#define LOAD_FORMAT "thzmap-scene/1"
#define LOAD_FORMAT_1_1 "thzmap-scene/1.1"
#define LOAD_SEQUENCE_FORMAT "thzmap-sequence/1"

/* The most a scene file may hold (a sequence and the scenes it lists too): it is refused
 * before it is read (as the CSV reader caps its tables); scenes are kilobytes, inline
 * tables may make them megabytes. */
#define LOAD_MAX_SCENE_BYTES (256u * 1024u * 1024u)

/* Reads the JSON document of the file at path as the scene loader does: a regular file
 * (no FIFO or device: core/file.h) of at most max_bytes, duplicate keys rejected,
 * parsed by load_json_parse. `real` (NULL: path) is what is opened: the real path
 * load_file_confine checked. Errors name label (NULL: path) for the file checks and path
 * with line:column for syntax; running out of memory is THZ_ERR_NOMEM, "while parsing
 * WHAT". *out is the caller's. */
thz_status load_json_file(const char *path, const char *real, const char *label, const char *what,
                          uint64_t max_bytes, json_t **out, thz_error *err);

/* Long enough for any path a sane scene produces; longer ones are cut (messages only). */
#define LOAD_PATH_MAX 512

typedef struct load_ctx {
    const char *label; /* the scene file as named in messages */
    const char *dir;   /* relative file paths in the scene are relative to it */
    const char *root;  /* NULL, or the real path every named file must lie under */
    thz_scene *scene;
    thz_error *err;
    /* what the atmosphere block gave (for the defaults and warnings that need objects) */
    bool non_emitting_air;      /* "emitting": false */
    bool air_temperature_given; /* the air's (itu-p676, lines) or temperature_k */
    bool background_given;      /* background_temperature_k */
    /* load_unique_name's names of the list it checks (an object: name -> index), so that
     * n names cost n lookups, not n^2 / 2 comparisons (20 000 objects took 7.6 s) */
    json_t *names;
    const json_t *names_of; /* the list they are of */
    size_t names_next;      /* the index they were checked up to */
    /* Mesh files more than one object names (load_objects.c): imported once, each object
     * a copy (three objects of one 5 M-triangle scan were imported three times, 30 s) */
    json_t *mesh_uses; /* file name as written -> objects naming it */
    struct load_mesh_copy *mesh_copies;
    size_t n_mesh_copies;
} load_ctx;

/* The temperature of emitting air whose model has none (constant, table) when the
 * scene has no enclosure around its sensors to take it from (scene_checks.h). */
#define LOAD_DEFAULT_AIR_TEMPERATURE_K 293.15

typedef struct load_cursor {
    json_t *value; /* borrowed; NULL when the key is absent */
    char path[LOAD_PATH_MAX];
} load_cursor;

/* A closed, open or half-open interval of accepted numbers; infinite ends allowed. */
typedef struct load_range {
    double lo, hi;
    bool lo_open, hi_open;
} load_range;

#define LOAD_ANY ((load_range){-INFINITY, INFINITY, false, false})
#define LOAD_NONNEGATIVE ((load_range){0.0, INFINITY, false, false})
#define LOAD_POSITIVE ((load_range){0.0, INFINITY, true, false})
/* How far from the origin objects and sensors may lie, m: Embree, in single precision,
 * aborts on rays whose origins pass about 1.8e18 m (objects 1e26 m across did), and at
 * 1e9 m a float's step is 64 m already. */
#define LOAD_MAX_COORDINATE_M 1e9
#define LOAD_COORDINATE ((load_range){-LOAD_MAX_COORDINATE_M, LOAD_MAX_COORDINATE_M, false, false})
/* A sensor's aperture area, m^2: up to a square kilometre, far beyond any sensor and far
 * from the 32-bit power cube's overflow; its diameter, m, up to a kilometre (a circle of
 * 0.79 km^2). Down to a square micrometre and a micrometre: from D = 1e-20 m the power
 * cube (float, proportional to the area) was all 0, and at 1e-170 m the Airy profile's
 * D^2 underflowed into an empty PSF kernel (an internal error, no JSON path). */
#define LOAD_APERTURE_M2 ((load_range){1e-12, 1e6, false, false})
#define LOAD_MIN_APERTURE_DIAMETER_M 1e-6
#define LOAD_MAX_APERTURE_DIAMETER_M 1000.0
#define LOAD_UNIT ((load_range){0.0, 1.0, false, false})
/* A channel's frequencies, THz (its centre, a range's ends, where a measured response is
 * > 0): up to 10 000 THz (30 nm, beyond the ultraviolet; thermal infrared cameras sit at
 * 10-100 THz). At 1e300 THz the band's top overflowed to inf: the run wrote wavelength
 * {inf} into the ENVI header and null into summary.json. */
#define LOAD_MAX_FREQUENCY_THZ 1e4
#define LOAD_FREQUENCY ((load_range){0.0, LOAD_MAX_FREQUENCY_THZ, true, false})
/* Temperatures, K, of objects, the background, the normalisation and the receiver: up to
 * 1e6 K, far above any scene a terahertz camera sees. Planck's law and the float outputs
 * overflowed from 4e38 K (truth temperature and brightness temperature inf), 1e50 K
 * (normalized) and 1e56 K (radiance); 1e30 K was still right. */
#define LOAD_MAX_TEMPERATURE_K 1e6
#define LOAD_TEMPERATURE ((load_range){0.0, LOAD_MAX_TEMPERATURE_K, false, false})
/* The background's, K: what atmosphere_set_emitting accepts, checked here to name the path. */
#define LOAD_BACKGROUND_TEMPERATURE ((load_range){0.0, 10000.0, false, false})
/* The atmosphere's attenuation (constant and table), 1/m: up to 1e10 (a mean free path
 * of 0.1 nm, far beyond any medium). The photon map's air photons carry power
 * 4 pi alpha B V / N, and at 1e200 /m their squares (the standard error) overflowed
 * into NaN images; 1e100 still gave the exact answer. */
#define LOAD_MAX_ATTENUATION_PER_M 1e10
#define LOAD_ATTENUATION ((load_range){0.0, LOAD_MAX_ATTENUATION_PER_M, false, false})

/* v as the shortest %g that reads back as v (6 to 17 digits) into out, returned: a value
 * just past a bound shows why it is out (0.5000001, not %g's 0.5). LOAD_G(v) formats
 * into a buffer of its own that lives until the end of the enclosing block. */
#define LOAD_NUMBER_CHARS 32
const char *load_number_text(double v, char *out);
#define LOAD_G(v) load_number_text((v), (char[LOAD_NUMBER_CHARS]){0})

/* The band of a channel that the scene's tables and indices must cover and that the
 * load checks evaluate: the Gaussian's centre +- 2 FWHM, a measured response's span where
 * it is > 0; never below 0 Hz. */
void load_channel_band(const thz_channel *ch, double *lo_hz, double *hi_hz);

/* The root cursor of a document. */
load_cursor load_root(json_t *value);

/* Member `key` of object cursor c (value NULL if absent), and element i of array c. */
load_cursor load_key(const load_cursor *c, const char *key);
load_cursor load_index(const load_cursor *c, size_t i);

/* Sets ctx->err to THZ_ERR_INPUT with "<label>: <path>: <message>" (no path part at
 * the root) and returns THZ_ERR_INPUT. */
thz_status load_fail(load_ctx *ctx, const load_cursor *c, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* A short description of a JSON value's type for messages ("a string", "null"). */
const char *load_type_name(const json_t *v);

/* Fails unless c is an object whose keys are all in `allowed` (NULL-terminated). */
thz_status load_expect_object(load_ctx *ctx, const load_cursor *c, const char *const *allowed);

/* Fails unless member `key` of c is present (used for required keys whose value
 * is parsed by a caller-specific function). `what` describes the expected value. */
thz_status load_require(load_ctx *ctx, const load_cursor *c, const char *key, const char *what);

/* The value of cursor c itself as a number in range r. */
thz_status load_number_value(load_ctx *ctx, const load_cursor *c, load_range r, double *out);

/* Member `key` of object c as a number in range r. Absent: the default if not
 * required, an error if required. */
thz_status load_number(load_ctx *ctx, const load_cursor *c, const char *key, load_range r,
                       bool required, double dflt, double *out);

/* Member `key` as a whole number in [min, max] (a JSON real with an integral value,
 * such as 1e6, counts). */
thz_status load_integer(load_ctx *ctx, const load_cursor *c, const char *key, uint64_t min,
                        uint64_t max, bool required, uint64_t dflt, uint64_t *out);

/* Member `key` as a string (borrowed from the document); *out = dflt if absent and
 * not required. */
thz_status load_string(load_ctx *ctx, const load_cursor *c, const char *key, bool required,
                       const char *dflt, const char **out);

/* Member `key` as a boolean. */
thz_status load_bool(load_ctx *ctx, const load_cursor *c, const char *key, bool dflt, bool *out);

/* Member `key` as an array of exactly n numbers each in r. */
thz_status load_vector(load_ctx *ctx, const load_cursor *c, const char *key, size_t n, load_range r,
                       bool required, double *out);

/* Member `key` as one of the NULL-terminated `choices`; *out is its index. */
thz_status load_choice(load_ctx *ctx, const load_cursor *c, const char *key,
                       const char *const *choices, bool required, size_t dflt, size_t *out);

/* The files a scene or sequence names (load_files.c), the one place that resolves them
 * and confines them to a root.
 * load_file_confine: *real (malloc'd) is the file at path to open: path itself when root
 * is NULL; else its real path (symlinks, "." and ".." resolved), which must be the root
 * (a real path: load_root_real) or lie below it. Refused (THZ_ERR_INPUT, *refusal the
 * reason, worded to follow the quoted name and to reveal nothing outside the root) when
 * it lies outside, does not exist or does not resolve. THZ_ERR_NOMEM: out of memory.
 * load_file_check: the same for a file another names as `name` (path: name resolved
 * against the naming file's directory), refused also when name is absolute while root is
 * set.
 * load_root_real: the real path of root (NULL: none) into *real (malloc'd), or an input
 * error when it is not a directory.
 * load_file_path: name, given at cursor k of the scene, resolved against ctx->dir
 * (absolute names stay; dir "." adds nothing) into *label (malloc'd, for messages) and
 * checked within ctx->root into *path (malloc'd, to open); a refusal fails at k. */
thz_status load_file_confine(const char *path, const char *root, char **real, const char **refusal);
thz_status load_file_check(const char *name, const char *path, const char *root, char **real,
                           const char **refusal);
thz_status load_root_real(const char *root, char **real, thz_error *err);
thz_status load_file_path(load_ctx *ctx, const load_cursor *k, const char *name, char **path,
                          char **label);

/* Member `key` of c, a file name, read as a CSV table. Errors name the JSON path and
 * the CSV file with its line and row. */
thz_status load_csv(load_ctx *ctx, const load_cursor *c, const char *key, csv_table *table);

/* Fails unless t has a column frequency_thz, a column `required` (unless NULL), and no
 * column but these and the NULL-terminated `known` ones. Errors name the CSV file. */
thz_status load_csv_columns(load_ctx *ctx, const load_cursor *c, const csv_table *t,
                            const char *const *known, const char *required);

/* Column `column` of t (against column frequency_thz; load_csv_columns has checked
 * both are present) as a spectrum, checking frequencies (> 0, strictly increasing) and
 * values in r. Errors name the file and the row. */
thz_status load_csv_spectrum(load_ctx *ctx, const load_cursor *c, const csv_table *t,
                             const char *column, load_range r, thz_spectrum *out);

/* Member `key` of c as a spectral property: a number, or a table
 * [[frequency_thz, value], ...]. *present tells whether the key was there (out is
 * left untouched when it was not). */
thz_status load_spectrum(load_ctx *ctx, const load_cursor *c, const char *key, load_range r,
                         thz_spectrum *out, bool *present);

/* Member "name" of list[i]: a non-empty string unlike the "name" of every earlier entry
 * of the list (entries without one do not count). *out is borrowed from the document,
 * NULL when the key is absent and not required. `what` names the entry in messages. */
thz_status load_unique_name(load_ctx *ctx, const load_cursor *list, size_t i, const char *what,
                            bool required, const char **out);

/* The required, non-empty list `key` of the root (objects, sensors): its cursor and
 * length, or a failure naming what was expected. */
thz_status load_list(load_ctx *ctx, const load_cursor *root, const char *key, const char *what,
                     load_cursor *list, size_t *n);

/* The spectral properties of a material: their keys (and CSV columns), NULL-terminated,
 * in the order of load_material_property (0 reflectivity, 1 attenuation, 2 emissivity). */
#define LOAD_N_PROPERTIES 3
extern const char *const load_material_columns[];
thz_spectrum *load_material_property(thz_material *m, size_t k);

/* A material's complex index (load_index.c): `refractive_index` or
 * `permittivity_model` of c (replacing m->index when given; *given says whether one
 * was), the n and k columns of a material CSV t, and the `library` entry named by c
 * (material_library.c; range_hz gets the range its source states, {0, 0} if none).
 * load_index_check_channels refuses channel bands that leave an itu-p2040 model's
 * ranges and warns where they leave an index table or, when lib_range_hz is not NULL,
 * the library entry's stated range. */
thz_status load_material_index(load_ctx *ctx, const load_cursor *c, thz_material *m, bool *given);
thz_status load_index_csv(load_ctx *ctx, const load_cursor *file, const csv_table *t,
                          thz_material *m);
thz_status load_material_library(load_ctx *ctx, const load_cursor *c, thz_material *m,
                                 double range_hz[2]);
thz_status load_index_check_channels(load_ctx *ctx, const load_cursor *c, const thz_material *m,
                                     const double *lib_range_hz);

/* The blocks of the document, in dependency order; each fills its part of ctx->scene
 * (root is the document's cursor). Channels before sensors, materials before objects. */
thz_status load_channels(load_ctx *ctx, const load_cursor *root);
thz_status load_materials(load_ctx *ctx, const load_cursor *root);
/* The atmosphere block (load_atmosphere.c); c->value may be NULL (model none). */
thz_status load_atmosphere(load_ctx *ctx, const load_cursor *c, thz_atmosphere *atm);
/* After the objects: emitting air with no temperature given takes the enclosure's
 * (when > 0; else it keeps LOAD_DEFAULT_AIR_TEMPERATURE_K), and so does its background
 * when none is given. */
thz_status load_atmosphere_defaults(load_ctx *ctx, double enclosure_temperature_k);
thz_status load_objects(load_ctx *ctx, const load_cursor *root);
thz_status load_sensors(load_ctx *ctx, const load_cursor *root);
/* Sensor c's optics and noise keys into sn (load_sensor_model.c); after aperture_m2. */
thz_status load_sensor_model(load_ctx *ctx, const load_cursor *c, size_t n_channels,
                             thz_sensor *sn);
/* The optional photons and render blocks (absent: the scene's defaults stay). */
thz_status load_photons(load_ctx *ctx, const load_cursor *root);
thz_status load_render(load_ctx *ctx, const load_cursor *root);

#endif
