/* The scene loader for thzmap-scene/1 (scene-format.md): parses the JSON document
 * block by block (each in its own load_<block>.c), in dependency order (channels
 * before sensors, materials before objects), checks every value as it goes and stops
 * at the first error with one message naming the file and the JSON path. After a
 * successful parse it prepares the atmosphere and collects the warnings `validate`
 * prints. Also the name and list helpers the blocks share. */
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/c_locale.h"
#include "core/file.h"
#include "scene/load.h"
#include "scene/mesh_import.h"
#include "scene/scene_checks.h"

/* Explicit emissivity may differ from Kirchhoff's value by this much before validate
 * warns (physics.md "Surfaces"). */
#define LOAD_KIRCHHOFF_TOLERANCE 0.01
/* Rounding slack for eps + R-bar <= 1 (load_materials.c's for eps + R). */
#define LOAD_ENERGY_SLACK 1e-9

/* ---- names ---------------------------------------------------------------------- */

thz_status load_unique_name(load_ctx *ctx, const load_cursor *list, size_t i, const char *what,
                            bool required, const char **out)
{
    load_cursor e = load_index(list, i);
    thz_status st = load_string(ctx, &e, "name", required, NULL, out);
    if (st != THZ_OK || !*out)
        return st;
    load_cursor k = load_key(&e, "name");
    if (!(*out)[0])
        return load_fail(ctx, &k, "expected a non-empty %s name", what);
    if (ctx->names_of != list->value || ctx->names_next != i) { /* names before i, afresh */
        json_decref(ctx->names);
        ctx->names = json_object();
        ctx->names_of = list->value;
        for (size_t j = 0; ctx->names && j < i; j++) {
            json_t *other = json_object_get(json_array_get(list->value, j), "name");
            if (json_is_string(other) && !json_object_get(ctx->names, json_string_value(other)) &&
                json_object_set_new(ctx->names, json_string_value(other),
                                    json_integer((json_int_t)j)))
                break;
        }
    }
    json_t *earlier = ctx->names ? json_object_get(ctx->names, *out) : NULL;
    if (earlier)
        return load_fail(ctx, &k,
                         "%s name \"%s\" is already used by %s[%zu] (expected unique names)", what,
                         *out, list->path, (size_t)json_integer_value(earlier));
    if (!ctx->names || json_object_set_new(ctx->names, *out, json_integer((json_int_t)i))) {
        json_decref(ctx->names);
        ctx->names = NULL;
        ctx->names_of = NULL;
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory checking %s names", what);
    }
    ctx->names_next = i + 1;
    return THZ_OK;
}

thz_status load_list(load_ctx *ctx, const load_cursor *root, const char *key, const char *what,
                     load_cursor *list, size_t *n)
{
    *list = load_key(root, key);
    if (!list->value)
        return load_fail(ctx, list, "missing key (expected a list of %ss)", what);
    if (!json_is_array(list->value))
        return load_fail(ctx, list, "expected a list of %ss, got %s", what,
                         load_type_name(list->value));
    *n = json_array_size(list->value);
    if (*n == 0)
        return load_fail(ctx, list, "expected at least one %s, got an empty list", what);
    return THZ_OK;
}

/* ---- warnings ------------------------------------------------------------------- */

/* Largest Kirchhoff violation of obj over the channel centres and the table points of
 * its material; *at_hz gets where. */
static double load_kirchhoff_worst(thz_scene *s, const thz_object *obj, double *at_hz)
{
    thz_material *m = &s->materials[obj->material];
    double worst = 0.0;
    *at_hz = s->channels[0].center_hz;
    for (size_t c = 0; c < s->n_channels; c++) {
        optics_point o = scene_object_optics(s, obj, s->channels[c].center_hz);
        double v = optics_kirchhoff_violation(&o);
        if (v > worst) {
            worst = v;
            *at_hz = s->channels[c].center_hz;
        }
    }
    for (size_t k = 0; k < LOAD_N_PROPERTIES; k++) {
        const thz_spectrum *sp = load_material_property(m, k);
        for (size_t i = 0; sp->freq_hz && i < sp->n; i++) {
            optics_point o = scene_object_optics(s, obj, sp->freq_hz[i]);
            double v = optics_kirchhoff_violation(&o);
            if (v > worst) {
                worst = v;
                *at_hz = sp->freq_hz[i];
            }
        }
    }
    return worst;
}

