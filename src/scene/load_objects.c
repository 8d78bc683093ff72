/* The scene's `objects` block: each object's material, temperature and kind, its shape
 * (a built-in primitive or a mesh file) and its transform into world space. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "scene/load.h"
#include "scene/material_library.h"
#include "scene/mesh_import.h"
#include "scene/primitives.h"
#include "scene/transform.h"

static thz_status load_segments(load_ctx *ctx, const load_cursor *c, unsigned *out)
{
    uint64_t v;
    thz_status st = load_integer(ctx, c, "segments", PRIMITIVE_MIN_SEGMENTS, PRIMITIVE_MAX_SEGMENTS,
                                 false, 64, &v);
    *out = (unsigned)v;
    return st;
}

/* A mesh file as imported, before any object's transform. */
struct load_mesh_copy {
    const char *file; /* as the scene writes it (the document's string) */
    thz_mesh mesh;
};

/* dst (empty) as a copy of src's vertices and triangles; false when out of memory. */
static bool load_mesh_duplicate(thz_mesh *dst, const thz_mesh *src, thz_error *err)
{
    if (primitive_mesh_alloc(dst, src->n_vertices, src->n_triangles, err) != THZ_OK)
        return false;
    memcpy(dst->positions, src->positions, 3 * src->n_vertices * sizeof *src->positions);
    memcpy(dst->indices, src->indices, 3 * src->n_triangles * sizeof *src->indices);
    dst->n_vertices = src->n_vertices;
    dst->n_triangles = src->n_triangles;
    return true;
}

/* The mesh file `file` into mesh: imported, or copied from its earlier import when more
 * than one object names it (kept for the later ones). */
static thz_status load_mesh_file(load_ctx *ctx, const load_cursor *k, const char *file,
                                 thz_mesh *mesh)
{
    for (size_t i = 0; i < ctx->n_mesh_copies; i++)
        if (strcmp(ctx->mesh_copies[i].file, file) == 0)
            return load_mesh_duplicate(mesh, &ctx->mesh_copies[i].mesh, ctx->err)
                       ? THZ_OK
                       : thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    char *path = NULL, *label = NULL;
    thz_status st = load_file_path(ctx, k, file, &path, &label);
    if (st != THZ_OK)
        return st;
    thz_error inner = {0};
    st = mesh_import(path, label, mesh, &inner);
    free(path);
    free(label);
    if (st == THZ_ERR_INPUT)
        return load_fail(ctx, k, "%s", inner.message);
    if (st != THZ_OK) /* out of memory, a failed child: the scene and the key too */
        return thz_error_set(ctx->err, st, "%s: %s: %s", ctx->label, k->path, inner.message);
    json_t *uses = json_object_get(ctx->mesh_uses, file);
    if (json_integer_value(uses) < 2)
        return THZ_OK;
    struct load_mesh_copy *more =
        realloc(ctx->mesh_copies, (ctx->n_mesh_copies + 1) * sizeof *ctx->mesh_copies);
    if (!more)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    ctx->mesh_copies = more;
    struct load_mesh_copy *c = &more[ctx->n_mesh_copies];
    *c = (struct load_mesh_copy){.file = file};
    if (!load_mesh_duplicate(&c->mesh, mesh, ctx->err))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    ctx->n_mesh_copies++;
    return THZ_OK;
}

/* Counts the objects naming each mesh file (ctx->mesh_uses). */
static thz_status load_count_mesh_uses(load_ctx *ctx, const load_cursor *list, size_t n)
{
    ctx->mesh_uses = json_object();
    if (!ctx->mesh_uses)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < n; i++) {
        json_t *shape = json_object_get(json_array_get(list->value, i), "shape");
        const char *type = json_string_value(json_object_get(shape, "type"));
        const char *file = json_string_value(json_object_get(shape, "file"));
        if (!type || strcmp(type, "mesh") != 0 || !file || !file[0])
            continue;
        json_int_t uses = json_integer_value(json_object_get(ctx->mesh_uses, file));
        if (json_object_set_new(ctx->mesh_uses, file, json_integer(uses + 1)) != 0)
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    }
    return THZ_OK;
}

static void load_mesh_copies_free(load_ctx *ctx)
{
    for (size_t i = 0; i < ctx->n_mesh_copies; i++)
        mesh_fini(&ctx->mesh_copies[i].mesh);
    free(ctx->mesh_copies);
    ctx->mesh_copies = NULL;
    ctx->n_mesh_copies = 0;
    json_decref(ctx->mesh_uses);
    ctx->mesh_uses = NULL;
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
        st = load_mesh_file(ctx, &k, file, mesh);
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

/* An object's material the scene does not define: the scene's names, and the library's
 * entry of that name when there is one (a library material must be defined in "materials"). */
static thz_status unknown_material(load_ctx *ctx, const load_cursor *c, const thz_scene *s,
                                   const char *material)
{
    char names[400] = "";
    size_t used = 0;
    for (size_t m = 0; m < s->n_materials && used < sizeof names - 1; m++) {
        int n = snprintf(names + used, sizeof names - used, "%s%s", m ? ", " : "",
                         s->materials[m].name);
        used = n < 0 ? used : used + (size_t)n;
    }
    if (used >= sizeof names - 1)
        memcpy(names + sizeof names - 5, "...", 4);
    material_library *lib = NULL;
    thz_error ignored = {0};
    bool in_library = material_library_load(&lib, &ignored) == THZ_OK &&
                      material_library_find(lib, material) != NULL;
    material_library_destroy(lib);
    load_cursor k = load_key(c, "material");
    if (in_library)
        return load_fail(ctx, &k,
                         "unknown material \"%s\" (the scene's materials: %s); the material "
                         "library has one of that name: define it in \"materials\" as "
                         "\"%s\": {\"library\": \"%s\"}",
                         material, names, material, material);
    return load_fail(ctx, &k, "unknown material \"%s\" (the scene's materials: %s)", material,
                     names);
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
    if (o->material == s->n_materials)
        return unknown_material(ctx, c, s, material);
    st = load_number(ctx, c, "temperature_k", LOAD_TEMPERATURE, true, 0, &o->temperature_k);
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
    for (int k = 0; k < 3; k++)
        if (fmax(-o->mesh.bbox_min_m[k], o->mesh.bbox_max_m[k]) > LOAD_MAX_COORDINATE_M)
            return load_fail(ctx, transform.value ? &transform : &shape,
                             "the object reaches %g m from the origin; scenes must lie within "
                             "%g m of it (expected metres: a mesh in millimetres needs "
                             "\"transform\": {\"scale\": 0.001})",
                             fmax(-o->mesh.bbox_min_m[k], o->mesh.bbox_max_m[k]),
                             LOAD_MAX_COORDINATE_M);
    if (o->mesh.n_triangles == 0 || !(o->mesh.total_area_m2 > 0.0))
        return load_fail(ctx, &shape, "the shape has no triangles of non-zero area");
    return THZ_OK;
}

/* Items are counted as they load (n_objects = i + 1) so that a failure frees them. */
thz_status load_objects(load_ctx *ctx, const load_cursor *root)
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
    st = load_count_mesh_uses(ctx, &c, n);
    for (size_t i = 0; i < n && st == THZ_OK; i++) {
        s->n_objects = i + 1;
        st = load_object(ctx, &c, i, &s->objects[i]);
    }
    load_mesh_copies_free(ctx);
    return st;
}
