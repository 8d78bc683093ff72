/* The scene texts of the band values' renders (bands_values.c renders them): the scene's
 * JSON with the candidates as its channels, the path integrator, and one nuisance
 * changed: a target's temperature, the surroundings' and the air's, the humidity, the
 * shells' thickness, or the sensor turned about its up axis (bands_values_internal.h).
 */
#include <jansson.h>
#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "analysis/bands_values_internal.h"

static const char *const humidity_keys[] = {"relative_humidity", "water_vapour_g_m3", "h2o_vmr"};

static int add_number(json_t *obj, const char *key, double delta, double factor)
{
    json_t *v = json_object_get(obj, key);
    if (!v || !json_is_number(v))
        return 0;
    json_object_set_new(obj, key, json_real(json_number_value(v) * factor + delta));
    return 1;
}

static bool get_vec3(const json_t *obj, const char *key, double v[3])
{
    const json_t *a = json_object_get(obj, key);
    if (!json_is_array(a) || json_array_size(a) != 3)
        return false;
    for (size_t i = 0; i < 3; i++) {
        const json_t *x = json_array_get(a, i);
        if (!json_is_number(x))
            return false;
        v[i] = json_number_value(x);
    }
    return true;
}

static void set_vec3(json_t *obj, const char *key, const double v[3])
{
    json_t *a = json_array();
    for (size_t i = 0; i < 3; i++)
        json_array_append_new(a, json_real(v[i]));
    json_object_set_new(obj, key, a);
}

/* v turned by `deg` about the axis `k` (any length but 0), Rodrigues' formula. */
static void rotate(double v[3], const double k_in[3], double deg)
{
    double len = sqrt(k_in[0] * k_in[0] + k_in[1] * k_in[1] + k_in[2] * k_in[2]);
    double k[3] = {k_in[0] / len, k_in[1] / len, k_in[2] / len};
    double th = deg * M_PI / 180.0, c = cos(th), sn = sin(th);
    double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    double x[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]};
    for (size_t i = 0; i < 3; i++)
        v[i] = v[i] * c + x[i] * sn + k[i] * kv * (1.0 - c);
}

/* The viewing-angle nuisance: the sensor turned by `deg` about its up axis, around its
 * look_at_m point (it keeps looking at it, from another side), or about its own position
 * when it gives a direction instead. Returns 1 when it changed the sensor. */
static int turn_sensor(json_t *sensor, double deg)
{
    double pos[3], at[3], dir[3], up[3] = {0.0, 0.0, 1.0};
    if (!get_vec3(sensor, "position_m", pos))
        return 0;
    get_vec3(sensor, "up", up);
    if (!(up[0] * up[0] + up[1] * up[1] + up[2] * up[2] > 0.0))
        return 0;
    if (get_vec3(sensor, "look_at_m", at)) {
        double r[3] = {pos[0] - at[0], pos[1] - at[1], pos[2] - at[2]};
        rotate(r, up, deg);
        for (size_t i = 0; i < 3; i++)
            pos[i] = at[i] + r[i];
        set_vec3(sensor, "position_m", pos);
        return 1;
    }
    if (!get_vec3(sensor, "direction", dir))
        return 0;
    rotate(dir, up, deg);
    set_vec3(sensor, "direction", dir);
    return 1;
}

uint32_t bands_coarse_paths(uint32_t paths)
{
    return paths >= 4 ? paths / 4 : 1;
}

/* The air's temperature in a variant: the nominal scene's air_t_k (NaN: its air has
 * none) raised by the ambient range in VAR_AMBIENT, and held at air_t_k in every other
 * variant, written out where the scene leaves it to the enclosure's temperature (an
 * enclosure that is a target then changes alone). Returns 1 when it changed it. */
static int set_air_temperature(json_t *atm, int what, double air_t_k, double range_k)
{
    if (!atm || !isfinite(air_t_k))
        return 0;
    double t = what == VAR_AMBIENT ? air_t_k + range_k : air_t_k;
    json_object_set_new(atm, "temperature_k", json_real(t));
    return what == VAR_AMBIENT;
}

char *bands_variant_text(const json_t *root, const bands_setup *s, const bool *is_class, int what,
                         size_t target, double air_t_k, bool coarse, int *changed)
{
    json_t *doc = json_deep_copy(root);
    if (!doc)
        return NULL;
    json_t *channels = json_array();
    for (size_t c = 0; c < s->n_candidates; c++) {
        json_t *ch = json_object();
        json_object_set_new(ch, "frequency_thz", json_real(s->candidates_thz[c]));
        json_object_set_new(ch, "relative_width", json_real(s->widths[c]));
        json_array_append_new(channels, ch);
    }
    json_object_set_new(doc, "channels", channels);
    json_t *render = json_object();
    json_object_set_new(render, "integrator", json_string("path"));
    json_object_set_new(
        render, "paths_per_sample",
        json_integer(coarse ? bands_coarse_paths(s->paths_per_sample) : s->paths_per_sample));
    json_object_set_new(doc, "render", render);
    /* the sensor's noise with one netd_k per channel cannot follow the candidates: its
     * NETD is interpolated to them instead (api_bands.c), and the renders need none */
    json_t *sensor = json_array_get(json_object_get(doc, "sensors"), s->sensor);
    json_t *noise = json_object_get(sensor, "noise");
    if (noise && json_is_array(json_object_get(noise, "netd_k")))
        json_object_del(sensor, "noise");
    if (coarse && sensor)
        json_object_set_new(sensor, "oversampling", json_integer(1));
    *changed = 0;
    json_t *objects = json_object_get(doc, "objects");
    json_t *atm = json_object_get(doc, "atmosphere");
    if (what != VAR_NOMINAL)
        *changed += set_air_temperature(atm, what, air_t_k, s->ambient_range_k);
    if (what == VAR_TARGETS) {
        /* one target at a time: the targets' temperatures vary independently */
        *changed +=
            add_number(json_array_get(objects, target), "temperature_k", s->target_range_k, 1.0);
    } else if (what == VAR_AMBIENT) {
        for (size_t i = 0; i < json_array_size(objects); i++)
            if (!is_class[i])
                *changed += add_number(json_array_get(objects, i), "temperature_k",
                                       s->ambient_range_k, 1.0);
    } else if (what == VAR_HUMIDITY && atm) {
        /* downwards, which every humidity key accepts */
        for (size_t i = 0; i < 3; i++)
            *changed += add_number(atm, humidity_keys[i], 0.0, 1.0 - s->humidity_range);
    } else if (what == VAR_THICKNESS) {
        for (size_t i = 0; i < json_array_size(objects); i++) {
            json_t *o = json_array_get(objects, i);
            const char *type = json_string_value(json_object_get(o, "type"));
            if (type && strcmp(type, "shell") == 0)
                *changed += add_number(o, "thickness_m", 0.0, 1.0 + s->thickness_range);
        }
    } else if (what == VAR_ANGLE && sensor) {
        *changed += turn_sensor(sensor, s->angle_range_deg);
    }
    char *text = json_dumps(doc, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(doc);
    return text;
}