void load_channel_band(const thz_channel *ch, double *lo_hz, double *hi_hz)
{
    channel_support_hz(ch, 2.0 * CHANNEL_FWHM_PER_SIGMA, lo_hz, hi_hz);
    if (*lo_hz < 0.0) /* a wide band: no frequency below 0 (nor a rounding's -6e-17 THz) */
        *lo_hz = 0.0;
}

/* Whether obj's material gives an explicit emissivity beside an R that varies with angle
 * (a complex index) at freq_hz; then *eps and *r_bar, R-bar = 2 int R(mu) mu dmu. */
static bool load_index_energy(const thz_scene *s, const thz_object *obj, double freq_hz,
                              double *eps, double *r_bar)
{
    optics_point o = scene_object_optics(s, obj, freq_hz);
    if (!o.explicit_emissivity || !optics_reflectance_varies(&o))
        return false;
    *eps = optics_emissivity(&o, 1.0);
    *r_bar = optics_mean_reflectance(&o);
    return true;
}

/* Refuses an explicit emissivity beside a complex index (R varies with angle) where
 * eps + R-bar > 1, R-bar of the half-space or the shell's slab: the surface would emit
 * more than the isothermal radiation around it gives it to absorb. With a constant R,
 * R-bar = R, the rule load_materials.c checks (physics.md "Surfaces"). Checked at each
 * channel's centre and band ends and at the emissivity table's points. */
static thz_status load_check_index_energy(load_ctx *ctx, const load_cursor *root)
{
    const thz_scene *s = ctx->scene;
    for (size_t i = 0; i < s->n_objects; i++) {
        const thz_object *obj = &s->objects[i];
        const thz_material *m = &s->materials[obj->material];
        if (m->emissivity.n == 0 || !m->index)
            continue;
        size_t n_table = m->emissivity.freq_hz ? m->emissivity.n : 0;
        for (size_t j = 0; j < 3 * s->n_channels + n_table; j++) {
            double f, band[3], eps, r_bar;
            if (j < 3 * s->n_channels) {
                band[0] = s->channels[j / 3].center_hz;
                load_channel_band(&s->channels[j / 3], &band[1], &band[2]);
                f = band[j % 3];
            } else {
                f = m->emissivity.freq_hz[j - 3 * s->n_channels];
            }
            if (f > 0.0 && load_index_energy(s, obj, f, &eps, &r_bar) &&
                eps + r_bar > 1.0 + LOAD_ENERGY_SLACK) {
                load_cursor mc = load_key(root, "materials"), c = load_key(&mc, m->name);
                load_cursor e = load_key(&c, "emissivity");
                return load_fail(
                    ctx, e.value ? &e : &c,
                    "emissivity + the hemispherical mean reflectance of the "
                    "material's complex index must not exceed 1, got %.10g + %.10g = %.10g "
                    "at %.4g THz (object \"%s\")",
                    eps, r_bar, eps + r_bar, f * 1e-12, obj->name);
            }
        }
    }
    return THZ_OK;
}

/* Warns about channel bands (load_channel_band) that leave table `sp`. */
static bool load_warn_table(thz_scene *s, const thz_spectrum *sp, const char *what)
{
    if (!sp->freq_hz || sp->n < 2)
        return true;
    size_t first = s->n_channels, count = 0;
    for (size_t c = 0; c < s->n_channels; c++) {
        double lo, hi;
        load_channel_band(&s->channels[c], &lo, &hi);
        if (spectrum_table_exceeded(sp, lo, hi)) {
            if (first == s->n_channels)
                first = c;
            count++;
        }
    }
    if (count == 0)
        return true;
    const thz_channel *ch = &s->channels[first];
    double lo, hi;
    load_channel_band(ch, &lo, &hi);
    char ghz[160];
    scene_checks_ghz_table_hint(sp->freq_hz[0], ch->center_hz, ghz, sizeof ghz);
    return scene_add_warning(
        s,
        "%s: the table covers %.4g to %.4g THz%s but channel \"%s\" (band %.4g to %.4g THz, "
        "%s)%s beyond it; the end values are used there",
        what, sp->freq_hz[0] * 1e-12, sp->freq_hz[sp->n - 1] * 1e-12, ghz, ch->name, lo * 1e-12,
        hi * 1e-12, channel_has_response(ch) ? "where its response is > 0" : "centre +- 2 FWHM",
        count > 1 ? " and others reach" : " reaches");
}

