/* The scene's `materials` block: spectral properties from numbers, tables or a CSV
 * file, and the energy check eps + R <= 1. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "scene/load.h"

/* Rounding slack for eps + R <= 1. */
#define LOAD_SUM_SLACK 1e-9

/* The spectral properties of a material: their keys (and CSV columns), accepted
 * values, and load_material_property's order. */
const char *const load_material_columns[] = {"reflectivity", "attenuation_per_m", "emissivity",
                                             NULL};
static const load_range load_material_ranges[] = {
    {0.0, 1.0, false, false}, {0.0, INFINITY, false, false}, {0.0, 1.0, false, false}};

thz_spectrum *load_material_property(thz_material *m, size_t k)
{
    return k == 0 ? &m->reflectivity : k == 1 ? &m->attenuation_per_m : &m->emissivity;
}

/* Fills the spectra of m from the CSV file named by c's `file`. */
static thz_status load_material_file(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    csv_table t = {0};
    thz_status st = load_csv(ctx, c, "file", &t);
    if (st != THZ_OK)
        return st;
    static const char *const columns[] = {
        "reflectivity", "attenuation_per_m", "emissivity", "n", "k", NULL};
    load_cursor file = load_key(c, "file");
    st = load_csv_columns(ctx, &file, &t, columns, NULL);
    for (size_t k = 0; k < LOAD_N_PROPERTIES && st == THZ_OK; k++)
        if (csv_column(&t, load_material_columns[k]) >= 0)
            st = load_csv_spectrum(ctx, &file, &t, load_material_columns[k],
                                   load_material_ranges[k], load_material_property(m, k));
    if (st == THZ_OK)
        st = load_index_csv(ctx, &file, &t, m);
    csv_fini(&t);
    return st;
}

/* Refuses eps + R > 1 at any table point of either (and at one point when both are
 * constants); between table points both are linear, so the ends of each piece suffice. */
static thz_status load_check_energy(load_ctx *ctx, const load_cursor *c, const thz_material *m)
{
    if (m->emissivity.n == 0)
        return THZ_OK;
    const thz_spectrum *sp[2] = {&m->reflectivity, &m->emissivity};
    for (int which = 0; which < 2; which++) {
        size_t n = sp[which]->freq_hz ? sp[which]->n : 1;
        for (size_t i = 0; i < n; i++) {
            double f = sp[which]->freq_hz ? sp[which]->freq_hz[i] : 1e12;
            double r = spectrum_eval(&m->reflectivity, f), e = spectrum_eval(&m->emissivity, f);
            if (e + r > 1.0 + LOAD_SUM_SLACK) {
                load_cursor k = load_key(c, "emissivity");
                char at[64] = ""; /* two constants: no frequency to name */
                if (sp[which]->freq_hz)
                    snprintf(at, sizeof at, " at %.4g THz", f * 1e-12);
                return load_fail(
                    ctx, &k,
                    "emissivity + reflectivity must not exceed 1, got %.10g + %.10g = %.10g%s", e,
                    r, e + r, at);
            }
        }
    }
    return THZ_OK;
}

/* The `reflection` key: "diffuse" (default), "specular", or {"model": "ward", "alpha_x",
 * "alpha_y"} (1e-6 <= alpha <= 1), whose albedo table is built here (brdf.h). */
static thz_status load_material_reflection(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    static const char *const names[] = {"diffuse", "specular", NULL};
    static const char *const ward_keys[] = {"model", "alpha_x", "alpha_y", NULL};
    static const char *const models[] = {"ward", NULL};
    load_cursor r = load_key(c, "reflection");
    m->reflection = REFLECTION_DIFFUSE;
    const char *forms = "expected \"diffuse\", \"specular\" or {\"model\": \"ward\", "
                        "\"alpha_x\": ax, \"alpha_y\": ay}, got";
    if (json_is_string(r.value) && strcmp(json_string_value(r.value), names[0]) != 0 &&
        strcmp(json_string_value(r.value), names[1]) != 0)
        return load_fail(ctx, &r, "%s \"%s\"", forms, json_string_value(r.value));
    if (!r.value || json_is_string(r.value)) {
        size_t which = 0;
        thz_status st = load_choice(ctx, c, "reflection", names, false, 0, &which);
        m->reflection = which == 1 ? REFLECTION_SPECULAR : REFLECTION_DIFFUSE;
        return st;
    }
    if (!json_is_object(r.value))
        return load_fail(ctx, &r, "%s %s", forms, load_type_name(r.value));
    thz_status st = load_expect_object(ctx, &r, ward_keys);
    size_t model = 0;
    /* Below 1e-6 (a mirror: "specular"), alpha_x alpha_y (h.n)^4 underflows in the lobe's
     * normalisation, near 1e-155 for both, and photon-map's estimates were NaN. */
    const load_range slope = {1e-6, 1.0, false, false};
    if (st == THZ_OK)
        st = load_choice(ctx, &r, "model", models, true, 0, &model);
    if (st == THZ_OK)
        st = load_number(ctx, &r, "alpha_x", slope, true, 0.0, &m->ward_alpha[0]);
    if (st == THZ_OK)
        st = load_number(ctx, &r, "alpha_y", slope, true, 0.0, &m->ward_alpha[1]);
    if (st != THZ_OK)
        return st;
    m->reflection = REFLECTION_WARD;
    m->ward_table = brdf_ward_table_create(m->ward_alpha[0], m->ward_alpha[1]);
    if (!m->ward_table)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    return THZ_OK;
}

