/* The material library shipped with the program (data/materials/library.json, format
 * in docs/scene-format.md "Material library"): named materials, each a complex index
 * (refractive_index or permittivity_model, as in a scene) with its source cited.
 * Scenes take an entry with `"library": "NAME"`; `thzmap materials` lists them.
 */
#ifndef THZ_SCENE_MATERIAL_LIBRARY_H
#define THZ_SCENE_MATERIAL_LIBRARY_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "physics/material_index.h"

/* The library file inside the data directory. */
#define MATERIAL_LIBRARY_FILE "materials/library.json"

typedef struct material_library_entry {
    char *name;
    char *description; /* what it is, e.g. "liquid water at 25 °C" */
    char *basis;       /* "measured", "model", "fit" or "assumed" (library.json) */
    char *source;      /* the citation */
    char *note;        /* "" when none */
    bool has_range;    /* valid_thz given: the range the entry holds for (library.json) */
    double lo_hz, hi_hz;
    bool has_color;
    double color[3];
    material_index *index; /* owned */
} material_library_entry;

typedef struct material_library {
    char *path; /* the file, for messages */
    size_t n;
    material_library_entry *entries; /* in the file's order */
} material_library;

/* Reads and checks the whole library from the data directory (data_dir.h; the ITU-R
 * P.2040 table of its itu-p2040 entries comes from there too). THZ_ERR_IO when the file is missing,
 * THZ_ERR_INPUT naming the JSON path of a bad entry. */
thz_status material_library_load(material_library **out, thz_error *err);

/* The entry called name, or NULL. */
const material_library_entry *material_library_find(const material_library *lib, const char *name);

void material_library_destroy(material_library *lib);

#endif
