/* The scene loader for thzmap-scene/1 (scene-format.md): parses the JSON document
 * section by section, in dependency order (channels before sensors, materials before
 * objects), checks every value as it goes and stops at the first error with one
 * message naming the file and the JSON path. After a successful parse it prepares
 * the atmosphere, finalises the meshes and collects the warnings `validate` prints. */
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/vec3.h"
#include "scene/load.h"
#include "scene/mesh_import.h"
#include "scene/primitives.h"
#include "scene/transform.h"
#include "sensor/images.h"

#define LOAD_FORMAT "thzmap-scene/1"
#define LOAD_MAX_CHANNELS 4096u
#define LOAD_MAX_RESOLUTION 65536u
#define LOAD_MAX_OVERSAMPLING 16u
/* Explicit emissivity may differ from Kirchhoff's value by this much before validate
 * warns (physics.md "Surfaces"). */
#define LOAD_KIRCHHOFF_TOLERANCE 0.01
/* Rounding slack for eps + R <= 1. */
#define LOAD_SUM_SLACK 1e-9

/* ---- names ---------------------------------------------------------------------- */

/* Member "name" of list[i]: a non-empty string unlike the "name" of every earlier entry
 * of the list (entries without one do not count). *out is borrowed from the document,
 * NULL when the key is absent and not required. */
static thz_status load_unique_name(load_ctx *ctx, const load_cursor *list, size_t i,
                                   const char *what, bool required, const char **out)
{
    load_cursor e = load_index(list, i);
    thz_status st = load_string(ctx, &e, "name", required, NULL, out);
    if (st != THZ_OK || !*out)
        return st;
    load_cursor k = load_key(&e, "name");
    if (!(*out)[0])
        return load_fail(ctx, &k, "expected a non-empty %s name", what);
    for (size_t j = 0; j < i; j++) {
        json_t *other = json_object_get(json_array_get(list->value, j), "name");
        if (json_is_string(other) && strcmp(json_string_value(other), *out) == 0)
            return load_fail(ctx, &k,
                             "%s name \"%s\" is already used by %s[%zu] (expected unique names)",
                             what, *out, list->path, j);
    }
    return THZ_OK;
}

/* ---- channels ------------------------------------------------------------------- */

/* Default names show the frequency with 3 decimals, more where that is what tells two
 * channels apart (0.350 and 0.3501 THz become "0.3500 THz" and "0.3501 THz"), up to
 * 1 Hz; channels at the same frequency get their index too. */
#define LOAD_NAME_MIN_DECIMALS 3
#define LOAD_NAME_MAX_DECIMALS 12

typedef struct load_name_entry {
    char name[sizeof(((thz_channel *)NULL)->name)];
    size_t channel;
} load_name_entry;

static int load_name_cmp(const void *a, const void *b)
{
    const load_name_entry *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->channel > y->channel) - (x->channel < y->channel);
}

/* Fills e with every channel's name, or for unnamed channels their frequency with
 * `decimals` decimals, sorted by name. */
static void load_name_entries(const thz_scene *s, load_name_entry *e, int decimals)
{
    for (size_t i = 0; i < s->n_channels; i++) {
        const thz_channel *ch = &s->channels[i];
        e[i].channel = i;
        if (ch->name[0])
            memcpy(e[i].name, ch->name, sizeof e[i].name);
        else
            snprintf(e[i].name, sizeof e[i].name, "%.*f THz", decimals, ch->center_hz * 1e-12);
    }
    qsort(e, s->n_channels, sizeof *e, load_name_cmp);
}

/* Names the channels that have no name (c: the channels key; `list`: the list form,
 * whose entries' paths then name a channel). */
