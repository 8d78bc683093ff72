/* POST /api/validate (a scene's text checked by the library, and what the page draws
 * of it) and GET /api/materials[/NAME] (the material library). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "serve_internal.h"

#define SERVE_SPECTRUM_POINTS 200

static json_t *serve_vec3(const double v[3])
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

/* One error of the loader, split into JSON path or line and column, and message. The
 * loader writes "LABEL: PATH: message" or "LABEL:LINE:COLUMN: message". */
static json_t *serve_scene_error(const char *label, const char *message)
{
    size_t n = strlen(label);
    const char *m = message;
    if (strncmp(m, label, n) == 0 && m[n] == ':')
        m += n + 1 + (m[n + 1] == ' ');
    json_t *o = json_pack("{s:n, s:n, s:n}", "json_path", "line", "column");
    int line = 0, column = 0, used = 0;
    if (sscanf(m, "%d:%d: %n", &line, &column, &used) == 2 && used > 0) {
        json_object_set_new(o, "line", json_integer(line));
        json_object_set_new(o, "column", json_integer(column));
        m += used;
    } else {
        const char *colon = strstr(m, ": ");
        if (colon && colon > m && !memchr(m, ' ', (size_t)(colon - m))) {
            json_object_set_new(o, "json_path", json_stringn(m, (size_t)(colon - m)));
            m = colon + 2;
        }
    }
    json_object_set_new(o, "message", json_string(m));
    return o;
}

/* The frequencies spectra are drawn at: the channels +- 20 %, at least 0.1-1.5 THz. */
static void serve_spectrum_range(const thz_scene *scene, double *lo_thz, double *hi_thz)
{
    *lo_thz = 0.1;
    *hi_thz = 1.5;
    for (size_t c = 0; c < thz_scene_channel_count(scene); c++) {
        thz_channel_info ch;
        thz_scene_channel(scene, c, &ch);
        *lo_thz = fmin(*lo_thz, 0.8 * ch.frequency_thz);
        *hi_thz = fmax(*hi_thz, 1.2 * ch.frequency_thz);
    }
}

static json_t *serve_material_json(const thz_scene *scene, size_t i, double lo, double hi)
{
    thz_material_info m;
    thz_scene_material(scene, i, &m);
    json_t *f = json_array(), *r = json_array(), *e = json_array(), *a = json_array();
    json_t *n = m.index_model ? json_array() : json_null();
    json_t *k = m.index_model ? json_array() : json_null();
    for (int p = 0; p < SERVE_SPECTRUM_POINTS; p++) {
        double thz = lo + (hi - lo) * p / (SERVE_SPECTRUM_POINTS - 1);
        thz_surface_optics o;
        thz_scene_material_optics(scene, i, thz * 1e12, 0.0, &o);
        json_array_append_new(f, json_real(thz));
        json_array_append_new(r, json_real(o.reflectance_normal));
        json_array_append_new(e, json_real(o.emissivity_normal));
        json_array_append_new(a, json_real(o.attenuation_per_m));
        if (m.index_model) {
            json_array_append_new(n, o.has_index ? json_real(o.n) : json_null());
            json_array_append_new(k, o.has_index ? json_real(o.k) : json_null());
        }
    }
    return json_pack("{s:s, s:s?, s:s?, s:s, s:[f,f,f], s:{s:o, s:o, s:o, s:o, s:o, s:o}}", "name",
                     m.name, "index_model", m.index_model, "reflection", m.reflection,
                     "transmission", m.transmission, "color", m.color[0], m.color[1], m.color[2],
                     "spectra", "freq_thz", f, "R", r, "emissivity", e, "alpha_per_m", a, "n", n,
                     "k", k);
}

/* Object i, with its mesh while *budget (triangles) holds it, else "mesh": null: a JSON
 * number is about 100 bytes of jansson's tree, and a 1.7 KB body of one cylinder of the
 * scene format's 1 000 000 segments took the server to 1 GB and a 170 MB answer. */
