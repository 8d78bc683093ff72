/* The material library through the public API (include/thzmap/materials.h). */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "api/api.h"
#include "core/alloc.h"
#include "physics/material_index.h"
#include "scene/material_library.h"

/* Speed of light in m/s. */
#define C_M_PER_S 299792458.0

struct thz_library {
    material_library *lib;
};

thz_status thz_library_load(thz_library **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_library_load: no place for the library");
    *out = NULL;
    thz_library *l = thz_calloc(1, sizeof *l);
    if (!l)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_status st = material_library_load(&l->lib, err);
    if (st != THZ_OK) {
        free(l);
        return st;
    }
    *out = l;
    return THZ_OK;
}

void thz_library_destroy(thz_library *lib)
{
    if (!lib)
        return;
    material_library_destroy(lib->lib);
    free(lib);
}

size_t thz_library_count(const thz_library *lib)
{
    return lib ? lib->lib->n : 0;
}

/* Entry i, or NULL when lib is NULL or i is out of range. */
static const material_library_entry *api_entry(const thz_library *lib, size_t i)
{
    return lib && i < lib->lib->n ? &lib->lib->entries[i] : NULL;
}

thz_status thz_library_find(const thz_library *lib, const char *name, size_t *index, thz_error *err)
{
    if (!lib || !name || !index)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_library_find: no %s",
                             !lib    ? "library"
                             : !name ? "name"
                                     : "place for the index");
    const material_library_entry *e = material_library_find(lib->lib, name);
    if (e) {
        *index = (size_t)(e - lib->lib->entries);
        return THZ_OK;
    }
    char names[2048] = "";
    for (size_t i = 0; i < lib->lib->n; i++) {
        size_t used = strlen(names);
        snprintf(names + used, sizeof names - used, "%s%s", i ? ", " : "",
                 lib->lib->entries[i].name);
    }
    return thz_error_set(err, THZ_ERR_INPUT, "%s: no material \"%s\" (known: %s)", lib->lib->path,
                         name, names);
}

void thz_library_get_info(const thz_library *lib, size_t i, thz_library_material_info *out)
{
    if (!out)
        return;
    const material_library_entry *e = api_entry(lib, i);
    if (!e) {
        *out = (thz_library_material_info){0};
        return;
    }
    double lo = 0, hi = 0;
    bool data_range = material_index_range(e->index, &lo, &hi);
    *out = (thz_library_material_info){.name = e->name,
                                       .description = e->description,
                                       .basis = e->basis,
                                       .source = e->source,
                                       .note = e->note,
                                       .model = material_index_form(e->index),
                                       .has_valid_range = e->has_range,
                                       .valid_from_thz = e->lo_hz / 1e12,
                                       .valid_to_thz = e->hi_hz / 1e12,
                                       .has_data_range = data_range,
                                       .data_from_thz = data_range ? lo / 1e12 : 0.0,
                                       .data_to_thz = data_range ? hi / 1e12 : 0.0,
                                       .n_data_ranges = material_index_n_ranges(e->index)};
}

void thz_library_get_range(const thz_library *lib, size_t i, size_t r, double *from_thz,
                           double *to_thz)
{
    const material_library_entry *e = api_entry(lib, i);
    double lo = 0.0, hi = 0.0;
    if (e && r < material_index_n_ranges(e->index))
        material_index_range_at(e->index, r, &lo, &hi);
    if (from_thz)
        *from_thz = lo / 1e12;
    if (to_thz)
        *to_thz = hi / 1e12;
}

int thz_library_in_range(const thz_library *lib, size_t i, double freq_hz)
{
    const material_library_entry *e = api_entry(lib, i);
    if (!e)
        return 0;
    if (e->has_range && (freq_hz < e->lo_hz || freq_hz > e->hi_hz))
        return 0;
    const permittivity_model *pm = material_index_model_of(e->index);
    if (pm && pm->kind == PERMITTIVITY_P2040)
        return permittivity_covers(pm, freq_hz, freq_hz);
    return 1;
}

void thz_library_optics_at(const thz_library *lib, size_t i, double freq_hz,
                           thz_library_optics *out)
{
    if (!out)
        return;
    const material_library_entry *e = api_entry(lib, i);
    if (!e || !(freq_hz > 0.0) || isinf(freq_hz)) {
        *out = (thz_library_optics){0};
        return;
    }
    const material_index *idx = e->index;
    double n = 0, k = 0, re = 0, im = 0;
    material_index_at(idx, freq_hz, &n, &k);
    material_index_permittivity(idx, freq_hz, &re, &im);
    double num = (n - 1) * (n - 1) + k * k, den = (n + 1) * (n + 1) + k * k;
    *out = (thz_library_optics){.n = n,
                                .k = k,
                                .eps_real = re,
                                .eps_imag = im,
                                .attenuation_per_m = 4.0 * M_PI * k * freq_hz / C_M_PER_S,
                                .normal_reflectance = num / den};
}
