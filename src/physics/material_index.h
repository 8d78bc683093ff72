/* Complex refractive indices n + ik of materials (scene-format.md "Materials: optics
 * from a complex index"): constants, tables and the permittivity models (Debye, double
 * Debye, Lorentz, Drude, ITU-R P.2040), evaluated at one frequency.
 *
 * A material_index is built by the scene loader from a material's `refractive_index`,
 * `permittivity_model` or `library` entry and owned by its thz_material.
 */
#ifndef THZ_PHYSICS_MATERIAL_INDEX_H
#define THZ_PHYSICS_MATERIAL_INDEX_H

#include <stdbool.h>

typedef struct material_index material_index;

/* n and k (k >= 0: absorbing) of `idx` at freq_hz. False when idx is NULL. */
bool material_index_at(const material_index *idx, double freq_hz, double *n, double *k);

void material_index_destroy(material_index *idx);

#endif