static thz_status load_channel_default_names(load_ctx *ctx, const load_cursor *c, bool list)
{
    thz_scene *s = ctx->scene;
    size_t n = s->n_channels;
    load_name_entry *e = thz_malloc_array(n, sizeof *e);
    bool *unnamed = thz_malloc_array(n, sizeof *unnamed);
    thz_status st = THZ_OK;
    if (!e || !unnamed) {
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    size_t left = 0;
    for (size_t i = 0; i < n; i++) {
        unnamed[i] = !s->channels[i].name[0];
        left += unnamed[i];
    }
    /* Names of different widths never coincide, so a name unique among those of its
     * width (and the given ones) is unique. */
    for (int d = LOAD_NAME_MIN_DECIMALS; d <= LOAD_NAME_MAX_DECIMALS && left > 0; d++) {
        load_name_entries(s, e, d);
        for (size_t i = 0; i < n; i++) {
            thz_channel *ch = &s->channels[e[i].channel];
            bool alone = (i == 0 || strcmp(e[i].name, e[i - 1].name) != 0) &&
                         (i + 1 == n || strcmp(e[i].name, e[i + 1].name) != 0);
            if (alone && !ch->name[0]) {
                memcpy(ch->name, e[i].name, sizeof ch->name);
                left--;
            }
        }
    }
    for (size_t i = 0; i < n && left > 0; i++) {
        thz_channel *ch = &s->channels[i];
        if (!ch->name[0])
            snprintf(ch->name, sizeof ch->name, "%.*f THz #%zu", LOAD_NAME_MIN_DECIMALS,
                     ch->center_hz * 1e-12, i);
    }
    /* Only a given name that looks like a default one can still coincide with it. */
    load_name_entries(s, e, 0);
    for (size_t i = 1; i < n; i++) {
        if (strcmp(e[i].name, e[i - 1].name) != 0)
            continue;
        size_t mine = unnamed[e[i].channel] ? e[i].channel : e[i - 1].channel;
        size_t other = mine == e[i].channel ? e[i - 1].channel : e[i].channel;
        load_cursor k = list ? load_index(c, mine) : *c;
        st = load_fail(ctx, &k,
                       "the default name \"%s\" of channels[%zu] is already used by "
                       "channels[%zu] (expected a \"name\" for it)",
                       s->channels[mine].name, mine, other);
        goto cleanup;
    }
cleanup:
    free(e);
    free(unnamed);
    return st;
}

static const load_range load_relative_width = {0.0, 0.5, true, false};

static thz_status load_channel_range(load_ctx *ctx, const load_cursor *c)
{
    static const char *const keys[] = {"from_thz", "to_thz", "count", "relative_width", NULL};
    thz_scene *s = ctx->scene;
    double from, to, width;
    uint64_t count;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st == THZ_OK)
        st = load_number(ctx, c, "from_thz", LOAD_POSITIVE, true, 0, &from);
    if (st == THZ_OK)
        st = load_number(ctx, c, "to_thz", LOAD_POSITIVE, true, 0, &to);
    if (st == THZ_OK)
        st = load_integer(ctx, c, "count", 1, LOAD_MAX_CHANNELS, true, 0, &count);
    if (st == THZ_OK)
        st = load_number(ctx, c, "relative_width", load_relative_width, true, 0, &width);
    if (st != THZ_OK)
        return st;
    load_cursor k = load_key(c, "to_thz");
    if (count == 1 && to != from)
        return load_fail(ctx, &k, "with count 1, to_thz must equal from_thz (%g)", from);
    if (count > 1 && !(to > from))
        return load_fail(ctx, &k, "expected a number > from_thz (%g), got %g", from, to);
    s->channels = thz_calloc(count, sizeof *s->channels);
    if (!s->channels)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    s->n_channels = count;
    for (size_t i = 0; i < count; i++) {
        thz_channel *ch = &s->channels[i];
        double thz = count == 1 ? from : from + (to - from) * (double)i / (double)(count - 1);
        if (i + 1 == count)
            thz = to; /* exactly the given end */
        ch->center_hz = thz * 1e12;
        ch->relative_width = width;
    }
    return load_channel_default_names(ctx, c, false);
}

static thz_status load_channels(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"name", "frequency_thz", "relative_width", NULL};
    thz_scene *s = ctx->scene;
    load_cursor c = load_key(root, "channels");
    const char *what = "a list of channels [{\"frequency_thz\": ..., \"relative_width\": ...}] or "
                       "a range {\"from_thz\", \"to_thz\", \"count\", \"relative_width\"}";
    if (!c.value)
        return load_fail(ctx, &c, "missing key (expected %s)", what);
    if (json_is_object(c.value))
        return load_channel_range(ctx, &c);
    if (!json_is_array(c.value))
        return load_fail(ctx, &c, "expected %s, got %s", what, load_type_name(c.value));
    size_t n = json_array_size(c.value);
    if (n == 0)
        return load_fail(ctx, &c, "expected at least one channel, got an empty list");
    if (n > LOAD_MAX_CHANNELS)
        return load_fail(ctx, &c, "expected at most %u channels, got %zu", LOAD_MAX_CHANNELS, n);
    s->channels = thz_calloc(n, sizeof *s->channels);
    if (!s->channels)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    s->n_channels = n;
    for (size_t i = 0; i < n; i++) {
        load_cursor e = load_index(&c, i);
        thz_channel *ch = &s->channels[i];
        double thz;
        const char *name = NULL;
        thz_status st = load_expect_object(ctx, &e, keys);
        if (st == THZ_OK)
            st = load_number(ctx, &e, "frequency_thz", LOAD_POSITIVE, true, 0, &thz);
        if (st == THZ_OK)
            st = load_number(ctx, &e, "relative_width", load_relative_width, true, 0,
                             &ch->relative_width);
        if (st == THZ_OK)
            st = load_unique_name(ctx, &c, i, "channel", false, &name);
        if (st != THZ_OK)
            return st;
        ch->center_hz = thz * 1e12;
        if (name && strlen(name) >= sizeof ch->name) {
            load_cursor k = load_key(&e, "name");
            return load_fail(ctx, &k, "channel names are at most %zu characters",
                             sizeof ch->name - 1);
        }
        if (name)
            memcpy(ch->name, name, strlen(name) + 1);
    }
    return load_channel_default_names(ctx, &c, true);
}