static json_t *serve_object_json(const thz_scene *scene, size_t i, size_t *budget)
{
    thz_object_info o;
    thz_object_mesh mesh;
    thz_scene_object(scene, i, &o);
    thz_scene_object_mesh(scene, i, &mesh);
    json_t *m = json_null();
    if (mesh.n_triangles <= *budget) {
        *budget -= mesh.n_triangles;
        json_t *pos = json_array(), *idx = json_array();
        for (size_t v = 0; v < 3 * mesh.n_vertices; v++)
            json_array_append_new(pos, json_real(mesh.positions[v]));
        for (size_t t = 0; t < 3 * mesh.n_triangles; t++)
            json_array_append_new(idx, json_integer(mesh.indices[t]));
        m = json_pack("{s:o, s:o}", "positions", pos, "indices", idx);
    }
    return json_pack("{s:s, s:s, s:f, s:s, s:f, s:b, s:I, s:f, s:o, s:o, s:o}", "name", o.name,
                     "material", o.material_name, "temperature_K", o.temperature_k, "type", o.type,
                     "thickness_m", o.thickness_m, "two_sided", o.two_sided, "triangles",
                     (json_int_t)o.triangles, "area_m2", o.area_m2, "bbox_min_m",
                     serve_vec3(o.bbox_min_m), "bbox_max_m", serve_vec3(o.bbox_max_m), "mesh", m);
}

/* The distance from a sensor to the centre of the box around the objects it looks at
 * (every object whose box does not hold the sensor, i.e. no enclosure), m; 0 if none. */
static double serve_sensor_distance_m(const thz_scene *scene, const thz_sensor_info *sn)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool any = false;
    for (size_t i = 0; i < thz_scene_object_count(scene); i++) {
        thz_object_info o;
        thz_scene_object(scene, i, &o);
        bool inside = true;
        for (int a = 0; a < 3; a++)
            inside = inside && sn->position_m[a] >= o.bbox_min_m[a] &&
                     sn->position_m[a] <= o.bbox_max_m[a];
        if (inside)
            continue;
        any = true;
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], o.bbox_min_m[a]);
            hi[a] = fmax(hi[a], o.bbox_max_m[a]);
        }
    }
    double d2 = 0.0;
    for (int a = 0; any && a < 3; a++) {
        double d = 0.5 * (lo[a] + hi[a]) - sn->position_m[a];
        d2 += d * d;
    }
    return sqrt(d2);
}

