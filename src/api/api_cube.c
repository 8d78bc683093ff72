/* The public API of cubes (thzmap/analysis.h): a handle over io/envi_read.c's
 * envi_cube, read from an ENVI file or made of the caller's values, which the classifier
 * (api_classify.c) takes alike. */
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "core/alloc.h"
#include "core/error.h"
#include "io/envi.h"
#include "thzmap/thzmap.h"

thz_status thz_cube_read(const char *dir, const char *stem, thz_cube **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_cube_read: no place for the cube");
    *out = NULL;
    if (!dir || !stem)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_cube_read: no directory or stem");
    thz_cube *cube = thz_calloc(1, sizeof *cube);
    if (!cube)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_status st = envi_read_float32(dir, stem, &cube->c, err);
    if (st == THZ_OK && !(cube->stem = thz_strdup(stem)))
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    if (st != THZ_OK) {
        thz_cube_destroy(cube);
        return st;
    }
    cube->wavelength_ghz = cube->c.wavelength && cube->c.wavelength_units &&
                           strcmp(cube->c.wavelength_units, "GHz") == 0;
    *out = cube;
    return THZ_OK;
}

thz_status thz_cube_create(const char *name, uint32_t columns, uint32_t rows, size_t bands,
                           const float *data, thz_cube **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_cube_create: no place for the cube");
    *out = NULL;
    if (!name)
        name = "cube";
    if (!name[0])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_cube_create: an empty name");
    thz_cube *cube = thz_calloc(1, sizeof *cube);
    if (!cube)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_status st = envi_cube_init(&cube->c, name, columns, rows, bands, data, err);
    if (st == THZ_OK && !(cube->stem = thz_strdup(name)))
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    if (st != THZ_OK) {
        thz_cube_destroy(cube);
        return st;
    }
    *out = cube;
    return THZ_OK;
}

thz_status thz_cube_set_object_names(thz_cube *cube, const char *const *names, size_t n,
                                     thz_error *err)
{
    if (!cube)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_cube_set_object_names: no cube");
    return envi_cube_set_object_names(&cube->c, cube->stem, names, n, err);
}

void thz_cube_destroy(thz_cube *cube)
{
    if (!cube)
        return;
    envi_cube_fini(&cube->c);
    free(cube->stem);
    free(cube);
}

uint32_t thz_cube_columns(const thz_cube *cube)
{
    return cube ? cube->c.samples : 0;
}

uint32_t thz_cube_rows(const thz_cube *cube)
{
    return cube ? cube->c.lines : 0;
}

size_t thz_cube_bands(const thz_cube *cube)
{
    return cube ? cube->c.bands : 0;
}

const float *thz_cube_data(const thz_cube *cube)
{
    return cube ? cube->c.data : NULL;
}

const double *thz_cube_wavelength_ghz(const thz_cube *cube)
{
    return cube && cube->wavelength_ghz ? cube->c.wavelength : NULL;
}

size_t thz_cube_object_name_count(const thz_cube *cube)
{
    return cube ? cube->c.n_object_names : 0;
}

const char *thz_cube_object_name(const thz_cube *cube, size_t i)
{
    return cube && i < cube->c.n_object_names ? cube->c.object_names[i] : NULL;
}