/* ---- materials ------------------------------------------------------------------ */

/* The spectral properties of a material: their keys (and CSV columns), accepted
 * values, and load_material_property's order. */
static const char *const load_material_columns[] = {"reflectivity", "attenuation_per_m",
                                                    "emissivity", NULL};
static const load_range load_material_ranges[] = {
    {0.0, 1.0, false, false}, {0.0, INFINITY, false, false}, {0.0, 1.0, false, false}};
#define LOAD_N_PROPERTIES 3

static thz_spectrum *load_material_property(thz_material *m, size_t k)
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
    load_cursor file = load_key(c, "file");
    st = load_csv_columns(ctx, &file, &t, load_material_columns, NULL);
    for (size_t k = 0; k < LOAD_N_PROPERTIES && st == THZ_OK; k++)
        if (csv_column(&t, load_material_columns[k]) >= 0)
            st = load_csv_spectrum(ctx, &file, &t, load_material_columns[k],
                                   load_material_ranges[k], load_material_property(m, k));
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
                return load_fail(ctx, &k,
                                 "emissivity + reflectivity must not exceed 1, got %g + %g = %g "
                                 "at %.4g THz",
                                 e, r, e + r, f * 1e-12);
            }
        }
    }
    return THZ_OK;
}

static thz_status load_material(load_ctx *ctx, const load_cursor *c, thz_material *m)
{
    static const char *const keys[] = {
        "reflectivity", "attenuation_per_m", "emissivity", "transmission", "color", "file", NULL};
    static const char *const transmissions[] = {"diffuse", "straight", NULL};
    thz_status st = load_expect_object(ctx, c, keys);
    if (st != THZ_OK)
        return st;
    if (json_object_get(c->value, "file")) {
        st = load_material_file(ctx, c, m);
        if (st != THZ_OK)
            return st;
    }
    bool present;
    for (size_t k = 0; k < LOAD_N_PROPERTIES && st == THZ_OK; k++)
        st = load_spectrum(ctx, c, load_material_columns[k], load_material_ranges[k],
                           load_material_property(m, k), &present);
    if (st != THZ_OK)
        return st;
    if (m->reflectivity.n == 0) {
        load_cursor k = load_key(c, "reflectivity");
        return load_fail(ctx, &k,
                         "missing key (expected R, a number in [0, 1] or a table "
                         "[[frequency_thz, R], ...], or a \"file\" with a reflectivity column)");
    }
    if (m->attenuation_per_m.n == 0 && !spectrum_set_constant(&m->attenuation_per_m, 0.0))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    size_t transmission = 0;
    st = load_choice(ctx, c, "transmission", transmissions, false, 0, &transmission);
    if (st != THZ_OK)
        return st;
    m->transmission = transmission == 1 ? TRANSMISSION_STRAIGHT : TRANSMISSION_DIFFUSE;
    for (int k = 0; k < 3; k++)
        m->color[k] = 0.6;
    st = load_vector(ctx, c, "color", 3, LOAD_UNIT, false, m->color);
    if (st != THZ_OK)
        return st;
    return load_check_energy(ctx, c, m);
}

static thz_status load_materials(load_ctx *ctx, const load_cursor *root)
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

/* ---- objects -------------------------------------------------------------------- */

static thz_status load_segments(load_ctx *ctx, const load_cursor *c, unsigned *out)
{
    uint64_t v;
    thz_status st = load_integer(ctx, c, "segments", PRIMITIVE_MIN_SEGMENTS, PRIMITIVE_MAX_SEGMENTS,
                                 false, 64, &v);
    *out = (unsigned)v;
    return st;
}

