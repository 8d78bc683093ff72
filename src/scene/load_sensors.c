/* The scene's `sensors` block: pinhole cameras (position, viewing direction, up, angle
 * of view, resolution, aperture, oversampling, normalisation temperature); their optics
 * and noise are in load_sensor_model.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/c_locale.h"
#include "physics/planck.h"
#include "scene/load.h"
#include "scene/scene_checks.h"
#include "core/vec3.h"

#define LOAD_MAX_RESOLUTION 65536u
#define LOAD_MAX_OVERSAMPLING 16u

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

/* A name fit to begin file names, and not naming the files of an earlier sensor. */
static thz_status load_sensor_file_name(load_ctx *ctx, const load_cursor *list, size_t index,
                                        const char *name)
{
    load_cursor e = load_index(list, index), k = load_key(&e, "name");
    size_t len = strlen(name);
    if (len > SENSOR_NAME_MAX)
        return load_fail(ctx, &k,
                         "a name of %zu bytes (expected at most %d: it begins the names of the "
                         "sensor's output files)",
                         len, SENSOR_NAME_MAX);
    for (size_t j = 0; j < index; j++) {
        json_t *other = json_object_get(json_array_get(list->value, j), "name");
        const char *o = json_is_string(other) ? json_string_value(other) : NULL;
        if (!o || strlen(o) != len)
            continue;
        size_t i = 0;
        while (i < len && sensor_file_char(o[i]) == sensor_file_char(name[i]))
            i++;
        if (i == len)
            return load_fail(ctx, &k,
                             "\"%s\" would write the same files as %s[%zu] \"%s\" (a '/' in a "
                             "name becomes '_' in file names; expected names whose files differ)",
                             name, list->path, j, o);
    }
    return THZ_OK;
}

/* The coldest normalize_to_k: h nu / (k T_ref) <= LOAD_NORMALIZE_MAX_X at the top of every
 * channel's band (centre + 2 FWHM, or where a measured response ends), so that the
 * band-mean B(T_ref) stays above exp(-50) of the Rayleigh-Jeans value and
 * B(T) / B(T_ref) for T up to LOAD_MAX_TEMPERATURE_K fits the float normalised cube. At
 * 0.35 THz T_ref 0.1 K gave an inf cube and 0.02 K one of 0 (B(T_ref) underflowed); 80
 * instead of 50 would still overflow (kT/h nu e^80 > 3.4e38 for 1e6 K at 0.35 THz).
 * Only a given normalize_to_k is held to it: the default 295 K fails it only for bands
 * beyond 307 THz, which validate already warns about as outside 0.05 to 10 THz (a GHz
 * value given in THz), and refusing there would hide that warning. */
#define LOAD_NORMALIZE_MAX_X 50.0

static thz_status load_normalize_floor(load_ctx *ctx, const load_cursor *c, double t_ref)
{
    const thz_scene *s = ctx->scene;
    double top = 0.0;
    size_t at = 0;
    for (size_t i = 0; i < s->n_channels; i++) {
        double lo, hi;
        load_channel_band(&s->channels[i], &lo, &hi);
        if (hi > top) {
            top = hi;
            at = i;
        }
    }
    double floor_k = THZ_PLANCK_H * top / (THZ_BOLTZMANN_K * LOAD_NORMALIZE_MAX_X);
    load_cursor k = load_key(c, "normalize_to_k");
    if (t_ref >= floor_k || !k.value) /* the default 295 K: see the comment above */
        return THZ_OK;
    char shown[LOAD_NUMBER_CHARS]; /* 4 digits, rounded up: a value as shown is accepted */
    for (double up = floor_k;; up *= 1.0 + 1e-5) {
        snprintf(shown, sizeof shown, "%.4g", up);
        if (thz_strtod(shown, NULL) >= floor_k)
            break;
    }
    /* A channel beyond the range thzmap is meant for is most often a GHz value given in
     * THz; validate's warning says so, but this refusal comes first and would hide it. */
    char ghz[256];
    scene_checks_ghz_hint(s, ghz, sizeof ghz);
    return load_fail(ctx, &k,
                     "expected a temperature >= %s K (h nu / k T_ref at most %g at %.4g THz, "
                     "the top of channel \"%s\"'s band; colder, B(T_ref) is too small for the "
                     "normalised cube), got %s K%s",
                     shown, LOAD_NORMALIZE_MAX_X, top * 1e-12, s->channels[at].name, LOAD_G(t_ref),
                     ghz);
}

