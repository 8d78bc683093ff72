/* Complex refractive indices: evaluation at one frequency (material_index.h). */
#include "physics/material_index.h"

#include <stdlib.h>

struct material_index {
    double n, k; /* constant index (the models come with the material library) */
};

bool material_index_at(const material_index *idx, double freq_hz, double *n, double *k)
{
    (void)freq_hz;
    if (!idx)
        return false;
    *n = idx->n;
    *k = idx->k;
    return true;
}

void material_index_destroy(material_index *idx)
{
    free(idx);
}
