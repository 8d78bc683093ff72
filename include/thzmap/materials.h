/* thzmap public API: the material library shipped with the program (include
 * thzmap/thzmap.h, which includes this), as `thzmap materials` lists it and a scene's
 * `"library": "NAME"` uses it (docs/scene-format.md "Material library").
 *
 * A thz_library is the whole library read from the data directory (THZMAP_DATA_DIR, or
 * the installed or source data/); read-only once opened. Strings in the info structs
 * belong to the library.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_MATERIALS_H
#define THZMAP_MATERIALS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct thz_library thz_library;

/* Reads and checks the library. THZ_ERR_IO when its file is missing, THZ_ERR_INPUT
 * naming the JSON path of a bad entry. *out is owned (thz_library_destroy). */
THZ_API thz_status thz_library_load(thz_library **out, thz_error *err);
THZ_API void thz_library_destroy(thz_library *lib);

/* The number of entries (0 for a NULL lib), and the index of the entry called name
 * (THZ_ERR_INPUT naming the known names when there is none). */
THZ_API size_t thz_library_count(const thz_library *lib);
THZ_API thz_status thz_library_find(const thz_library *lib, const char *name, size_t *index,
                                    thz_error *err);

typedef struct thz_library_material_info {
    const char *name;
    const char *description; /* what it is */
    const char *basis;       /* "measured", "model", "fit" or "assumed" */
    const char *source;      /* the citation */
    const char *note;        /* "" when none */
    const char *model;       /* "constant", "table", "debye", "double-debye", "lorentz",
                                "drude" or "itu-p2040" */
    int has_valid_range;     /* the source states a frequency range: */
    double valid_from_thz, valid_to_thz;
    int has_data_range; /* the data cover a range (tables, itu-p2040 rows): */
    double data_from_thz, data_to_thz;
    size_t n_data_ranges; /* a table's range, or each itu-p2040 row's (thz_library_get_range) */
} thz_library_material_info;

/* Entry i (0-based, < count) in the library file's order; a zeroed *out (name NULL)
 * when i is out of range or lib is NULL. */
THZ_API void thz_library_get_info(const thz_library *lib, size_t i, thz_library_material_info *out);

/* Data range r (< n_data_ranges) of entry i in THz; an itu-p2040 entry is valid only
 * within the union of its rows' ranges, which a scene's channel bands must not leave.
 * 0 to 0 when i or r is out of range. */
THZ_API void thz_library_get_range(const thz_library *lib, size_t i, size_t r, double *from_thz,
                                   double *to_thz);
/* True when freq_hz lies within entry i's stated validity (valid_from/to_thz), where it
 * states one, and, for an itu-p2040 entry, within one of its rows: both where it has
 * both; always true for entries that state neither; false when i is out of range. */
THZ_API int thz_library_in_range(const thz_library *lib, size_t i, double freq_hz);

/* The complex index n + ik (k >= 0) and relative permittivity eps' + i eps'' of entry
 * i at freq_hz > 0. */
typedef struct thz_library_optics {
    double n, k;
    double eps_real, eps_imag;
    double attenuation_per_m;  /* 4 pi k nu / c, the power attenuation in the medium */
    double normal_reflectance; /* |(n + ik - 1)/(n + ik + 1)|^2 from air */
} thz_library_optics;
/* All zero when i is out of range or freq_hz is not a finite frequency above 0. */
THZ_API void thz_library_optics_at(const thz_library *lib, size_t i, double freq_hz,
                                   thz_library_optics *out);

#ifdef __cplusplus
}
#endif

#endif