/* Whether object i of the document (validated) is a mesh file: built-in shapes are
 * wound consistently by construction (primitives.h), so only files need the check. */
static bool load_is_mesh_file(const load_cursor *root, size_t i)
{
    json_t *object = json_array_get(json_object_get(root->value, "objects"), i);
    const char *type = json_string_value(json_object_get(json_object_get(object, "shape"), "type"));
    return type && strcmp(type, "mesh") == 0;
}

/* Whether the box lo..hi leaves the air's extent by more than a rounding (a room's walls
 * on the extent's faces stay inside). */
static bool load_outside_extent(const thz_atmosphere *atm, const double lo[3], const double hi[3])
{
    for (int k = 0; k < 3; k++) {
        double size = atm->extent_max_m[k] - atm->extent_min_m[k];
        double slack = 1e-6 * size + 1e-9;
        if (lo[k] < atm->extent_min_m[k] - slack || hi[k] > atm->extent_max_m[k] + slack)
            return true;
    }
    return false;
}

/* An extent smaller than the scene: free paths outside it still attenuate and emit
 * (docs/atmosphere.md, "Limits"), so say which objects and sensors leave it. */
static bool load_warn_extent(thz_scene *s)
{
    const thz_atmosphere *atm = &s->atmosphere;
    if (!atm->emitting || !atm->has_extent)
        return true;
    bool ok = true;
    for (size_t i = 0; i < s->n_objects && ok; i++) {
        const thz_mesh *m = &s->objects[i].mesh;
        if (load_outside_extent(atm, m->bbox_min_m, m->bbox_max_m))
            ok = scene_add_warning(s,
                                   "object \"%s\" reaches outside the atmosphere's extent: the "
                                   "air between surfaces there attenuates and emits as inside "
                                   "it; enclose the scene in extent_min_m .. extent_max_m",
                                   s->objects[i].name);
    }
    for (size_t j = 0; j < s->n_sensors && ok; j++)
        if (load_outside_extent(atm, s->sensors[j].position_m, s->sensors[j].position_m))
            ok = scene_add_warning(s,
                                   "sensor \"%s\" is outside the atmosphere's extent: the air "
                                   "between it and the surfaces it sees attenuates and emits as "
                                   "inside it; enclose the scene in extent_min_m .. extent_max_m",
                                   s->sensors[j].name);
    return ok;
}