/* v divided by its largest component's magnitude (0 when v is 0), so that its length is
 * finite however large or small the numbers given (a direction [0, 0, 1e308] is one). */
static vec3 load_sensor_unscaled(const double v[3])
{
    double m = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    if (!(m > 0.0))
        return v3(0.0, 0.0, 0.0);
    return v3(v[0] / m, v[1] / m, v[2] / m);
}

static thz_status load_sensor(load_ctx *ctx, const load_cursor *list, size_t index, thz_sensor *sn)
{
    static const char *const keys[] = {
        "name",         "position_m",     "look_at_m",           "direction",
        "up",           "fov_deg",        "resolution",          "aperture_m2",
        "oversampling", "normalize_to_k", "aperture_diameter_m", "psf",
        "psf_fwhm_deg", "noise",          "noise_seed",          NULL};
    load_cursor e = load_index(list, index);
    const load_cursor *c = &e;
    const char *name;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st == THZ_OK)
        st = load_unique_name(ctx, list, index, "sensor", true, &name);
    if (st == THZ_OK)
        st = load_sensor_file_name(ctx, list, index, name);
    if (st != THZ_OK)
        return st;
    sn->name = thz_strdup(name);
    if (!sn->name)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    st = load_vector(ctx, c, "position_m", 3, LOAD_COORDINATE, true, sn->position_m);
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
        st = load_vector(ctx, c, "look_at_m", 3, LOAD_COORDINATE, true, p);
        for (int i = 0; i < 3; i++)
            d[i] = p[i] - sn->position_m[i];
    } else {
        st = load_vector(ctx, c, "direction", 3, LOAD_ANY, true, d);
    }
    if (st != THZ_OK)
        return st;
    vec3 dv = load_sensor_unscaled(d);
    if (!(v3_length(dv) > 0.0))
        return load_fail(ctx, look.value ? &look : &dir,
                         look.value ? "the point to look at is the sensor's position (expected "
                                      "a different point)"
                                    : "expected a non-zero direction");
    dv = v3_normalize(dv);
    double up[3] = {0, 0, 1};
    st = load_vector(ctx, c, "up", 3, LOAD_ANY, false, up);
    if (st != THZ_OK)
        return st;
    vec3 uv = load_sensor_unscaled(up);
    load_cursor up_c = load_key(c, "up");
    double ul = v3_length(uv);
    if (!(ul > 0.0))
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
        st = load_number(ctx, c, "aperture_m2", LOAD_APERTURE_M2, false, 1e-2, &sn->aperture_m2);
    if (st == THZ_OK)
        st = load_integer(ctx, c, "oversampling", 1, LOAD_MAX_OVERSAMPLING, false, 1, &over);
    if (st == THZ_OK)
        st = load_number(ctx, c, "normalize_to_k",
                         (load_range){0.0, LOAD_MAX_TEMPERATURE_K, true, false}, false, 295.0,
                         &sn->normalize_to_k);
    if (st == THZ_OK)
        st = load_normalize_floor(ctx, c, sn->normalize_to_k);
    if (st != THZ_OK)
        return st;
    sn->oversampling = (uint32_t)over;
    return load_sensor_model(ctx, c, ctx->scene->n_channels, sn);
}

thz_status load_sensors(load_ctx *ctx, const load_cursor *root)
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
