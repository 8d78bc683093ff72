/* The material library (material_library.h) and a scene's `library` key. */
#include "scene/material_library.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/data_dir.h"
#include "core/path.h"
#include "scene/load.h"

static thz_status entry_string(load_ctx *ctx, const load_cursor *c, const char *key, bool required,
                               char **out)
{
    const char *s = NULL;
    thz_status st = load_string(ctx, c, key, required, "", &s);
    if (st == THZ_OK && required && !*s) {
        load_cursor k = load_key(c, key);
        return load_fail(ctx, &k, "expected a non-empty string");
    }
    if (st == THZ_OK && !(*out = thz_strdup(s)))
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    return st;
}

static thz_status load_entry(load_ctx *ctx, const load_cursor *c, material_library_entry *e)
{
    static const char *const keys[] = {
        "description",        "basis", "source", "note", "valid_thz", "color", "refractive_index",
        "permittivity_model", NULL};
    static const char *const bases[] = {"measured", "model", "fit", "assumed", NULL};
    thz_status st = load_expect_object(ctx, c, keys);
    size_t basis = 0;
    if (st == THZ_OK)
        st = entry_string(ctx, c, "description", true, &e->description);
    if (st == THZ_OK)
        st = load_choice(ctx, c, "basis", bases, true, 0, &basis);
    if (st == THZ_OK && !(e->basis = thz_strdup(bases[basis])))
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    if (st == THZ_OK)
        st = entry_string(ctx, c, "source", true, &e->source);
    if (st == THZ_OK)
        st = entry_string(ctx, c, "note", false, &e->note);
    double range[2] = {0, 0};
    e->has_range = st == THZ_OK && json_object_get(c->value, "valid_thz");
    if (st == THZ_OK)
        st = load_vector(ctx, c, "valid_thz", 2, LOAD_POSITIVE, false, range);
    if (st == THZ_OK && e->has_range && !(range[1] > range[0])) {
        load_cursor k = load_key(c, "valid_thz");
        st = load_fail(ctx, &k, "expected [from_thz, to_thz] with from < to");
    }
    e->lo_hz = range[0] * 1e12;
    e->hi_hz = range[1] * 1e12;
    e->has_color = st == THZ_OK && json_object_get(c->value, "color");
    if (st == THZ_OK)
        st = load_vector(ctx, c, "color", 3, LOAD_UNIT, false, e->color);
    thz_material m = {0};
    bool given = false;
    if (st == THZ_OK)
        st = load_material_index(ctx, c, &m, &given);
    if (st == THZ_OK && !given)
        st = load_fail(ctx, c, "missing key (expected refractive_index or permittivity_model)");
    e->index = m.index;
    return st;
}

/* A library file that does not read as one is thzmap's installation's fault, not the
 * user's input: THZ_ERR_IO (exit 1), not THZ_ERR_INPUT (exit 2). */
static thz_status material_library_broken(thz_status st, thz_error *err)
{
    if (st != THZ_ERR_INPUT)
        return st;
    if (err) {
        err->status = THZ_ERR_IO;
        thz_error_prefix(err, "thzmap's own data is damaged (reinstall thzmap, or check "
                              "THZMAP_DATA_DIR): ");
    }
    return THZ_ERR_IO;
}

thz_status material_library_load(material_library **out, thz_error *err)
{
    *out = NULL;
    char dir[THZ_PATH_MAX], path[THZ_PATH_MAX];
    thz_status st = thz_data_dir_find(NULL, dir, sizeof dir, err);
    if (st == THZ_OK)
        st = thz_data_file(NULL, MATERIAL_LIBRARY_FILE, path, sizeof path, err);
    if (st != THZ_OK)
        return st;
    json_t *doc = NULL; /* as a scene is read: no FIFO or device, line:column of syntax */
    st = load_json_file(path, NULL, NULL, "material library", LOAD_MAX_SCENE_BYTES, &doc, err);
    if (st != THZ_OK)
        return material_library_broken(st, err);
    material_library *lib = thz_calloc(1, sizeof *lib);
    load_ctx ctx = {.label = path, .dir = dir, .err = err};
    load_cursor root = load_root(doc), c = load_key(&root, "materials");
    const char *format = NULL;
    if (!lib || !(lib->path = thz_strdup(path))) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    st = load_string(&ctx, &root, "format", true, NULL, &format);
    if (st == THZ_OK && strcmp(format, "thzmap-materials/1") != 0) {
        load_cursor k = load_key(&root, "format");
        st = load_fail(&ctx, &k, "expected \"thzmap-materials/1\", got \"%s\"", format);
    }
    if (st == THZ_OK && (!json_is_object(c.value) || json_object_size(c.value) == 0))
        st = load_fail(&ctx, &c, "expected a non-empty object of materials");
    if (st != THZ_OK)
        goto done;
    lib->entries = thz_calloc(json_object_size(c.value), sizeof *lib->entries);
    if (!lib->entries) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    const char *name;
    json_t *value;
    json_object_foreach(c.value, name, value)
    {
        material_library_entry *e = &lib->entries[lib->n++];
        load_cursor ec = load_key(&c, name);
        if (!(e->name = thz_strdup(name)))
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        if (st == THZ_OK)
            st = load_entry(&ctx, &ec, e);
        if (st != THZ_OK)
            goto done;
    }
done:
    json_decref(doc);
    if (st != THZ_OK) {
        material_library_destroy(lib);
        return material_library_broken(st, err);
    }
    *out = lib;
    return THZ_OK;
}

const material_library_entry *material_library_find(const material_library *lib, const char *name)
{
    for (size_t i = 0; i < lib->n; i++)
        if (strcmp(lib->entries[i].name, name) == 0)
            return &lib->entries[i];
    return NULL;
}

void material_library_destroy(material_library *lib)
{
    if (!lib)
        return;
    for (size_t i = 0; i < lib->n; i++) {
        material_library_entry *e = &lib->entries[i];
        free(e->name);
        free(e->description);
        free(e->basis);
        free(e->source);
        free(e->note);
        material_index_destroy(e->index);
    }
    free(lib->entries);
    free(lib->path);
    free(lib);
}

thz_status load_material_library(load_ctx *ctx, const load_cursor *c, thz_material *m,
                                 double range_hz[2])
{
    range_hz[0] = range_hz[1] = 0.0;
    const char *name = NULL;
    thz_status st = load_string(ctx, c, "library", true, NULL, &name);
    if (st != THZ_OK)
        return st;
    material_library *lib = NULL;
    st = material_library_load(&lib, ctx->err);
    if (st != THZ_OK)
        return st;
    const material_library_entry *e = material_library_find(lib, name);
    if (!e) {
        char names[2048] = "";
        for (size_t i = 0; i < lib->n; i++) {
            size_t used = strlen(names);
            snprintf(names + used, sizeof names - used, "%s%s", i ? ", " : "",
                     lib->entries[i].name);
        }
        load_cursor k = load_key(c, "library");
        st = load_fail(ctx, &k,
                       "unknown library material \"%s\" (`thzmap materials` lists them: %s)", name,
                       names);
    } else {
        material_index_destroy(m->index);
        m->index = material_index_copy(e->index);
        if (!m->index)
            st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        if (e->has_color)
            memcpy(m->color, e->color, sizeof m->color);
        if (e->has_range) {
            range_hz[0] = e->lo_hz;
            range_hz[1] = e->hi_hz;
        }
    }
    material_library_destroy(lib);
    return st;
}