static thz_status load_warnings(load_ctx *ctx, const load_cursor *root)
{
    thz_scene *s = ctx->scene;
    bool ok = true;
    for (size_t m = 0; m < s->n_materials; m++) {
        thz_material *mat = &s->materials[m];
        for (size_t k = 0; k < LOAD_N_PROPERTIES && ok; k++) {
            char what[256];
            snprintf(what, sizeof what, "material \"%s\", %s", mat->name, load_material_columns[k]);
            ok = load_warn_table(s, load_material_property(mat, k), what);
        }
    }
    if (ok && s->atmosphere.model == ATM_TABLE)
        ok = load_warn_table(s, &s->atmosphere.attenuation_per_m, "atmosphere attenuation_per_m");
    if (ok)
        ok = load_warn_extent(s);
    for (size_t i = 0; i < s->n_objects && ok; i++) {
        const thz_object *obj = &s->objects[i];
        if (s->materials[obj->material].emissivity.n > 0) {
            double at_hz;
            double worst = load_kirchhoff_worst(s, obj, &at_hz);
            if (worst > LOAD_KIRCHHOFF_TOLERANCE)
                ok = scene_add_warning(
                    s,
                    "object \"%s\": the explicit emissivity of material \"%s\" differs from "
                    "Kirchhoff's absorptivity by up to %.3g (at %.4g THz); the scene does not "
                    "conserve energy in equilibrium",
                    obj->name, s->materials[obj->material].name, worst, at_hz * 1e-12);
        }
        if (!load_is_mesh_file(root, i))
            continue;
        mesh_defects d;
        if (!mesh_import_defects(&obj->mesh, &d))
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        if (ok && d.repeated > 0)
            ok = scene_add_warning(s,
                                   "object \"%s\": %zu triangle(s) repeat another's three corners: "
                                   "each counts its area and emits again, so the surface there is "
                                   "too bright; remove the repeats",
                                   obj->name, d.repeated);
        if (ok && d.degenerate > 0)
            ok = scene_add_warning(s,
                                   "object \"%s\": %zu triangle(s) of no area (corners on one "
                                   "line): they emit nothing and stop nothing",
                                   obj->name, d.degenerate);
        if (ok && d.winding_conflicts > 0)
            ok = scene_add_warning(s,
                                   "object \"%s\": inconsistent winding: %zu edge(s) used twice "
                                   "in the same direction, so some normals point the wrong way",
                                   obj->name, d.winding_conflicts);
        if (ok && d.open_edges > 0 && !scene_object_two_sided(obj))
            ok = scene_add_warning(s,
                                   "object \"%s\": the mesh is open: %zu edge(s) of one triangle "
                                   "only (holes, an open surface's rim, or a file cut short); "
                                   "seen through an opening, a solid shows its back side, which "
                                   "neither emits nor reflects",
                                   obj->name, d.open_edges);
    }
    if (!ok)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    return THZ_OK;
}

/* ---- the document --------------------------------------------------------------- */

static thz_status load_document(load_ctx *ctx, json_t *doc)
{
    static const char *const keys[] = {"format",  "name",    "channels", "materials", "atmosphere",
                                       "objects", "sensors", "photons",  "render",    NULL};
    thz_scene *s = ctx->scene;
    load_cursor root = load_root(doc);
    const char *format, *name = NULL;
    if (!json_is_object(doc))
        return load_fail(ctx, NULL, "expected a JSON object {\"format\": \"%s\", ...}",
                         LOAD_FORMAT);
    if (!json_object_get(doc, "format"))
        return load_require(ctx, &root, "format",
                            "\"" LOAD_FORMAT "\" or \"" LOAD_FORMAT_1_1 "\"; a sequence file, "
                            "which `thzmap batch` runs, says \"" LOAD_SEQUENCE_FORMAT "\"");
    thz_status st = load_string(ctx, &root, "format", true, NULL, &format);
    if (st == THZ_OK && strcmp(format, LOAD_FORMAT) != 0 && strcmp(format, LOAD_FORMAT_1_1) != 0) {
        load_cursor k = load_key(&root, "format");
        bool sequence = strcmp(format, LOAD_SEQUENCE_FORMAT) == 0;
        return load_fail(ctx, &k, "expected \"%s\" or \"%s\", got \"%s\"%s", LOAD_FORMAT,
                         LOAD_FORMAT_1_1, format,
                         sequence ? " (a sequence file, which `thzmap batch` runs)" : "");
    }
    if (st == THZ_OK)
        st = load_expect_object(ctx, &root, keys);
    if (st == THZ_OK)
        st = load_string(ctx, &root, "name", false, NULL, &name);
    if (st != THZ_OK)
        return st;
    if (name) {
        free(s->name);
        s->name = thz_strdup(name);
        if (!s->name)
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    }
    st = load_channels(ctx, &root);
    if (st == THZ_OK)
        st = load_materials(ctx, &root);
    if (st == THZ_OK) {
        load_cursor atm = load_key(&root, "atmosphere");
        st = load_atmosphere(ctx, &atm, &s->atmosphere);
    }
    if (st == THZ_OK)
        st = load_objects(ctx, &root);
    if (st == THZ_OK)
        st = load_sensors(ctx, &root);
    if (st == THZ_OK)
        st = load_photons(ctx, &root);
    if (st == THZ_OK)
        st = load_render(ctx, &root);
    if (st != THZ_OK)
        return st;
    /* The meshes' closedness and volumes, for the enclosure here and the checks below. */
    check_object *info = scene_checks_objects(s);
    if (!info)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    size_t enclosure = scene_checks_enclosure(s, info);
    st = load_atmosphere_defaults(ctx, enclosure == SIZE_MAX ? 0.0
                                                             : s->objects[enclosure].temperature_k);
    if (st == THZ_OK) {
        st = atmosphere_prepare(&s->atmosphere, s->channels, s->n_channels, ctx->err);
        if (st != THZ_OK && ctx->err) {
            thz_error_prefix(ctx->err, "%s: atmosphere: ", ctx->label);
            size_t n = strnlen(ctx->err->message, sizeof ctx->err->message);
            scene_checks_ghz_hint(s, ctx->err->message + n, sizeof ctx->err->message - n);
        }
    }
    if (st == THZ_OK)
        st = load_check_index_energy(ctx, &root);
    if (st == THZ_OK)
        st = load_warnings(ctx, &root);
    scene_check_inputs in = {.non_emitting_air = ctx->non_emitting_air,
                             .background_given = ctx->background_given};
    if (st == THZ_OK && !scene_checks_run(s, info, enclosure, &in))
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    free(info);
    return st;
}

