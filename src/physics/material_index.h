/* Complex refractive indices n + ik of materials (scene-format.md "Materials: optics
 * from a complex index"): constants, tables and the permittivity models (Debye, double
 * Debye, Lorentz, Drude, ITU-R P.2040; permittivity.h), evaluated at one frequency.
 *
 * A material_index is built by the scene loader from a material's `refractive_index`,
 * `permittivity_model` or `library` entry and owned by its thz_material.
 *
 * Tables interpolate n and k linearly in frequency and hold the end values beyond the
 * ends, like every spectral table of a scene (validate warns where a channel's band
 * leaves the table); an itu-p2040 model is refused at load time where a channel's band
 * leaves the Recommendation's stated range, so it is only evaluated inside it.
 */
#ifndef THZ_PHYSICS_MATERIAL_INDEX_H
#define THZ_PHYSICS_MATERIAL_INDEX_H

#include <stdbool.h>
#include <stddef.h>

#include "physics/permittivity.h"

typedef struct material_index material_index;

/* A constant index n + ik (n > 0, k >= 0). NULL on allocation failure. */
material_index *material_index_constant(double n, double k);

/* A table of count >= 1 rows (frequencies strictly increasing, n > 0, k >= 0, checked by
 * the caller), copied. NULL on allocation failure. */
material_index *material_index_table(size_t count, const double *freq_hz, const double *n,
                                     const double *k);

/* A permittivity model (copied). NULL on allocation failure. */
material_index *material_index_model(const permittivity_model *model);

/* A deep copy (NULL for NULL or on allocation failure). */
material_index *material_index_copy(const material_index *idx);

/* n and k (k >= 0: absorbing) of `idx` at freq_hz. False when idx is NULL. */
bool material_index_at(const material_index *idx, double freq_hz, double *n, double *k);

/* The relative permittivity eps' + i eps'' = (n + ik)^2 at freq_hz. False when NULL. */
bool material_index_permittivity(const material_index *idx, double freq_hz, double *re, double *im);

/* What the index is: "constant", "table", or the model's name (permittivity.h). */
const char *material_index_form(const material_index *idx);

/* The frequency range the data are stated for: a table's first and last frequency, an
 * itu-p2040 model's rows; false (0, infinity) for constants and the other models. */
bool material_index_range(const material_index *idx, double *lo_hz, double *hi_hz);

/* The ranges the data are given for, one by one: the table's, or each itu-p2040 row's
 * (in file order; they may overlap or leave gaps). 0 for constants and other models. */
size_t material_index_n_ranges(const material_index *idx);
void material_index_range_at(const material_index *idx, size_t r, double *lo_hz, double *hi_hz);

/* A table's frequencies (its count; *freq_hz points into idx), where n and k have kinks;
 * 0 (and NULL) for constants and models. */
size_t material_index_table_hz(const material_index *idx, const double **freq_hz);

/* The model behind idx, or NULL for constants and tables. */
const permittivity_model *material_index_model_of(const material_index *idx);

void material_index_destroy(material_index *idx);

#endif