static thz_status load_shape(load_ctx *ctx, const load_cursor *c, thz_mesh *mesh)
{
    static const char *const types[] = {"box",  "cylinder", "sphere", "rectangle",
                                        "disk", "mesh",     NULL};
    static const char *const keys[][6] = {
        {"type", "size_m", "inward", NULL},
        {"type", "radius_m", "height_m", "caps", "segments", NULL},
        {"type", "radius_m", "subdivisions", NULL},
        {"type", "size_m", NULL},
        {"type", "radius_m", "segments", NULL},
        {"type", "file", NULL},
    };
    if (!c->value)
        return load_fail(ctx, c,
                         "missing key (expected a shape such as {\"type\": \"box\", \"size_m\": "
                         "[1, 1, 1]})");
    if (!json_is_object(c->value))
        return load_fail(ctx, c, "expected a shape object {\"type\": ...}, got %s",
                         load_type_name(c->value));
    size_t type;
    thz_status st = load_choice(ctx, c, "type", types, true, 0, &type);
    if (st == THZ_OK)
        st = load_expect_object(ctx, c, keys[type]);
    if (st != THZ_OK)
        return st;
    thz_error *err = ctx->err;
    switch (type) {
    case 0: {
        double size[3];
        bool inward;
        st = load_vector(ctx, c, "size_m", 3, LOAD_POSITIVE, true, size);
        if (st == THZ_OK)
            st = load_bool(ctx, c, "inward", false, &inward);
        if (st == THZ_OK)
            st = primitive_box(mesh, size, inward, err);
        break;
    }
    case 1: {
        double r, h;
        bool caps;
        unsigned segments;
        st = load_number(ctx, c, "radius_m", LOAD_POSITIVE, true, 0, &r);
        if (st == THZ_OK)
            st = load_number(ctx, c, "height_m", LOAD_POSITIVE, true, 0, &h);
        if (st == THZ_OK)
            st = load_bool(ctx, c, "caps", true, &caps);
        if (st == THZ_OK)
            st = load_segments(ctx, c, &segments);
        if (st == THZ_OK)
            st = primitive_cylinder(mesh, r, h, caps, segments, err);
        break;
    }
    case 2: {
        double r;
        uint64_t sub;
        st = load_number(ctx, c, "radius_m", LOAD_POSITIVE, true, 0, &r);
        if (st == THZ_OK)
            st =
                load_integer(ctx, c, "subdivisions", 0, PRIMITIVE_MAX_SUBDIVISIONS, false, 4, &sub);
        if (st == THZ_OK)
            st = primitive_sphere(mesh, r, (unsigned)sub, err);
        break;
    }
    case 3: {
        double size[2];
        st = load_vector(ctx, c, "size_m", 2, LOAD_POSITIVE, true, size);
        if (st == THZ_OK)
            st = primitive_rectangle(mesh, size, err);
        break;
    }
    case 4: {
        double r;
        unsigned segments;
        st = load_number(ctx, c, "radius_m", LOAD_POSITIVE, true, 0, &r);
        if (st == THZ_OK)
            st = load_segments(ctx, c, &segments);
        if (st == THZ_OK)
            st = primitive_disk(mesh, r, segments, err);
        break;
    }
    case 5: {
        const char *file;
        st = load_string(ctx, c, "file", true, NULL, &file);
        if (st != THZ_OK)
            break;
        load_cursor k = load_key(c, "file");
        if (!file[0]) {
            st = load_fail(ctx, &k, "expected a mesh file name, got an empty string");
            break;
        }
        char *path = load_resolve_path(ctx, file);
        if (!path) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            break;
        }
        thz_error inner = {0};
        st = mesh_import(path, path, mesh, &inner);
        free(path);
        if (st == THZ_ERR_INPUT)
            st = load_fail(ctx, &k, "%s", inner.message);
        else if (st != THZ_OK)
            st = thz_error_set(err, st, "%s", inner.message);
        break;
    }
    }
    return st;
}

static thz_status load_transform(load_ctx *ctx, const load_cursor *c, thz_mesh *mesh)
{
    static const char *const keys[] = {"scale", "rotate_deg", "translate_m", NULL};
    if (!c->value)
        return THZ_OK;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st != THZ_OK)
        return st;
    double scale[3] = {1, 1, 1}, rot[3] = {0, 0, 0}, tr[3] = {0, 0, 0};
    load_cursor k = load_key(c, "scale");
    if (json_is_number(k.value)) {
        st = load_number(ctx, c, "scale", LOAD_ANY, true, 1, &scale[0]);
        scale[1] = scale[2] = scale[0];
    } else if (k.value && !json_is_array(k.value)) {
        return load_fail(ctx, &k, "expected a number or a list of 3 numbers, got %s",
                         load_type_name(k.value));
    } else {
        st = load_vector(ctx, c, "scale", 3, LOAD_ANY, false, scale);
    }
    if (st != THZ_OK)
        return st;
    for (int i = 0; i < 3; i++)
        if (scale[i] == 0.0)
            return load_fail(ctx, &k,
                             "a scale factor of 0 flattens the object (expected non-zero factors)");
    st = load_vector(ctx, c, "rotate_deg", 3, LOAD_ANY, false, rot);
    if (st == THZ_OK)
        st = load_vector(ctx, c, "translate_m", 3, LOAD_ANY, false, tr);
    if (st != THZ_OK)
        return st;
    scene_transform t = transform_make(scale, rot, tr);
    transform_apply_mesh(&t, mesh);
    return THZ_OK;
}