static json_t *serve_scene_json(const thz_scene *scene)
{
    thz_scene_info info;
    thz_scene_get_info(scene, &info);
    thz_atm *atm = NULL;
    thz_atm_from_scene(scene, &atm, NULL);
    json_t *channels = json_array(), *atm_channels = json_array();
    size_t nc = thz_scene_channel_count(scene);
    double *alpha = calloc(nc ? nc : 1, sizeof *alpha);
    for (size_t c = 0; c < nc; c++) {
        thz_channel_info ch;
        thz_scene_channel(scene, c, &ch);
        json_array_append_new(channels,
                              json_pack("{s:s, s:f, s:f, s:f}", "name", ch.name, "centre_thz",
                                        ch.frequency_thz, "width_thz", ch.fwhm_hz * 1e-12,
                                        "relative_width", ch.relative_width));
        double a = atm && alpha ? thz_atm_attenuation_per_m(atm, ch.frequency_hz) : 0.0;
        if (alpha)
            alpha[c] = a;
        json_array_append_new(atm_channels, json_pack("{s:f, s:f}", "centre_thz", ch.frequency_thz,
                                                      "alpha_per_m", a));
    }
    double lo, hi;
    serve_spectrum_range(scene, &lo, &hi);
    json_t *materials = json_array(), *objects = json_array(), *sensors = json_array();
    json_t *atm_sensors = json_array();
    for (size_t i = 0; i < info.n_materials; i++)
        json_array_append_new(materials, serve_material_json(scene, i, lo, hi));
    size_t budget = SERVE_PREVIEW_TRIANGLES;
    for (size_t i = 0; i < info.n_objects; i++)
        json_array_append_new(objects, serve_object_json(scene, i, &budget));
    for (size_t i = 0; i < info.n_sensors; i++) {
        thz_sensor_info sn;
        thz_scene_sensor(scene, i, &sn);
        json_array_append_new(
            sensors, json_pack("{s:s, s:o, s:o, s:o, s:f, s:i, s:i, s:i, s:f, s:f}", "name",
                               sn.name, "position_m", serve_vec3(sn.position_m), "direction",
                               serve_vec3(sn.direction), "up", serve_vec3(sn.up), "fov_deg",
                               sn.fov_deg, "rows", (int)sn.rows, "columns", (int)sn.columns,
                               "oversampling", (int)sn.oversampling, "aperture_m2", sn.aperture_m2,
                               "normalize_to_k", sn.normalize_to_k));
        double d = serve_sensor_distance_m(scene, &sn);
        json_t *t = json_array();
        for (size_t c = 0; c < nc; c++)
            json_array_append_new(t, json_real(exp(-(alpha ? alpha[c] : 0.0) * d)));
        json_array_append_new(atm_sensors, json_pack("{s:s, s:f, s:o}", "name", sn.name,
                                                     "distance_m", d, "transmittance", t));
    }
    free(alpha);
    /* what the air emits at, K (null: it does not emit), and the background's: both
     * default to the enclosure's around the sensors */
    thz_atm_info ai = {0};
    thz_atm_get_info(atm, &ai);
    thz_atm_destroy(atm);
    json_t *emit_k = ai.emitting ? json_real(ai.emission_temperature_k) : json_null();
    json_t *background_k = ai.emitting ? json_real(ai.background_temperature_k) : json_null();
    return json_pack("{s:s, s:o, s:o, s:o, s:o, s:{s:s, s:o, s:o, s:o, s:o}, s:{s:s, s:I, s:I}}",
                     "name", info.name, "channels", channels, "materials", materials, "objects",
                     objects, "sensors", sensors, "atmosphere", "model", info.atmosphere_model,
                     "channels", atm_channels, "sensors", atm_sensors, "emission_temperature_k",
                     emit_k, "background_temperature_k", background_k, "settings", "integrator",
                     info.integrator, "photons_per_channel", (json_int_t)info.photons_per_channel,
                     "seed", (json_int_t)info.seed);
}

enum MHD_Result serve_validate(serve_request *r)
{
    enum MHD_Result ret = MHD_NO;
    static const char *const keys[] = {"path", "text", NULL};
    json_t *body = serve_body_object(r, keys, &ret);
    if (!body)
        return ret;
    json_t *jpath = json_object_get(body, "path"), *jtext = json_object_get(body, "text");
    if (!json_is_string(jtext)) {
        json_decref(body);
        return serve_reply_bad_json(r, "$.text", "expected the scene's JSON text as a string");
    }
    if (jpath && !json_is_null(jpath) && !json_is_string(jpath)) {
        json_decref(body);
        return serve_reply_bad_json(r, "$.path", "expected a path relative to the root, or null");
    }
    char base[PATH_MAX] = ".";
    const char *label = "<editor>";
    if (json_is_string(jpath)) {
        label = json_string_value(jpath);
        serve_path_status st = serve_path(r->s, label, false, base);
        if (st != SERVE_PATH_OK) {
            /* label points into body: the reply is made before body is freed */
            enum MHD_Result res = serve_reply_path(r, st, "$.path", ": ", label);
            json_decref(body);
            return res;
        }
        char *slash = strrchr(base, '/');
        if (slash)
            *slash = '\0';
        else
            strcpy(base, ".");
    }
    thz_scene *scene = NULL;
    thz_error err = {0};
    thz_status st = thz_scene_load_string_within(json_string_value(jtext), base, label, r->s->root,
                                                 &scene, &err);
    json_t *errors = json_array(), *warnings = json_array();
    if (st != THZ_OK)
        json_array_append_new(errors, serve_scene_error(label, err.message));
    for (size_t i = 0; scene && i < thz_scene_warning_count(scene); i++)
        json_array_append_new(warnings, json_string(thz_scene_warning(scene, i)));
    json_t *out =
        json_pack("{s:b, s:o, s:o, s:o}", "ok", st == THZ_OK, "errors", errors, "warnings",
                  warnings, "scene", scene ? serve_scene_json(scene) : json_null());
    thz_scene_destroy(scene);
    json_decref(body);
    return serve_reply_json(r, 200, out);
}