/* The scene's default name: the file name without directory and extension. */
static char *load_stem(const char *label)
{
    const char *base = strrchr(label, '/');
    base = base ? base + 1 : label;
    char *stem = thz_strdup(base);
    if (stem) {
        char *dot = strrchr(stem, '.');
        if (dot && dot != stem)
            *dot = '\0';
    }
    return stem;
}

static thz_status load_begin(const char *path_or_label, const char *dir, thz_scene **out,
                             thz_error *err)
{
    *out = scene_create();
    if (!*out)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    thz_scene *s = *out;
    s->path = thz_strdup(path_or_label);
    s->dir = thz_strdup(dir);
    s->name = load_stem(path_or_label);
    if (!s->path || !s->dir || !s->name)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    return THZ_OK;
}

/* Loads the document into *scene; root (a real path or NULL) confines the files it names. */
static thz_status load_finish(thz_scene **scene, json_t *doc, const char *root, thz_status st,
                              thz_error *err)
{
    if (st == THZ_OK) {
        load_ctx ctx = {.label = (*scene)->path,
                        .dir = (*scene)->dir,
                        .root = root,
                        .scene = *scene,
                        .err = err};
        locale_t previous = thz_locale_enter(); /* numbers in messages as in the file */
        st = load_document(&ctx, doc);
        thz_locale_leave(previous);
        json_decref(ctx.names);
    }
    json_decref(doc);
    if (st != THZ_OK) {
        scene_destroy(*scene);
        *scene = NULL;
    }
    return st;
}

/* The column where the token jansson names ("... near 'TOKEN'") begins: jansson gives
 * the column of its last character, a user looks for its first (characters, as
 * jansson counts them: UTF-8 continuation bytes are not counted). */
static int load_token_column(const json_error_t *je)
{
    const char *near = strstr(je->text, " near '");
    size_t len = strlen(je->text);
    if (!near || len < 2 || je->text[len - 1] != '\'')
        return je->column;
    int chars = 0;
    for (const char *c = near + 7; c < je->text + len - 1; c++)
        chars += ((unsigned char)*c & 0xC0) != 0x80;
    return chars > 1 && je->column >= chars ? je->column - (chars - 1) : je->column;
}

/* The error of a failed parse: out of memory, or the syntax error jansson found, and
 * what the file is when its first bytes tell (real: the file's path, NULL for a text). */
