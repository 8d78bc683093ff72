/* The scene's `atmosphere` block: models none, constant and table (alpha given),
 * itu-p676 and lines (alpha computed from the state of the air and spectral line
 * data, src/atmosphere/), and the emitting-atmosphere keys. docs/atmosphere.md
 * lists the keys. Every model but none emits unless "emitting": false (Kirchhoff). */
#include <stdlib.h>
#include <string.h>

#include "scene/load.h"

/* Keys every model but none accepts: the emitting atmosphere. */
#define EMITTING_KEYS "emitting", "background_temperature_k", "extent_min_m", "extent_max_m"
/* The air state of itu-p676 and lines. */
#define AIR_KEYS                                                                                   \
    "temperature_k", "pressure_hpa", "relative_humidity", "water_vapour_g_m3", "h2o_vmr"

/* Fails with the atmosphere module's message under the block's path, keeping the
 * status (input errors name files and lines themselves). */
static thz_status fail_from(load_ctx *ctx, const load_cursor *c, thz_status st,
                            const thz_error *inner)
{
    if (st == THZ_ERR_INPUT)
        return load_fail(ctx, c, "%s", inner->message);
    return thz_error_set(ctx->err, st, "%s: %s: %s", ctx->label, c->path, inner->message);
}

/* temperature_k, pressure_hpa and exactly one humidity key into *air. */
static thz_status load_air(load_ctx *ctx, const load_cursor *c, atm_air_state *air)
{
    static const char *const humidity_keys[] = {"relative_humidity", "water_vapour_g_m3",
                                                "h2o_vmr"};
    static const atm_humidity_kind kinds[] = {ATM_HUMIDITY_RELATIVE, ATM_HUMIDITY_DENSITY_G_M3,
                                              ATM_HUMIDITY_VMR};
    static const load_range ranges[] = {
        {0.0, 1.0, false, false}, {0.0, INFINITY, false, false}, {0.0, 1.0, false, true}};
    double t = 0.0, p = 0.0, h = 0.0;
    thz_status st = load_number(
        ctx, c, "temperature_k",
        (load_range){ATM_AIR_MIN_TEMPERATURE_K, ATM_AIR_MAX_TEMPERATURE_K, false, false}, true, 0.0,
        &t);
    if (st == THZ_OK)
        st = load_number(ctx, c, "pressure_hpa",
                         (load_range){0.0, ATM_AIR_MAX_PRESSURE_HPA, true, false}, true, 0.0, &p);
    if (st != THZ_OK)
        return st;
    int found = -1;
    for (int i = 0; i < 3; i++) {
        load_cursor k = load_key(c, humidity_keys[i]);
        if (!k.value)
            continue;
        if (found >= 0)
            return load_fail(ctx, &k,
                             "give only one of relative_humidity, water_vapour_g_m3, "
                             "h2o_vmr (%s is given too)",
                             humidity_keys[found]);
        found = i;
        st = load_number(ctx, c, humidity_keys[i], ranges[i], true, 0.0, &h);
        if (st != THZ_OK)
            return st;
    }
    if (found < 0)
        return load_fail(ctx, c,
                         "the air needs one of relative_humidity (0..1), water_vapour_g_m3 or "
                         "h2o_vmr (0 for dry air)");
    thz_error inner = {0};
    st = atm_air_state_init(air, t, p, kinds[found], h, &inner);
    if (st != THZ_OK)
        return fail_from(ctx, c, st, &inner);
    return THZ_OK;
}