static thz_status load_object(load_ctx *ctx, const load_cursor *list, size_t index, thz_object *o)
{
    static const char *const keys[] = {"name",          "type",        "material",
                                       "temperature_k", "thickness_m", "two_sided",
                                       "shape",         "transform",   NULL};
    static const char *const types[] = {"solid", "shell", NULL};
    thz_scene *s = ctx->scene;
    load_cursor e = load_index(list, index);
    const load_cursor *c = &e;
    const char *name, *material;
    size_t type;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st == THZ_OK)
        st = load_unique_name(ctx, list, index, "object", true, &name);
    if (st != THZ_OK)
        return st;
    o->name = thz_strdup(name);
    if (!o->name)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    st = load_choice(ctx, c, "type", types, true, 0, &type);
    if (st == THZ_OK)
        st = load_string(ctx, c, "material", true, NULL, &material);
    if (st != THZ_OK)
        return st;
    o->type = type == 1 ? OBJECT_SHELL : OBJECT_SOLID;
    o->material = s->n_materials;
    for (size_t m = 0; m < s->n_materials; m++)
        if (strcmp(s->materials[m].name, material) == 0)
            o->material = m;
    if (o->material == s->n_materials) {
        load_cursor k = load_key(c, "material");
        return load_fail(ctx, &k, "unknown material \"%s\" (expected a key of \"materials\")",
                         material);
    }
    st = load_number(ctx, c, "temperature_k", LOAD_NONNEGATIVE, true, 0, &o->temperature_k);
    if (st != THZ_OK)
        return st;
    load_cursor thick = load_key(c, "thickness_m");
    if (o->type == OBJECT_SHELL) {
        if (!thick.value)
            return load_fail(ctx, &thick,
                             "missing key (a shell needs its thickness, a number > 0)");
        st = load_number(ctx, c, "thickness_m", LOAD_POSITIVE, true, 0, &o->thickness_m);
    } else if (thick.value) {
        return load_fail(ctx, &thick, "only shells have a thickness (this object is a solid)");
    }
    if (st == THZ_OK)
        st = load_bool(ctx, c, "two_sided", false, &o->two_sided);
    if (st != THZ_OK)
        return st;
    load_cursor shape = load_key(c, "shape");
    st = load_shape(ctx, &shape, &o->mesh);
    if (st != THZ_OK)
        return st;
    load_cursor transform = load_key(c, "transform");
    st = load_transform(ctx, &transform, &o->mesh);
    if (st != THZ_OK)
        return st;
    if (!mesh_finalize(&o->mesh))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    for (int k = 0; k < 3; k++)
        if (!isfinite(o->mesh.bbox_min_m[k]) || !isfinite(o->mesh.bbox_max_m[k]) ||
            !isfinite(o->mesh.total_area_m2))
            return load_fail(
                ctx, transform.value ? &transform : &shape,
                "the object's coordinates or area exceed the range of single-precision "
                "floats (expected sizes in metres well below 1e30)");
    if (o->mesh.n_triangles == 0 || !(o->mesh.total_area_m2 > 0.0))
        return load_fail(ctx, &shape, "the shape has no triangles of non-zero area");
    return THZ_OK;
}

/* The required, non-empty list `key` of the root (objects, sensors): its cursor and
 * length, or a failure naming what was expected. */
static thz_status load_list(load_ctx *ctx, const load_cursor *root, const char *key,
                            const char *what, load_cursor *list, size_t *n)
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

/* Items are counted as they load (n_objects = i + 1) so that a failure frees them. */
static thz_status load_objects(load_ctx *ctx, const load_cursor *root)
{
    thz_scene *s = ctx->scene;
    load_cursor c;
    size_t n;
    thz_status st = load_list(ctx, root, "objects", "object", &c, &n);
    if (st != THZ_OK)
        return st;
    s->objects = thz_calloc(n, sizeof *s->objects);
    if (!s->objects)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n && st == THZ_OK; i++) {
        s->n_objects = i + 1;
        st = load_object(ctx, &c, i, &s->objects[i]);
    }
    return st;
}