static thz_status load_syntax_error(const char *label, const char *what, const json_error_t *je,
                                    bool out_of_memory, const char *real, thz_error *err)
{
    if (out_of_memory)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while parsing the %s", label,
                             what);
    unsigned char head[FILE_HEAD_BYTES];
    const char *kind = real ? file_kind_hint(head, file_read_head(real, head)) : NULL;
    char is[160] = "";
    if (kind)
        snprintf(is, sizeof is, " (the file is %s)", kind);
    else if (json_error_code(je) == json_error_numeric_overflow)
        snprintf(is, sizeof is,
                 " (a number beyond what JSON's numbers hold here: whole numbers "
                 "up to 9223372036854775807, reals up to about 1.8e308)");
    else if (json_error_code(je) == json_error_invalid_utf8)
        snprintf(is, sizeof is,
                 " (JSON is UTF-8 text: was the %s saved in another encoding, such as UTF-16?)",
                 real ? "file" : "text");
    else if (je->position == 0 && je->line <= 1 &&
             json_error_code(je) == json_error_premature_end_of_input)
        snprintf(is, sizeof is, " (the %s is empty)", real ? "file" : "text");
    int column = load_token_column(je);
    if (je->line > 0) /* a column 0 (an empty file) is the line's first */
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%d:%d: invalid JSON: %s%s", label, je->line,
                             column > 0 ? column : 1, je->text, is);
    return thz_error_set(err, THZ_ERR_INPUT, "%s: invalid JSON: %s%s", label, je->text, is);
}

thz_status load_json_file(const char *path, const char *real, const char *label, const char *what,
                          uint64_t max_bytes, json_t **out, thz_error *err)
{
    *out = NULL;
    if (!real)
        real = path;
    if (!label)
        label = path;
    /* a FIFO or device would block the open or never end (core/file.h) */
    thz_status st = file_check_regular(real, label, max_bytes, NULL, err);
    if (st != THZ_OK)
        return st;
    FILE *f = fopen(real, "rb");
    if (!f && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while opening the %s", path,
                             what);
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open %s file: %s", path, what,
                             strerror(errno));
    json_error_t je;
    bool oom = false;
    *out = load_json_parse(f, NULL, &je, &oom);
    fclose(f);
    return *out ? THZ_OK : load_syntax_error(path, what, &je, oom, real, err);
}

thz_status scene_load_within(const char *path, const char *root, thz_scene **out, thz_error *err)
{
    *out = NULL;
    thz_error_clear(err);
    char *root_real = NULL, *real = NULL;
    const char *refusal = NULL;
    json_t *doc = NULL;
    thz_status st = load_root_real(root, &root_real, err);
    if (st == THZ_OK) {
        st = load_file_confine(path, root_real, &real, &refusal);
        if (st == THZ_ERR_INPUT)
            thz_error_set(err, st, "%s: the scene file %s", path, refusal);
        else if (st != THZ_OK)
            thz_error_set(err, st, "out of memory");
    }
    if (st == THZ_OK)
        st = load_json_file(path, real, NULL, "scene", LOAD_MAX_SCENE_BYTES, &doc, err);
    free(real);
    char *copy = st == THZ_OK ? thz_strdup(path) : NULL;
    if (st == THZ_OK && !copy)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    if (st == THZ_OK) {
        st = load_begin(path, dirname(copy), out, err);
        st = load_finish(out, doc, root_real, st, err);
    } else {
        json_decref(doc);
    }
    free(copy);
    free(root_real);
    return st;
}

thz_status scene_load(const char *path, thz_scene **out, thz_error *err)
{
    return scene_load_within(path, NULL, out, err);
}

thz_status scene_load_string_within(const char *json_text, const char *base_dir, const char *label,
                                    const char *root, thz_scene **out, thz_error *err)
{
    *out = NULL;
    thz_error_clear(err);
    if (!label)
        label = "<scene>";
    char *root_real = NULL;
    thz_status st = load_root_real(root, &root_real, err);
    if (st != THZ_OK)
        return st;
    json_error_t je;
    bool oom = false;
    json_t *doc = load_json_parse(NULL, json_text, &je, &oom);
    if (!doc) {
        free(root_real);
        return load_syntax_error(label, "scene", &je, oom, NULL, err);
    }
    st = load_begin(label, base_dir ? base_dir : ".", out, err);
    st = load_finish(out, doc, root_real, st, err);
    free(root_real);
    return st;
}

thz_status scene_load_string(const char *json_text, const char *base_dir, const char *label,
                             thz_scene **out, thz_error *err)
{
    return scene_load_string_within(json_text, base_dir, label, NULL, out, err);
}