static json_t *serve_range(int has, double a, double b)
{
    return has ? json_pack("[f,f]", a, b) : json_null();
}

static json_t *serve_library_entry(const thz_library *lib, size_t i, bool spectra)
{
    thz_library_material_info m;
    thz_library_get_info(lib, i, &m);
    json_t *o = json_pack(
        "{s:s, s:s, s:s, s:s, s:s, s:s, s:o, s:o}", "name", m.name, "description", m.description,
        "basis", m.basis, "source", m.source, "note", m.note, "model", m.model, "valid_thz",
        serve_range(m.has_valid_range, m.valid_from_thz, m.valid_to_thz), "data_thz",
        serve_range(m.has_data_range, m.data_from_thz, m.data_to_thz));
    if (!spectra || !o)
        return o;
    double lo = 0.1, hi = 3.0;
    if (m.has_data_range) {
        lo = m.data_from_thz;
        hi = m.data_to_thz;
    } else if (m.has_valid_range) {
        lo = m.valid_from_thz;
        hi = m.valid_to_thz;
    }
    const char *keys[] = {"freq_thz", "n", "k", "eps_real", "eps_imag", "alpha_per_m", "R"};
    json_t *arrays[7];
    for (int a = 0; a < 7; a++)
        arrays[a] = json_array();
    for (int p = 0; p < SERVE_SPECTRUM_POINTS; p++) {
        double thz = lo + (hi - lo) * p / (SERVE_SPECTRUM_POINTS - 1);
        bool in = thz > 0.0 && thz_library_in_range(lib, i, thz * 1e12);
        thz_library_optics x = {0};
        if (in)
            thz_library_optics_at(lib, i, thz * 1e12, &x);
        double v[7] = {
            thz, x.n, x.k, x.eps_real, x.eps_imag, x.attenuation_per_m, x.normal_reflectance};
        for (int a = 0; a < 7; a++)
            json_array_append_new(arrays[a], a == 0 || in ? json_real(v[a]) : json_null());
    }
    json_t *sp = json_object();
    for (int a = 0; a < 7; a++)
        json_object_set_new(sp, keys[a], arrays[a]);
    json_object_set_new(o, "spectra", sp);
    return o;
}

enum MHD_Result serve_materials(serve_request *r)
{
    const char *name = r->url + strlen("/api/materials");
    if (*name == '/')
        name++;
    thz_library *lib = NULL;
    thz_error err = {0};
    if (thz_library_load(&lib, &err) != THZ_OK)
        return serve_reply_error(r, 500, "%s", err.message);
    json_t *out = NULL;
    if (!*name) {
        json_t *list = json_array();
        for (size_t i = 0; i < thz_library_count(lib); i++)
            json_array_append_new(list, serve_library_entry(lib, i, false));
        out = json_pack("{s:o}", "materials", list);
    } else {
        size_t i = 0;
        if (thz_library_find(lib, name, &i, &err) != THZ_OK) {
            /* the library's message begins with its file's absolute path, which a client
             * of the server has no business knowing: name the known entries here */
            char known[2048] = "";
            size_t used = 0;
            for (size_t k = 0; k < thz_library_count(lib) && used < sizeof known; k++) {
                thz_library_material_info m;
                thz_library_get_info(lib, k, &m);
                int n = snprintf(known + used, sizeof known - used, "%s%s", k ? ", " : "", m.name);
                used = n < 0 ? sizeof known : used + (size_t)n;
            }
            thz_library_destroy(lib);
            return serve_reply_error(
                r, 404, "no material \"%s\" in the material library (known: %s)", name, known);
        }
        out = serve_library_entry(lib, i, true);
    }
    thz_library_destroy(lib);
    return serve_reply_json(r, 200, out);
}