/* ---- sensors -------------------------------------------------------------------- */

static thz_status load_resolution(load_ctx *ctx, const load_cursor *c, uint32_t *columns,
                                  uint32_t *rows)
{
    load_cursor k = load_key(c, "resolution");
    const char *what = "[columns, rows], whole numbers from 1 to 65536";
    if (!k.value)
        return load_fail(ctx, &k, "missing key (expected %s)", what);
    if (!json_is_array(k.value) || json_array_size(k.value) != 2)
        return load_fail(ctx, &k, "expected %s, got %s", what, load_type_name(k.value));
    uint32_t v[2];
    for (size_t i = 0; i < 2; i++) {
        load_cursor e = load_index(&k, i);
        double x = json_is_number(e.value) ? json_number_value(e.value) : NAN;
        if (!json_is_number(e.value) || x != floor(x) || x < 1 || x > LOAD_MAX_RESOLUTION)
            return load_fail(ctx, &k, "expected %s, got %s%s", what,
                             json_is_number(e.value) ? "" : load_type_name(e.value),
                             json_is_number(e.value)
                                 ? (x < 1                     ? "a value below 1"
                                    : x > LOAD_MAX_RESOLUTION ? "a value above 65536"
                                                              : "a fraction")
                                 : "");
        v[i] = (uint32_t)x;
    }
    *columns = v[0];
    *rows = v[1];
    return THZ_OK;
}

static thz_status load_sensor(load_ctx *ctx, const load_cursor *list, size_t index, thz_sensor *sn)
{
    static const char *const keys[] = {
        "name",       "position_m",  "look_at_m",    "direction",      "up", "fov_deg",
        "resolution", "aperture_m2", "oversampling", "normalize_to_k", NULL};
    thz_scene *s = ctx->scene;
    load_cursor e = load_index(list, index);
    const load_cursor *c = &e;
    const char *name;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st == THZ_OK)
        st = load_unique_name(ctx, list, index, "sensor", true, &name);
    if (st != THZ_OK)
        return st;
    sn->name = thz_strdup(name);
    if (!sn->name)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    st = load_vector(ctx, c, "position_m", 3, LOAD_ANY, true, sn->position_m);
    if (st != THZ_OK)
        return st;
    load_cursor look = load_key(c, "look_at_m"), dir = load_key(c, "direction");
    double d[3];
    if (look.value && dir.value)
        return load_fail(ctx, &dir, "give either look_at_m or direction, not both");
    if (!look.value && !dir.value)
        return load_fail(ctx, c,
                         "missing key 'look_at_m' or 'direction' (expected a point to "
                         "look at or a viewing direction, 3 numbers)");
    if (look.value) {
        double p[3];
        st = load_vector(ctx, c, "look_at_m", 3, LOAD_ANY, true, p);
        for (int i = 0; i < 3; i++)
            d[i] = p[i] - sn->position_m[i];
    } else {
        st = load_vector(ctx, c, "direction", 3, LOAD_ANY, true, d);
    }
    if (st != THZ_OK)
        return st;
    vec3 dv = v3_from_array(d);
    if (!(v3_length(dv) > 0.0) || !isfinite(v3_length(dv)))
        return load_fail(ctx, look.value ? &look : &dir,
                         look.value ? "the point to look at is the sensor's position (expected "
                                      "a different point)"
                                    : "expected a non-zero direction");
    dv = v3_normalize(dv);
    double up[3] = {0, 0, 1};
    st = load_vector(ctx, c, "up", 3, LOAD_ANY, false, up);
    if (st != THZ_OK)
        return st;
    vec3 uv = v3_from_array(up);
    load_cursor up_c = load_key(c, "up");
    double ul = v3_length(uv);
    if (!(ul > 0.0) || !isfinite(ul))
        return load_fail(ctx, &up_c, "expected a non-zero up vector");
    uv = v3_scale(uv, 1.0 / ul);
    if (v3_length(v3_cross(dv, uv)) < 1e-6)
        return load_fail(ctx, &up_c,
                         "the up vector is parallel to the viewing direction "
                         "(expected a vector not parallel to it, default [0, 0, 1])");
    sn->direction[0] = dv.x, sn->direction[1] = dv.y, sn->direction[2] = dv.z;
    sn->up[0] = uv.x, sn->up[1] = uv.y, sn->up[2] = uv.z;
    const load_range fov = {0.0, 180.0, true, true};
    uint64_t over;
    st = load_number(ctx, c, "fov_deg", fov, true, 0, &sn->fov_deg);
    if (st == THZ_OK)
        st = load_resolution(ctx, c, &sn->columns, &sn->rows);
    if (st == THZ_OK)
        st = load_number(ctx, c, "aperture_m2", LOAD_POSITIVE, false, 1e-2, &sn->aperture_m2);
    if (st == THZ_OK)
        st = load_integer(ctx, c, "oversampling", 1, LOAD_MAX_OVERSAMPLING, false, 1, &over);
    if (st == THZ_OK)
        st =
            load_number(ctx, c, "normalize_to_k", LOAD_POSITIVE, false, 295.0, &sn->normalize_to_k);
    if (st != THZ_OK)
        return st;
    sn->oversampling = (uint32_t)over;
    uint64_t need = sensor_images_bytes(sn->columns, sn->rows, s->n_channels);
    uint64_t have = thz_physical_memory_bytes();
    if (have > 0 && need > have) {
        load_cursor k = load_key(c, "resolution");
        return load_fail(ctx, &k,
                         "the images of %u x %u pixels in %zu channels need %.1f GiB, more than "
                         "this machine's memory (%.1f GiB); lower 'resolution' (or the number "
                         "of channels)",
                         sn->columns, sn->rows, s->n_channels, (double)need / 1073741824.0,
                         (double)have / 1073741824.0);
    }
    return THZ_OK;
}