static thz_status load_material(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    static const char *const keys[] = {
        "reflectivity",     "attenuation_per_m",  "emissivity", "transmission", "color", "file",
        "refractive_index", "permittivity_model", "library",    "reflection",   NULL};
    static const char *const transmissions[] = {"diffuse", "straight", NULL};
    thz_status st = load_expect_object(ctx, c, keys);
    if (st != THZ_OK)
        return st;
    for (int k = 0; k < 3; k++)
        m->color[k] = 0.6;
    double lib_range_hz[2] = {0, 0};
    const material_index *lib_index = NULL;
    if (json_object_get(c->value, "library")) {
        st = load_material_library(ctx, c, m, lib_range_hz);
        if (st != THZ_OK)
            return st;
        lib_index = m->index;
    }
    if (json_object_get(c->value, "file")) {
        st = load_material_file(ctx, c, m);
        if (st != THZ_OK)
            return st;
    }
    bool present;
    for (size_t k = 0; k < LOAD_N_PROPERTIES && st == THZ_OK; k++)
        st = load_spectrum(ctx, c, load_material_columns[k], load_material_ranges[k],
                           load_material_property(m, k), &present);
    if (st == THZ_OK)
        st = load_material_index(ctx, c, m, &present);
    if (st == THZ_OK)
        st = load_index_check_channels(ctx, c, m,
                                       m->index && m->index == lib_index ? lib_range_hz : NULL);
    if (st != THZ_OK)
        return st;
    /* With an index, R and alpha_M not given (n == 0) come from it (physics.md). */
    if (m->reflectivity.n == 0 && !m->index) {
        load_cursor k = load_key(c, "reflectivity");
        return load_fail(ctx, &k,
                         "missing key (expected R, a number in [0, 1] or a table "
                         "[[frequency_thz, R], ...], a \"file\" with a reflectivity column, or "
                         "a complex index: refractive_index, permittivity_model or library)");
    }
    if (m->attenuation_per_m.n == 0 && !m->index &&
        !spectrum_set_constant(&m->attenuation_per_m, 0.0))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    size_t transmission = 0;
    st = load_choice(ctx, c, "transmission", transmissions, false, 0, &transmission);
    if (st != THZ_OK)
        return st;
    m->transmission = transmission == 1 ? TRANSMISSION_STRAIGHT : TRANSMISSION_DIFFUSE;
    st = load_material_reflection(ctx, c, m);
    if (st != THZ_OK)
        return st;
    st = load_vector(ctx, c, "color", 3, LOAD_UNIT, false, m->color);
    if (st != THZ_OK)
        return st;
    return load_check_energy(ctx, c, m);
}

thz_status load_materials(load_ctx *ctx, const load_cursor *root)
{
    thz_scene *s = ctx->scene;
    load_cursor c = load_key(root, "materials");
    const char *what = "an object mapping material names to materials, such as "
                       "{\"wall\": {\"reflectivity\": 0.1}}";
    if (!c.value)
        return load_fail(ctx, &c, "missing key (expected %s)", what);
    if (!json_is_object(c.value))
        return load_fail(ctx, &c, "expected %s, got %s", what, load_type_name(c.value));
    size_t n = json_object_size(c.value);
    if (n == 0)
        return load_fail(ctx, &c, "expected at least one material, got an empty object");
    s->materials = thz_calloc(n, sizeof *s->materials);
    if (!s->materials)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    const char *name;
    json_t *value;
    json_object_foreach(c.value, name, value)
    {
        thz_material *m = &s->materials[s->n_materials++];
        load_cursor e = load_key(&c, name);
        m->name = thz_strdup(name);
        if (!m->name)
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        thz_status st = load_material(ctx, &e, m);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}
