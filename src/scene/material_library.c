/* The material library (data/materials/library.json): stub until the library lands. */
#include "scene/load.h"

thz_status load_material_library(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    (void)m;
    load_cursor k = load_key(c, "library");
    return load_fail(ctx, &k, "the material library is not available yet");
}