static thz_status load_sensors(load_ctx *ctx, const load_cursor *root)
{
    thz_scene *s = ctx->scene;
    load_cursor c;
    size_t n;
    thz_status st = load_list(ctx, root, "sensors", "sensor", &c, &n);
    if (st != THZ_OK)
        return st;
    s->sensors = thz_calloc(n, sizeof *s->sensors);
    if (!s->sensors)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n && st == THZ_OK; i++) {
        s->n_sensors = i + 1;
        st = load_sensor(ctx, &c, i, &s->sensors[i]);
    }
    return st;
}

/* ---- photons and render --------------------------------------------------------- */

static thz_status load_photons(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"per_channel", "seed", "min_relative_power",
                                       "gather_min_photons", NULL};
    thz_photon_settings *p = &ctx->scene->photons;
    load_cursor c = load_key(root, "photons");
    if (!c.value)
        return THZ_OK;
    uint64_t k = 0;
    const load_range fraction = {0.0, 1.0, true, true};
    thz_status st = load_expect_object(ctx, &c, keys);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "per_channel", 1, (uint64_t)1 << 53, false, p->per_channel,
                          &p->per_channel);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "seed", 0, INT64_MAX, false, p->seed, &p->seed);
    if (st == THZ_OK)
        st = load_number(ctx, &c, "min_relative_power", fraction, false, p->min_relative_power,
                         &p->min_relative_power);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "gather_min_photons", 2, 1000000, false, p->gather_min_photons,
                          &k);
    if (st == THZ_OK)
        p->gather_min_photons = (uint32_t)k;
    return st;
}

static thz_status load_render(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"integrator", "gather_rays", "paths_per_sample", NULL};
    thz_render_settings *r = &ctx->scene->render;
    load_cursor c = load_key(root, "render");
    if (!c.value)
        return THZ_OK;
    size_t integrator = 0;
    uint64_t rays = 0, paths = 0;
    thz_status st = load_expect_object(ctx, &c, keys);
    if (st == THZ_OK)
        st = load_choice(ctx, &c, "integrator", scene_integrator_names, false, 0, &integrator);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "gather_rays", 1, 1000000, false, r->gather_rays, &rays);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "paths_per_sample", 1, 1000000, false, r->paths_per_sample,
                          &paths);
    if (st != THZ_OK)
        return st;
    r->integrator = (thz_integrator)integrator; /* scene_integrator_names' index */
    r->gather_rays = (uint32_t)rays;
    r->paths_per_sample = (uint32_t)paths;
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

