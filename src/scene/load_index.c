/* A material's complex index from the scene: `refractive_index` (a constant [n, k] or a
 * table [[frequency_thz, n, k], ...]), the n and k columns of a material CSV, and
 * `permittivity_model` (permittivity.h), including the ITU-R P.2040 materials of
 * data/materials/itu-r-p2040.json and the check of their stated frequency ranges. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/data_dir.h"
#include "core/path.h"
#include "scene/load.h"
#include "scene/scene_checks.h"

/* n and k, each at most 1e100: fresnel_interface squares n + ik, and [1e300, 1e300] (or
 * [1e-300, 1e300]) overflowed it into a photon map at 11.83 K where path read 295 K;
 * [1e150, 1e150] still agreed. The permittivity models' parameters are held to 1e200
 * (n = sqrt(eps) <= 1e100), and every index is checked at the channels' frequencies. */
#define LOAD_MAX_INDEX 1e100
#define LOAD_INDEX_N ((load_range){0.0, LOAD_MAX_INDEX, true, false})
#define LOAD_INDEX_K ((load_range){0.0, LOAD_MAX_INDEX, false, false})
#define LOAD_MAX_PERMITTIVITY 1e200

/* The ITU-R P.2040 table shipped in the data directory. */
#define P2040_FILE "materials/itu-r-p2040.json"

/* Replaces m->index by idx (NULL: out of memory). */
static thz_status set_index(load_ctx *ctx, thz_material *m, material_index *idx)
{
    if (!idx)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    material_index_destroy(m->index);
    m->index = idx;
    return THZ_OK;
}

