/* ENVI images: a raw band-sequential file DIR/STEM.img and its text header
 * DIR/STEM.hdr (scene-format.md "Outputs"), the format Spectral Python, GDAL and ENVI
 * itself open. Data are little-endian on every host (`byte order = 0`), without a
 * header offset; float32 (`data type = 4`) only, as the format promises for every
 * image: integer data such as object indices are written as exact float values.
 */
#ifndef THZ_IO_ENVI_H
#define THZ_IO_ENVI_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* What the header says about a cube. Strings are written with ENVI's list and brace
 * characters ({ } ,) and line breaks replaced by spaces or semicolons, so any channel
 * or object name yields a header the readers parse. */
typedef struct envi_info {
    const char *description; /* one line; required */
    const char *data_units;  /* unit of the values, e.g. "K" or "W m-2 sr-1 Hz-1" */
    uint32_t samples;        /* columns */
    uint32_t lines;          /* rows; line 0 is the top of the picture */
    size_t bands;
    const char *const *band_names; /* `bands` entries, or NULL */
    const double *wavelength_ghz;  /* `bands` channel centres in GHz, or NULL */
    const double *fwhm_ghz;        /* `bands` channel FWHMs in GHz, or NULL */
    int has_ignore_value;          /* write `data ignore value` */
    double ignore_value;
    const char *const *object_names; /* `object names` (object_id images), or NULL */
    size_t n_object_names;
} envi_info;

/* Writes DIR/STEM.img (samples*lines*bands float32, BSQ) and DIR/STEM.hdr. A path
 * longer than THZ_PATH_MAX is THZ_ERR_IO (core/path.h). */
thz_status envi_write_float32(const char *dir, const char *stem, const envi_info *info,
                              const float *data, thz_error *err);

/* An image read back (envi_read.c): what thzmap writes, and any ENVI Standard file of
 * float32 values in band-sequential order with byte order 0 or 1 and a header offset. */
typedef struct envi_cube {
    uint32_t samples, lines;
    size_t bands;
    float *data;            /* bands x lines x samples, BSQ, host order */
    double *wavelength;     /* `bands` values of `wavelength`, or NULL */
    char *wavelength_units; /* or NULL */
    char **object_names;    /* `object names`, or NULL */
    size_t n_object_names;
} envi_cube;

/* Largest header and data file envi_read_float32 reads (bytes), and the most samples,
 * lines or bands a header may give (a cube made in memory: the most bands). */
#define ENVI_MAX_HEADER_BYTES (1u << 20)
#define ENVI_MAX_DATA_BYTES (16ull << 30)
#define ENVI_MAX_DIM (1u << 20)

/* Reads DIR/STEM.hdr and DIR/STEM.img. THZ_ERR_INPUT (naming the file and, for the
 * header, the line) when a file is missing, not a regular file, above the limits, or
 * not a float32 BSQ image of the size its header says. */
thz_status envi_read_float32(const char *dir, const char *stem, envi_cube *out, thz_error *err);
void envi_cube_fini(envi_cube *cube);

/* A cube of the caller's values (bands x lines x samples, BSQ), copied, without a
 * wavelength or object names: what a file of them would read back as. Any float is
 * taken, as the reader takes any (the classifier refuses what it cannot use).
 * THZ_ERR_INPUT, its message beginning with `name`, when data is NULL, a size is 0,
 * bands is above ENVI_MAX_DIM, or the values' bytes overflow a size_t. */
thz_status envi_cube_init(envi_cube *out, const char *name, uint32_t samples, uint32_t lines,
                          size_t bands, const float *data, thz_error *err);

/* Replaces the cube's `object names` by copies of names[0 .. n-1] (n 0: none).
 * THZ_ERR_INPUT, its message beginning with `name`, for a NULL or empty name; the cube
 * keeps its names then. */
thz_status envi_cube_set_object_names(envi_cube *cube, const char *name, const char *const *names,
                                      size_t n, thz_error *err);

#endif