/* The lines model: air, catalogue files (relative to the scene) and continuum. */
static thz_status load_lines(load_ctx *ctx, const load_cursor *c, thz_atmosphere *atm)
{
    static const char *const file_keys[] = {"h2o_lines_file",         "o2_lines_file",
                                            "o2_coupled_lines_file",  "h2o_partition_sums_file",
                                            "o2_partition_sums_file", "continuum_file"};
    enum { N_FILES = 6 };
    char *paths[N_FILES] = {0};
    atm_air_state air;
    atm_lines_options opt;
    atmosphere_lines_options_default(&opt);
    thz_status st = load_air(ctx, c, &air);
    if (st == THZ_OK)
        st = load_bool(ctx, c, "continuum", true, &opt.continuum);
    for (size_t i = 0; st == THZ_OK && i < N_FILES; i++) {
        const char *file = NULL;
        st = load_string(ctx, c, file_keys[i], false, NULL, &file);
        if (st == THZ_OK && file) {
            load_cursor k = load_key(c, file_keys[i]);
            char *label = NULL;
            st = load_file_path(ctx, &k, file, &paths[i], &label);
            free(label); /* the atmosphere's messages name the file it opens */
        }
    }
    if (st == THZ_OK) {
        opt.h2o_lines_file = paths[0];
        opt.o2_lines_file = paths[1];
        opt.o2_coupled_lines_file = paths[2];
        opt.h2o_partition_sums_file = paths[3];
        opt.o2_partition_sums_file = paths[4];
        opt.continuum_file = paths[5];
        thz_error inner = {0};
        st = atmosphere_init_lines(atm, &air, &opt, &inner);
        /* a file's own error (it starts with the file's path) names the key that gave it */
        load_cursor at = *c;
        for (size_t i = 0; st != THZ_OK && i < N_FILES; i++)
            if (paths[i] && strncmp(inner.message, paths[i], strlen(paths[i])) == 0 &&
                (inner.message[strlen(paths[i])] == ':' || inner.message[strlen(paths[i])] == ' '))
                at = load_key(c, file_keys[i]);
        if (st != THZ_OK)
            st = fail_from(ctx, &at, st, &inner);
    }
    for (size_t i = 0; i < N_FILES; i++)
        free(paths[i]);
    return st;
}

/* emitting (default true: air that absorbs emits), background_temperature_k and the
 * extent (after the model is set). Without air (constant, table) the temperature_k,
 * when absent, and the background, when absent, get their defaults in
 * load_atmosphere_defaults once the objects are known. */
static thz_status load_emitting(load_ctx *ctx, const load_cursor *c, thz_atmosphere *atm)
{
    bool emitting = true;
    thz_status st = load_bool(ctx, c, "emitting", true, &emitting);
    if (st != THZ_OK)
        return st;
    load_cursor t = load_key(c, "temperature_k"), bg = load_key(c, "background_temperature_k");
    load_cursor lo = load_key(c, "extent_min_m"), hi = load_key(c, "extent_max_m");
    if (!emitting) {
        ctx->non_emitting_air = true;
        if (!atm->has_air && t.value)
            return load_fail(ctx, &t,
                             "only the air of itu-p676 and lines, or an emitting "
                             "atmosphere (the default), has a temperature");
        const load_cursor *stray = bg.value ? &bg : lo.value ? &lo : hi.value ? &hi : NULL;
        if (stray)
            return load_fail(ctx, stray, "only an emitting atmosphere (the default) has this");
        return THZ_OK;
    }
    double t_air = atm->has_air ? atm->air.temperature_k : LOAD_DEFAULT_AIR_TEMPERATURE_K;
    ctx->air_temperature_given = atm->has_air || t.value;
    if (!atm->has_air) {
        st = load_number(ctx, c, "temperature_k", (load_range){0.0, 1000.0, true, false}, false,
                         t_air, &t_air);
        if (st != THZ_OK)
            return st;
    }
    double t_bg = t_air;
    ctx->background_given = bg.value != NULL;
    st = load_number(ctx, c, "background_temperature_k", LOAD_BACKGROUND_TEMPERATURE, false, t_air,
                     &t_bg);
    if (st != THZ_OK)
        return st;
    thz_error inner = {0};
    st = atmosphere_set_emitting(atm, t_air, t_bg, &inner);
    if (st != THZ_OK)
        return fail_from(ctx, c, st, &inner);
    if (!lo.value && !hi.value)
        return THZ_OK;
    double min_m[3], max_m[3];
    st = load_vector(ctx, c, "extent_min_m", 3, LOAD_COORDINATE, true, min_m);
    if (st == THZ_OK)
        st = load_vector(ctx, c, "extent_max_m", 3, LOAD_COORDINATE, true, max_m);
    if (st != THZ_OK)
        return st;
    st = atmosphere_set_extent(atm, min_m, max_m, &inner);
    if (st != THZ_OK)
        return fail_from(ctx, &hi, st, &inner);
    return THZ_OK;
}