/* A table [[frequency_thz, n, k], ...] at cursor k (a non-empty array of arrays). */
static thz_status index_table(load_ctx *ctx, const load_cursor *k, thz_material *m)
{
    size_t count = json_array_size(k->value);
    double *f = thz_malloc_array(count, sizeof *f), *n = thz_malloc_array(count, sizeof *n);
    double *kk = thz_malloc_array(count, sizeof *kk);
    thz_status st = THZ_OK;
    if (!f || !n || !kk) {
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    for (size_t i = 0; i < count && st == THZ_OK; i++) {
        load_cursor row = load_index(k, i);
        if (!json_is_array(row.value) || json_array_size(row.value) != 3) {
            st = load_fail(ctx, &row, "expected a row [frequency_thz, n, k], got %s",
                           load_type_name(row.value));
            break;
        }
        load_cursor fc = load_index(&row, 0), nc = load_index(&row, 1), kc = load_index(&row, 2);
        double thz;
        st = load_number_value(ctx, &fc, LOAD_POSITIVE, &thz);
        if (st == THZ_OK && i > 0 && !(thz * 1e12 > f[i - 1]))
            st = load_fail(ctx, &fc, "frequencies must increase strictly, got %g THz after %g THz",
                           thz, f[i - 1] * 1e-12);
        f[i] = thz * 1e12;
        if (st == THZ_OK)
            st = load_number_value(ctx, &nc, LOAD_INDEX_N, &n[i]);
        if (st == THZ_OK)
            st = load_number_value(ctx, &kc, LOAD_INDEX_K, &kk[i]);
    }
    if (st == THZ_OK)
        st = set_index(ctx, m, material_index_table(count, f, n, kk));
cleanup:
    free(f);
    free(n);
    free(kk);
    return st;
}

static thz_status refractive_index(load_ctx *ctx, const load_cursor *k, thz_material *m)
{
    const char *what = "[n, k] (n > 0, k >= 0) or a table [[frequency_thz, n, k], ...]";
    size_t count = json_array_size(k->value);
    if (!json_is_array(k->value) || count == 0)
        return load_fail(ctx, k, "expected %s, got %s", what,
                         json_is_array(k->value) ? "an empty list" : load_type_name(k->value));
    if (json_is_array(json_array_get(k->value, 0)))
        return index_table(ctx, k, m);
    if (count != 2)
        return load_fail(ctx, k, "expected %s, got a list of %zu numbers", what, count);
    load_cursor nc = load_index(k, 0), kc = load_index(k, 1);
    double n, kk;
    thz_status st = load_number_value(ctx, &nc, LOAD_INDEX_N, &n);
    if (st == THZ_OK)
        st = load_number_value(ctx, &kc, LOAD_INDEX_K, &kk);
    if (st == THZ_OK)
        st = set_index(ctx, m, material_index_constant(n, kk));
    return st;
}

/* The rows of ITU-R P.2040 material `name` from the data directory into pm. */
static thz_status p2040_rows(load_ctx *ctx, const load_cursor *mc, const char *name,
                             permittivity_model *pm)
{
    char path[THZ_PATH_MAX];
    thz_status st = thz_data_file(NULL, P2040_FILE, path, sizeof path, ctx->err);
    if (st != THZ_OK)
        return st;
    json_t *doc = NULL; /* as a scene is read: no FIFO or device, line:column of syntax */
    st = load_json_file(path, NULL, NULL, "ITU-R P.2040 table", LOAD_MAX_SCENE_BYTES, &doc,
                        ctx->err);
    if (st != THZ_OK)
        return st;
    json_t *all = json_object_get(doc, "materials"), *rows = json_object_get(all, name);
    if (!json_is_array(rows) || json_array_size(rows) == 0) {
        char names[1024] = "";
        const char *key;
        json_t *v;
        json_object_foreach(all, key, v)
        {
            size_t used = strlen(names);
            snprintf(names + used, sizeof names - used, "%s%s", used ? ", " : "", key);
        }
        json_decref(doc);
        return load_fail(ctx, mc, "unknown ITU-R P.2040 material \"%s\" (expected one of: %s)",
                         name, names);
    }
    snprintf(pm->material, sizeof pm->material, "%s", name);
    size_t i;
    json_t *row;
    st = THZ_OK;
    json_array_foreach(rows, i, row)
    {
        if (i >= PERMITTIVITY_MAX_RANGES) {
            st = thz_error_set(ctx->err, THZ_ERR_INPUT, "%s: %s: more than %d rows", path, name,
                               PERMITTIVITY_MAX_RANGES);
            break;
        }
        permittivity_p2040_row *r = &pm->rows[pm->n_rows++];
        r->lo_hz = json_number_value(json_object_get(row, "from_ghz")) * 1e9;
        r->hi_hz = json_number_value(json_object_get(row, "to_ghz")) * 1e9;
        r->a = json_number_value(json_object_get(row, "a"));
        r->b = json_number_value(json_object_get(row, "b"));
        r->c = json_number_value(json_object_get(row, "c"));
        r->d = json_number_value(json_object_get(row, "d"));
        if (!(r->lo_hz > 0.0 && r->hi_hz > r->lo_hz && r->a > 0.0 && r->c >= 0.0))
            st = thz_error_set(ctx->err, THZ_ERR_INPUT, "%s: %s: row %zu is not a valid fit", path,
                               name, i + 1);
    }
    json_decref(doc);
    return st;
}

static thz_status lorentz_oscillators(load_ctx *ctx, const load_cursor *c, permittivity_model *pm)
{
    static const char *const keys[] = {"frequency_thz", "strength", "width_thz", NULL};
    thz_status st = load_require(ctx, c, "oscillators",
                                 "a list of {\"frequency_thz\", \"strength\", \"width_thz\"}");
    load_cursor list = load_key(c, "oscillators");
    size_t count = json_array_size(list.value);
    if (st == THZ_OK && (!json_is_array(list.value) || count == 0))
        st = load_fail(ctx, &list, "expected a non-empty list of oscillators, got %s",
                       json_is_array(list.value) ? "an empty list" : load_type_name(list.value));
    if (st == THZ_OK && count > PERMITTIVITY_MAX_OSCILLATORS)
        st = load_fail(ctx, &list, "expected at most %d oscillators, got %zu",
                       PERMITTIVITY_MAX_OSCILLATORS, count);
    for (size_t i = 0; i < count && st == THZ_OK; i++) {
        load_cursor o = load_index(&list, i);
        permittivity_oscillator *osc = &pm->oscillators[pm->n_oscillators++];
        double thz = 0, width = 0;
        st = load_expect_object(ctx, &o, keys);
        if (st == THZ_OK)
            st = load_number(ctx, &o, "frequency_thz", LOAD_POSITIVE, true, 0, &thz);
        if (st == THZ_OK)
            st = load_number(ctx, &o, "strength", LOAD_POSITIVE, true, 0, &osc->strength);
        if (st == THZ_OK)
            st = load_number(ctx, &o, "width_thz", LOAD_POSITIVE, true, 0, &width);
        osc->freq_hz = thz * 1e12;
        osc->width_hz = width * 1e12;
    }
    return st;
}

static thz_status permittivity(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    static const char *const keys[][7] = {
        {"model", "eps_inf", "eps_s", "tau_ps", NULL},
        {"model", "eps_inf", "eps_2", "eps_s", "tau1_ps", "tau2_ps", NULL},
        {"model", "eps_inf", "oscillators", NULL},
        {"model", "plasma_frequency_thz", "collision_frequency_thz", NULL},
        {"model", "material", NULL}};
    const load_range eps = {1.0, LOAD_MAX_PERMITTIVITY, false, false};
    if (!json_is_object(c->value))
        return load_fail(ctx, c, "expected an object {\"model\": ...}, got %s",
                         load_type_name(c->value));
    size_t kind = 0;
    thz_status st = load_choice(ctx, c, "model", permittivity_kind_names, true, 0, &kind);
    if (st == THZ_OK)
        st = load_expect_object(ctx, c, keys[kind]);
    if (st != THZ_OK)
        return st;
    permittivity_model pm = {.kind = (permittivity_kind)kind, .eps_inf = 1.0};
    double tau1 = 0, tau2 = 0, fp = 0, fc = 0;
    const char *name = NULL;
    switch (pm.kind) {
    case PERMITTIVITY_DEBYE:
        if ((st = load_number(ctx, c, "eps_inf", eps, true, 0, &pm.eps_inf)) == THZ_OK &&
            (st = load_number(ctx, c, "eps_s", eps, true, 0, &pm.eps_s)) == THZ_OK)
            st = load_number(ctx, c, "tau_ps", LOAD_POSITIVE, true, 0, &tau1);
        break;
    case PERMITTIVITY_DOUBLE_DEBYE:
        if ((st = load_number(ctx, c, "eps_inf", eps, true, 0, &pm.eps_inf)) == THZ_OK &&
            (st = load_number(ctx, c, "eps_2", eps, true, 0, &pm.eps_2)) == THZ_OK &&
            (st = load_number(ctx, c, "eps_s", eps, true, 0, &pm.eps_s)) == THZ_OK &&
            (st = load_number(ctx, c, "tau1_ps", LOAD_POSITIVE, true, 0, &tau1)) == THZ_OK)
            st = load_number(ctx, c, "tau2_ps", LOAD_POSITIVE, true, 0, &tau2);
        break;
    case PERMITTIVITY_LORENTZ:
        if ((st = load_number(ctx, c, "eps_inf", eps, true, 0, &pm.eps_inf)) == THZ_OK)
            st = lorentz_oscillators(ctx, c, &pm);
        break;
    case PERMITTIVITY_DRUDE:
        if ((st = load_number(ctx, c, "plasma_frequency_thz", LOAD_POSITIVE, true, 0, &fp)) ==
            THZ_OK)
            st = load_number(ctx, c, "collision_frequency_thz", LOAD_POSITIVE, true, 0, &fc);
        break;
    case PERMITTIVITY_P2040:
        if ((st = load_string(ctx, c, "material", true, NULL, &name)) == THZ_OK) {
            load_cursor mc = load_key(c, "material");
            st = p2040_rows(ctx, &mc, name, &pm);
        }
        break;
    }
    if (st != THZ_OK)
        return st;
    pm.tau1_s = tau1 * 1e-12;
    pm.tau2_s = tau2 * 1e-12;
    pm.plasma_hz = fp * 1e12;
    pm.collision_hz = fc * 1e12;
    /* Relaxation strengths must be >= 0 for a passive medium (eps'' >= 0). */
    if (pm.kind == PERMITTIVITY_DEBYE && pm.eps_s < pm.eps_inf) {
        load_cursor k = load_key(c, "eps_s");
        return load_fail(ctx, &k, "expected eps_s >= eps_inf = %g, got %g", pm.eps_inf, pm.eps_s);
    }
    if (pm.kind == PERMITTIVITY_DOUBLE_DEBYE && !(pm.eps_s >= pm.eps_2 && pm.eps_2 >= pm.eps_inf)) {
        load_cursor k = load_key(c, "eps_2");
        return load_fail(ctx, &k, "expected eps_s >= eps_2 >= eps_inf, got %g, %g, %g", pm.eps_s,
                         pm.eps_2, pm.eps_inf);
    }
    return set_index(ctx, m, material_index_model(&pm));
}

thz_status load_material_index(load_ctx *ctx, const load_cursor *c, thz_material *m, bool *given)
{
    load_cursor ri = load_key(c, "refractive_index"), pm = load_key(c, "permittivity_model");
    *given = ri.value || pm.value;
    if (ri.value && pm.value)
        return load_fail(ctx, &pm, "give either refractive_index or permittivity_model, not both");
    if (ri.value)
        return refractive_index(ctx, &ri, m);
    if (pm.value)
        return permittivity(ctx, &pm, m);
    return THZ_OK;
}

thz_status load_index_csv(load_ctx *ctx, const load_cursor *file, const csv_table *t,
                          thz_material *m)
{
    bool has_n = csv_column(t, "n") >= 0, has_k = csv_column(t, "k") >= 0;
    if (!has_n && !has_k)
        return THZ_OK;
    if (has_n != has_k)
        return load_fail(ctx, file, "%s: the columns n and k go together, but only %s is there",
                         t->label, has_n ? "n" : "k");
    thz_spectrum n = {0}, k = {0};
    thz_status st = load_csv_spectrum(ctx, file, t, "n", LOAD_INDEX_N, &n);
    if (st == THZ_OK)
        st = load_csv_spectrum(ctx, file, t, "k", LOAD_INDEX_K, &k);
    if (st == THZ_OK) /* one row is a constant (no frequencies) */
        st = set_index(ctx, m,
                       n.freq_hz ? material_index_table(n.n, n.freq_hz, n.value, k.value)
                                 : material_index_constant(n.value[0], k.value[0]));
    spectrum_fini(&n);
    spectrum_fini(&k);
    return st;
}

/* How load_channel_band chose the band, for messages. */
static const char *index_band_how(const thz_channel *ch)
{
    return channel_has_response(ch) ? "where its response is > 0" : "centre +- 2 FWHM";
}

/* The first channel whose band (load_channel_band) leaves [lo_hz, hi_hz], and how many do;
 * n_channels when none. */
static size_t band_outside(const thz_scene *s, double lo_hz, double hi_hz, size_t *count)
{
    size_t first = s->n_channels;
    *count = 0;
    for (size_t i = 0; i < s->n_channels; i++) {
        double lo, hi;
        load_channel_band(&s->channels[i], &lo, &hi);
        if (lo < lo_hz || hi > hi_hz) {
            if (first == s->n_channels)
                first = i;
            (*count)++;
        }
    }
    return first;
}

/* Warns that channel bands leave [lo_hz, hi_hz], `what` saying whose range it is. */
static thz_status warn_outside(load_ctx *ctx, const load_cursor *c, const char *what, double lo_hz,
                               double hi_hz, const char *consequence)
{
    size_t count;
    size_t first = band_outside(ctx->scene, lo_hz, hi_hz, &count);
    if (count == 0)
        return THZ_OK;
    const thz_channel *ch = &ctx->scene->channels[first];
    double lo, hi;
    load_channel_band(ch, &lo, &hi);
    char ghz[160];
    scene_checks_ghz_table_hint(lo_hz, ch->center_hz, ghz, sizeof ghz);
    if (!scene_add_warning(ctx->scene,
                           "%s: %s covers %.4g to %.4g THz%s but channel \"%s\" (band %.4g to "
                           "%.4g THz, %s)%s beyond it; %s",
                           c->path, what, lo_hz * 1e-12, hi_hz * 1e-12, ghz, ch->name, lo * 1e-12,
                           hi * 1e-12, index_band_how(ch),
                           count > 1 ? " and others reach" : " reaches", consequence))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    return THZ_OK;
}

/* Refuses an index whose n or k, at some channel's centre or band end (load_channel_band,
 * ends above 0), is not finite or leaves (0, LOAD_MAX_INDEX] and [0, LOAD_MAX_INDEX]: a
 * permittivity model's extreme parameters (eps_s and tau_ps of 1e300, a resonance or a
 * plasma frequency far beyond the band) give what no constant index may. */
static thz_status index_check_values(load_ctx *ctx, const load_cursor *c, const thz_material *m)
{
    const thz_scene *s = ctx->scene;
    for (size_t i = 0; i < s->n_channels; i++) {
        const thz_channel *ch = &s->channels[i];
        double f[3] = {ch->center_hz, 0.0, 0.0};
        load_channel_band(ch, &f[1], &f[2]);
        for (size_t j = 0; j < 3; j++) {
            double n = 0.0, k = 0.0;
            if (!(f[j] > 0.0) || !material_index_at(m->index, f[j], &n, &k))
                continue;
            if (n > 0.0 && n <= LOAD_MAX_INDEX && k >= 0.0 && k <= LOAD_MAX_INDEX)
                continue;
            static const char *const keys[] = {"permittivity_model", "refractive_index", "library",
                                               "file"};
            load_cursor at = *c;
            for (size_t q = 0; q < sizeof keys / sizeof *keys; q++) {
                load_cursor kq = load_key(c, keys[q]);
                if (kq.value) {
                    at = kq;
                    break;
                }
            }
            return load_fail(ctx, &at,
                             "the complex index of material \"%s\" at %.4g THz (channel \"%s\") "
                             "is n = %g, k = %g; expected n in (0, %g] and k in [0, %g]",
                             m->name, f[j] * 1e-12, ch->name, n, k, LOAD_MAX_INDEX, LOAD_MAX_INDEX);
        }
    }
    return THZ_OK;
}

thz_status load_index_check_channels(load_ctx *ctx, const load_cursor *c, const thz_material *m,
                                     const double *lib_range_hz)
{
    if (!m->index)
        return THZ_OK;
    thz_status st = index_check_values(ctx, c, m);
    if (st != THZ_OK)
        return st;
    double t_lo, t_hi;
    if (lib_range_hz && lib_range_hz[1] > 0.0) {
        load_cursor k = load_key(c, "library");
        st = warn_outside(ctx, &k, "the source of this library entry", lib_range_hz[0],
                          lib_range_hz[1], "its model or data are used there all the same");
    }
    if (st == THZ_OK && strcmp(material_index_form(m->index), "table") == 0 &&
        material_index_range(m->index, &t_lo, &t_hi))
        st = warn_outside(ctx, c, "the table of n and k", t_lo, t_hi,
                          "the end values are used there");
    const permittivity_model *pm = material_index_model_of(m->index);
    if (st != THZ_OK || !pm || pm->kind != PERMITTIVITY_P2040)
        return st;
    const thz_scene *s = ctx->scene;
    for (size_t i = 0; i < s->n_channels; i++) {
        const thz_channel *ch = &s->channels[i];
        double lo, hi;
        load_channel_band(ch, &lo, &hi);
        if (permittivity_covers(pm, lo, hi))
            continue;
        char ranges[512] = "";
        for (size_t r = 0; r < pm->n_rows; r++) {
            size_t used = strlen(ranges);
            snprintf(ranges + used, sizeof ranges - used, "%s%g to %g GHz", r ? ", " : "",
                     pm->rows[r].lo_hz * 1e-9, pm->rows[r].hi_hz * 1e-9);
        }
        load_cursor k = load_key(c, "permittivity_model");
        if (!k.value)
            k = load_key(c, "library");
        return load_fail(ctx, &k,
                         "ITU-R P.2040 gives \"%s\" only for %s, but channel \"%s\" (band %.4g "
                         "to %.4g GHz, %s) reaches outside that",
                         pm->material, ranges, ch->name, lo * 1e-9, hi * 1e-9, index_band_how(ch));
    }
    return THZ_OK;
}