/* Warns about channel bands (centre +- 2 FWHM) that leave table `sp`. */
static bool load_warn_table(thz_scene *s, const thz_spectrum *sp, const char *what)
{
    if (!sp->freq_hz || sp->n < 2)
        return true;
    size_t first = s->n_channels, count = 0;
    for (size_t c = 0; c < s->n_channels; c++) {
        const thz_channel *ch = &s->channels[c];
        double fwhm = ch->relative_width * ch->center_hz;
        if (spectrum_table_exceeded(sp, ch->center_hz - 2 * fwhm, ch->center_hz + 2 * fwhm)) {
            if (first == s->n_channels)
                first = c;
            count++;
        }
    }
    if (count == 0)
        return true;
    const thz_channel *ch = &s->channels[first];
    double fwhm = ch->relative_width * ch->center_hz;
    return scene_add_warning(
        s,
        "%s: the table covers %.4g to %.4g THz but channel \"%s\" (band %.4g to %.4g THz, "
        "centre +- 2 FWHM)%s reaches beyond it; the end values are used there",
        what, sp->freq_hz[0] * 1e-12, sp->freq_hz[sp->n - 1] * 1e-12, ch->name,
        (ch->center_hz - 2 * fwhm) * 1e-12, (ch->center_hz + 2 * fwhm) * 1e-12,
        count > 1 ? " and others" : "");
}

/* Whether object i of the document (validated) is a mesh file: built-in shapes are
 * wound consistently by construction (primitives.h), so only files need the check. */
static bool load_is_mesh_file(const load_cursor *root, size_t i)
{
    json_t *object = json_array_get(json_object_get(root->value, "objects"), i);
    const char *type = json_string_value(json_object_get(json_object_get(object, "shape"), "type"));
    return type && strcmp(type, "mesh") == 0;
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
        size_t conflicts = mesh_import_winding_conflicts(&obj->mesh);
        if (conflicts == SIZE_MAX)
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        if (ok && conflicts > 0)
            ok = scene_add_warning(s,
                                   "object \"%s\": inconsistent winding: %zu edge(s) used twice "
                                   "in the same direction, so some normals point the wrong way",
                                   obj->name, conflicts);
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
        return load_require(ctx, &root, "format", "\"" LOAD_FORMAT "\"");
    thz_status st = load_string(ctx, &root, "format", true, NULL, &format);
    if (st == THZ_OK && strcmp(format, LOAD_FORMAT) != 0) {
        load_cursor k = load_key(&root, "format");
        return load_fail(ctx, &k, "expected \"%s\", got \"%s\"", LOAD_FORMAT, format);
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
    st = atmosphere_prepare(&s->atmosphere, s->channels, s->n_channels, ctx->err);
    if (st != THZ_OK) {
        thz_error_prefix(ctx->err, "%s: atmosphere: ", ctx->label);
        return st;
    }
    return load_warnings(ctx, &root);
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

static thz_status load_finish(thz_scene **scene, json_t *doc, thz_status st, thz_error *err)
{
    if (st == THZ_OK) {
        load_ctx ctx = {.label = (*scene)->path, .dir = (*scene)->dir, .scene = *scene, .err = err};
        st = load_document(&ctx, doc);
    }
    json_decref(doc);
    if (st != THZ_OK) {
        scene_destroy(*scene);
        *scene = NULL;
    }
    return st;
}

static thz_status load_syntax_error(const char *label, const json_error_t *je, thz_error *err)
{
    if (je->line > 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s:%d:%d: invalid JSON: %s", label, je->line,
                             je->column, je->text);
    return thz_error_set(err, THZ_ERR_INPUT, "%s: invalid JSON: %s", label, je->text);
}

thz_status scene_load(const char *path, thz_scene **out, thz_error *err)
{
    *out = NULL;
    thz_error_clear(err);
    struct stat info;
    if (stat(path, &info) == 0 && S_ISDIR(info.st_mode))
        return thz_error_set(err, THZ_ERR_INPUT, "%s: is a directory, expected a scene file", path);
    FILE *f = fopen(path, "rb");
    if (!f)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open scene file: %s", path,
                             strerror(errno));
    fclose(f);
    json_error_t je;
    json_t *doc = json_load_file(path, JSON_REJECT_DUPLICATES, &je);
    if (!doc)
        return load_syntax_error(path, &je, err);
    char *copy = thz_strdup(path);
    if (!copy) {
        json_decref(doc);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    }
    thz_status st = load_begin(path, dirname(copy), out, err);
    free(copy);
    return load_finish(out, doc, st, err);
}

thz_status scene_load_string(const char *json_text, const char *base_dir, const char *label,
                             thz_scene **out, thz_error *err)
{
    *out = NULL;
    thz_error_clear(err);
    if (!label)
        label = "<scene>";
    json_error_t je;
    json_t *doc = json_loads(json_text, JSON_REJECT_DUPLICATES, &je);
    if (!doc)
        return load_syntax_error(label, &je, err);
    thz_status st = load_begin(label, base_dir ? base_dir : ".", out, err);
    return load_finish(out, doc, st, err);
}

thz_status thz_scene_load(const char *path, thz_scene **out, thz_error *err)
{
    return scene_load(path, out, err);
}
