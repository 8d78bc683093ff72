/* The scene's `atmosphere` block: models none, constant and table. The line-by-line
 * models (itu-p676, lines) are parsed here too once the atmosphere module has them:
 * add the model name to `models` and a branch below. */
#include <string.h>

#include "scene/load.h"

thz_status load_atmosphere(load_ctx *ctx, const load_cursor *c, thz_atmosphere *atm)
{
    static const char *const models[] = {"none", "constant", "table", NULL};
    static const char *const keys_none[] = {"model", NULL};
    static const char *const keys_constant[] = {"model", "attenuation_per_m", NULL};
    static const char *const keys_table[] = {"model", "file", NULL};
    thz_status st = THZ_OK;
    csv_table table = {0};
    atmosphere_fini(atm);
    if (!c->value)
        return THZ_OK; /* model none */
    if (!json_is_object(c->value))
        return load_fail(ctx, c, "expected an object {\"model\": ...}, got %s",
                         load_type_name(c->value));
    size_t model = 0;
    st = load_choice(ctx, c, "model", models, true, 0, &model);
    if (st != THZ_OK)
        return st;
    switch (model) {
    case 0:
        st = load_expect_object(ctx, c, keys_none);
        atm->model = ATM_NONE;
        break;
    case 1: {
        double alpha = 0.0;
        st = load_expect_object(ctx, c, keys_constant);
        if (st == THZ_OK)
            st = load_number(ctx, c, "attenuation_per_m", LOAD_NONNEGATIVE, true, 0.0, &alpha);
        if (st != THZ_OK)
            break;
        if (!spectrum_set_constant(&atm->attenuation_per_m, alpha)) {
            st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
            break;
        }
        atm->model = ATM_CONSTANT;
        break;
    }
    case 2: {
        st = load_expect_object(ctx, c, keys_table);
        if (st == THZ_OK)
            st = load_csv(ctx, c, "file", &table);
        if (st != THZ_OK)
            break;
        load_cursor file = load_key(c, "file");
        for (size_t i = 0; i < table.n_columns; i++) {
            if (strcmp(table.names[i], "frequency_thz") != 0 &&
                strcmp(table.names[i], "attenuation_per_m") != 0) {
                st = load_fail(ctx, &file,
                               "%s: unknown column '%s' (expected frequency_thz, attenuation_per_m)",
                               table.label, table.names[i]);
                break;
            }
        }
        if (st == THZ_OK)
            st = load_csv_spectrum(ctx, &file, &table, "attenuation_per_m", LOAD_NONNEGATIVE,
                                   &atm->attenuation_per_m);
        if (st == THZ_OK)
            atm->model = ATM_TABLE;
        break;
    }
    }
    csv_fini(&table);
    return st;
}