thz_status load_atmosphere_defaults(load_ctx *ctx, double enclosure_temperature_k)
{
    thz_atmosphere *atm = &ctx->scene->atmosphere;
    if (!atm->emitting || ctx->air_temperature_given || !(enclosure_temperature_k > 0.0))
        return THZ_OK;
    double t_bg = ctx->background_given ? atm->background_temperature_k : enclosure_temperature_k;
    thz_error inner = {0};
    thz_status st = atmosphere_set_emitting(atm, enclosure_temperature_k, t_bg, &inner);
    if (st != THZ_OK)
        return thz_error_set(ctx->err, st, "%s: atmosphere: %s", ctx->label, inner.message);
    return THZ_OK;
}

thz_status load_atmosphere(load_ctx *ctx, const load_cursor *c, thz_atmosphere *atm)
{
    static const char *const models[] = {"none", "constant", "table", "itu-p676", "lines", NULL};
    static const char *const keys_none[] = {"model", NULL};
    static const char *const keys_constant[] = {"model", "attenuation_per_m", "temperature_k",
                                                EMITTING_KEYS, NULL};
    static const char *const keys_table[] = {"model", "file", "temperature_k", EMITTING_KEYS, NULL};
    static const char *const keys_itu[] = {"model", AIR_KEYS, EMITTING_KEYS, NULL};
    static const char *const keys_lines[] = {"model",
                                             AIR_KEYS,
                                             EMITTING_KEYS,
                                             "continuum",
                                             "h2o_lines_file",
                                             "o2_lines_file",
                                             "o2_coupled_lines_file",
                                             "h2o_partition_sums_file",
                                             "o2_partition_sums_file",
                                             "continuum_file",
                                             NULL};
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
        return st;
    case 1: {
        double alpha = 0.0;
        st = load_expect_object(ctx, c, keys_constant);
        if (st == THZ_OK)
            st = load_number(ctx, c, "attenuation_per_m", LOAD_ATTENUATION, true, 0.0, &alpha);
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
        static const char *const columns[] = {"attenuation_per_m", NULL};
        load_cursor file = load_key(c, "file");
        st = load_csv_columns(ctx, &file, &table, columns, "attenuation_per_m");
        if (st == THZ_OK)
            st = load_csv_spectrum(ctx, &file, &table, "attenuation_per_m", LOAD_ATTENUATION,
                                   &atm->attenuation_per_m);
        if (st == THZ_OK)
            atm->model = ATM_TABLE;
        break;
    }
    case 3: {
        atm_air_state air;
        st = load_expect_object(ctx, c, keys_itu);
        if (st == THZ_OK)
            st = load_air(ctx, c, &air);
        if (st == THZ_OK) {
            thz_error inner = {0};
            st = atmosphere_init_itu_p676(atm, &air, NULL, &inner);
            if (st != THZ_OK)
                st = fail_from(ctx, c, st, &inner);
        }
        break;
    }
    case 4:
        st = load_expect_object(ctx, c, keys_lines);
        if (st == THZ_OK)
            st = load_lines(ctx, c, atm);
        break;
    }
    if (st == THZ_OK)
        st = load_emitting(ctx, c, atm);
    csv_fini(&table);
    if (st != THZ_OK)
        atmosphere_fini(atm);
    return st;
}
