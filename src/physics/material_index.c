/* Complex refractive indices: evaluation at one frequency (material_index.h). */
#include "physics/material_index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "physics/spectrum.h"

struct material_index {
    bool is_model;
    size_t count;    /* table rows; 1 for a constant */
    double *freq_hz; /* count entries; NULL for a constant */
    double *n, *k;   /* count entries */
    permittivity_model model;
};

static material_index *index_alloc(size_t count, bool with_freq)
{
    material_index *idx = thz_calloc(1, sizeof *idx);
    if (!idx)
        return NULL;
    idx->count = count;
    idx->n = thz_malloc_array(count, sizeof *idx->n);
    idx->k = thz_malloc_array(count, sizeof *idx->k);
    idx->freq_hz = with_freq ? thz_malloc_array(count, sizeof *idx->freq_hz) : NULL;
    if (!idx->n || !idx->k || (with_freq && !idx->freq_hz)) {
        material_index_destroy(idx);
        return NULL;
    }
    return idx;
}

material_index *material_index_constant(double n, double k)
{
    material_index *idx = index_alloc(1, false);
    if (idx) {
        idx->n[0] = n;
        idx->k[0] = k;
    }
    return idx;
}

material_index *material_index_table(size_t count, const double *freq_hz, const double *n,
                                     const double *k)
{
    material_index *idx = index_alloc(count, true);
    if (idx) {
        memcpy(idx->freq_hz, freq_hz, count * sizeof *freq_hz);
        memcpy(idx->n, n, count * sizeof *n);
        memcpy(idx->k, k, count * sizeof *k);
    }
    return idx;
}

material_index *material_index_model(const permittivity_model *model)
{
    material_index *idx = thz_calloc(1, sizeof *idx);
    if (idx) {
        idx->is_model = true;
        idx->model = *model;
    }
    return idx;
}

material_index *material_index_copy(const material_index *idx)
{
    if (!idx)
        return NULL;
    if (idx->is_model)
        return material_index_model(&idx->model);
    if (!idx->freq_hz)
        return material_index_constant(idx->n[0], idx->k[0]);
    return material_index_table(idx->count, idx->freq_hz, idx->n, idx->k);
}

/* Linear interpolation in a table, the end values beyond the ends. */
static void table_at(const material_index *idx, double freq_hz, double *n, double *k)
{
    size_t last = idx->count - 1;
    if (!idx->freq_hz || freq_hz <= idx->freq_hz[0]) {
        *n = idx->n[0];
        *k = idx->k[0];
        return;
    }
    if (freq_hz >= idx->freq_hz[last]) {
        *n = idx->n[last];
        *k = idx->k[last];
        return;
    }
    size_t lo = spectrum_interval(idx->freq_hz, idx->count, freq_hz), hi = lo + 1;
    double t = (freq_hz - idx->freq_hz[lo]) / (idx->freq_hz[hi] - idx->freq_hz[lo]);
    *n = idx->n[lo] + t * (idx->n[hi] - idx->n[lo]);
    *k = idx->k[lo] + t * (idx->k[hi] - idx->k[lo]);
}

bool material_index_at(const material_index *idx, double freq_hz, double *n, double *k)
{
    if (!idx)
        return false;
    if (idx->is_model) {
        double re, im;
        permittivity_eval(&idx->model, freq_hz, &re, &im);
        permittivity_to_index(re, im, n, k);
    } else {
        table_at(idx, freq_hz, n, k);
    }
    return true;
}

bool material_index_permittivity(const material_index *idx, double freq_hz, double *re, double *im)
{
    if (!idx)
        return false;
    if (idx->is_model) {
        permittivity_eval(&idx->model, freq_hz, re, im);
        return true;
    }
    double n, k;
    table_at(idx, freq_hz, &n, &k);
    *re = n * n - k * k;
    *im = 2.0 * n * k;
    return true;
}

const char *material_index_form(const material_index *idx)
{
    if (idx->is_model)
        return permittivity_kind_names[idx->model.kind];
    return idx->freq_hz ? "table" : "constant";
}

bool material_index_range(const material_index *idx, double *lo_hz, double *hi_hz)
{
    if (idx->is_model)
        return permittivity_validity(&idx->model, lo_hz, hi_hz);
    if (!idx->freq_hz) {
        *lo_hz = 0.0;
        *hi_hz = INFINITY;
        return false;
    }
    *lo_hz = idx->freq_hz[0];
    *hi_hz = idx->freq_hz[idx->count - 1];
    return true;
}

size_t material_index_n_ranges(const material_index *idx)
{
    if (idx->is_model)
        return idx->model.kind == PERMITTIVITY_P2040 ? idx->model.n_rows : 0;
    return idx->freq_hz ? 1 : 0;
}

void material_index_range_at(const material_index *idx, size_t r, double *lo_hz, double *hi_hz)
{
    if (idx->is_model) {
        *lo_hz = idx->model.rows[r].lo_hz;
        *hi_hz = idx->model.rows[r].hi_hz;
    } else {
        material_index_range(idx, lo_hz, hi_hz);
    }
}

size_t material_index_table_hz(const material_index *idx, const double **freq_hz)
{
    bool table = !idx->is_model && idx->freq_hz && idx->count > 1;
    *freq_hz = table ? idx->freq_hz : NULL;
    return table ? idx->count : 0;
}

const permittivity_model *material_index_model_of(const material_index *idx)
{
    return idx->is_model ? &idx->model : NULL;
}

void material_index_destroy(material_index *idx)
{
    if (!idx)
        return;
    free(idx->freq_hz);
    free(idx->n);
    free(idx->k);
    free(idx);
}
