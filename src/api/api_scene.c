/* Scenes through the public API: loading (the loader, then the checks that the sensors'
 * images fit in memory and that their PSFs can be built, which the loader cannot make:
 * it knows no images nor kernels), read access by value. (Destroying is scene/scene.c's
 * thz_scene_destroy.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "core/c_locale.h"
#include "physics/channel.h"
#include "physics/planck.h"
#include "scene/scene_hash.h"
#include "sensor/measure.h"
#include "sensor/noise.h"
#include "sensor/psf.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"

/* A loaded scene whose images would not fit in memory is refused (THZ_ERR_INPUT, naming
 * sensors[i].resolution), and one whose PSF no run could build (psf_sensor_check, naming
 * sensors[i].psf_fwhm_deg or .aperture_diameter_m): validate, Python and serve load
 * through here, so they say what simulate would refuse. */
static thz_status api_scene_checked(thz_status st, thz_scene **out, thz_error *err)
{
    if (st != THZ_OK)
        return st;
    bool refused = run_check_scene_memory(*out, err) != THZ_OK;
    for (size_t i = 0; !refused && i < (*out)->n_sensors; i++)
        refused = psf_sensor_check(*out, i, err) != THZ_OK;
    if (refused) {
        scene_destroy(*out);
        *out = NULL;
        st = THZ_ERR_INPUT; /* the scene asks too much: bad input, as before */
        if (err)
            err->status = st;
    }
    return st;
}

thz_status thz_scene_load_string_within(const char *json_text, const char *base_dir,
                                        const char *label, const char *root, thz_scene **out,
                                        thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_scene_load_string: no place for the scene");
    if (!json_text) {
        *out = NULL;
        return thz_error_set(err, THZ_ERR_INPUT, "thz_scene_load_string: no JSON text");
    }
    return api_scene_checked(
        scene_load_string_within(json_text, base_dir, label ? label : "<string>", root, out, err),
        out, err);
}

thz_status thz_scene_load_string(const char *json_text, const char *base_dir, const char *label,
                                 thz_scene **out, thz_error *err)
{
    return thz_scene_load_string_within(json_text, base_dir, label, NULL, out, err);
}

thz_status thz_scene_load_within(const char *path, const char *root, thz_scene **out,
                                 thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_scene_load: no place for the scene");
    if (!path) {
        *out = NULL;
        return thz_error_set(err, THZ_ERR_INPUT, "thz_scene_load: no path");
    }
    return api_scene_checked(scene_load_within(path, root, out, err), out, err);
}

thz_status thz_scene_load(const char *path, thz_scene **out, thz_error *err)
{
    return thz_scene_load_within(path, NULL, out, err);
}

thz_status thz_scene_get_info(const thz_scene *s, thz_scene_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s)
        return THZ_ERR_INPUT;
    *out = (thz_scene_info){
        .name = s->name,
        .path = s->path,
        .atmosphere_model = atmosphere_model_name(s->atmosphere.model),
        .n_channels = s->n_channels,
        .n_materials = s->n_materials,
        .n_objects = s->n_objects,
        .n_sensors = s->n_sensors,
        .n_warnings = s->n_warnings,
        .photons_per_channel = s->photons.per_channel,
        .seed = s->photons.seed,
        .min_relative_power = s->photons.min_relative_power,
        .gather_min_photons = s->photons.gather_min_photons,
        .integrator = render_integrator_name(s->render.integrator),
        .gather_rays = s->render.gather_rays,
        .paths_per_sample = s->render.paths_per_sample,
    };
    return THZ_OK;
}

thz_status thz_scene_get_fingerprint(const thz_scene *s, thz_scene_fingerprint *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s)
        return THZ_ERR_INPUT;
    scene_hash h;
    scene_hash_compute(s, &h);
    *out = (thz_scene_fingerprint){.geometry = h.geometry,
                                   .optics = h.optics,
                                   .channels = h.channels,
                                   .run = scene_hash_run(s, true)};
    return THZ_OK;
}

thz_status thz_scene_channel(const thz_scene *s, size_t i, thz_channel_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_channels)
        return THZ_ERR_INPUT;
    const thz_channel *ch = &s->channels[i];
    *out = (thz_channel_info){
        .name = ch->name,
        .frequency_hz = ch->center_hz,
        .frequency_thz = ch->center_hz / 1e12, /* 0.8, not 0.7999999999999999 */
        .relative_width = ch->relative_width,
        .bandwidth_hz = channel_bandwidth_hz(ch),
        .emitted_power_w_per_hz = scene_band_emitted_power_w_per_hz(s, i),
        .noise_bandwidth_hz = channel_noise_bandwidth_hz(ch),
        .fwhm_hz = channel_fwhm_hz(ch),
        .response_points = ch->n_response,
    };
    return THZ_OK;
}

/* A mesh coordinate (a float) as the double of its shortest decimal: 0.6, which the
 * scene file said, rather than 0.6000000238418579, the float's exact value. */
static double api_float_decimal(double v)
{
    float f = (float)v;
    char text[32];
    for (int digits = 1; digits <= 9; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, (double)f);
        if (strtof(text, NULL) == f)
            return thz_strtod(text, NULL);
    }
    return v;
}

static thz_spectrum_info api_spectrum(const thz_spectrum *sp)
{
    thz_spectrum_info info = {0};
    if (sp->n == 0)
        return info;
    if (!sp->freq_hz) {
        info.kind = THZ_SPECTRUM_CONSTANT;
        info.n_points = 1;
        info.value = sp->value[0];
        return info;
    }
    info.kind = THZ_SPECTRUM_TABLE;
    info.n_points = sp->n;
    info.from_thz = sp->freq_hz[0] / 1e12;
    info.to_thz = sp->freq_hz[sp->n - 1] / 1e12;
    spectrum_range(sp, &info.min_value, &info.max_value);
    return info;
}

thz_status thz_scene_material(const thz_scene *s, size_t i, thz_material_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_materials)
        return THZ_ERR_INPUT;
    const thz_material *m = &s->materials[i];
    out->name = m->name;
    out->reflectivity = api_spectrum(&m->reflectivity);
    out->attenuation_per_m = api_spectrum(&m->attenuation_per_m);
    out->emissivity = api_spectrum(&m->emissivity);
    out->transmission = m->transmission == TRANSMISSION_STRAIGHT ? "straight" : "diffuse";
    memcpy(out->color, m->color, sizeof out->color);
    out->index_model = m->index ? material_index_form(m->index) : NULL;
    out->reflection = m->reflection == REFLECTION_SPECULAR ? "specular"
                      : m->reflection == REFLECTION_WARD   ? "ward"
                                                           : "diffuse";
    if (m->reflection == REFLECTION_WARD) {
        out->ward_alpha_x = m->ward_alpha[0];
        out->ward_alpha_y = m->ward_alpha[1];
    }
    return THZ_OK;
}

thz_status thz_scene_object(const thz_scene *s, size_t i, thz_object_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_objects)
        return THZ_ERR_INPUT;
    const thz_object *o = &s->objects[i];
    *out = (thz_object_info){
        .name = o->name,
        .type = o->type == OBJECT_SHELL ? "shell" : "solid",
        .two_sided = o->two_sided,
        .thickness_m = o->thickness_m,
        .material = o->material,
        .material_name = s->materials[o->material].name,
        .temperature_k = o->temperature_k,
        .triangles = o->mesh.n_triangles,
        .area_m2 = o->mesh.total_area_m2,
    };
    for (int a = 0; a < 3; a++) {
        out->bbox_min_m[a] = api_float_decimal(o->mesh.bbox_min_m[a]);
        out->bbox_max_m[a] = api_float_decimal(o->mesh.bbox_max_m[a]);
    }
    return THZ_OK;
}

thz_status thz_scene_sensor(const thz_scene *s, size_t i, thz_sensor_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_sensors)
        return THZ_ERR_INPUT;
    const thz_sensor *sn = &s->sensors[i];
    *out = (thz_sensor_info){
        .name = sn->name,
        .columns = sn->columns,
        .rows = sn->rows,
        .channels = s->n_channels,
        .fov_deg = sn->fov_deg,
        .oversampling = sn->oversampling,
        .aperture_m2 = sn->aperture_m2,
        .normalize_to_k = sn->normalize_to_k,
    };
    memcpy(out->position_m, sn->position_m, sizeof out->position_m);
    memcpy(out->direction, sn->direction, sizeof out->direction);
    memcpy(out->up, sn->up, sizeof out->up);
    return THZ_OK;
}

thz_status thz_scene_sensor_channel(const thz_scene *s, size_t sensor, size_t channel,
                                    thz_sensor_channel_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || sensor >= s->n_sensors || channel >= s->n_channels)
        return THZ_ERR_INPUT;
    const thz_sensor *sn = &s->sensors[sensor];
    const thz_channel *ch = &s->channels[channel];
    double t0 = scene_reference_temperature_k(s, channel);
    *out = (thz_sensor_channel_info){
        .psf = sensor_psf_name(sn->psf),
        .aperture_diameter_m = sn->aperture_diameter_m,
        .noise = sensor_noise_name(&sn->noise),
        .netd_k = noise_netd_k(&sn->noise, ch, channel, t0),
        .netd_at_k = sn->noise.kind == NOISE_RADIOMETER ? t0 : 0.0,
        .noise_bandwidth_hz = channel_noise_bandwidth_hz(ch),
        .noise_seed_given = sn->noise_seed_given,
        .noise_seed = sn->noise_seed,
    };
    if (sn->psf == PSF_AIRY)
        out->spot_rad = 1.22 * THZ_SPEED_OF_LIGHT / ch->center_hz / sn->aperture_diameter_m;
    else if (sn->psf == PSF_GAUSSIAN)
        out->spot_rad = sn->psf_fwhm_deg * M_PI / 180.0;
    return THZ_OK;
}

size_t thz_scene_channel_count(const thz_scene *s)
{
    return s ? s->n_channels : 0;
}

size_t thz_scene_object_count(const thz_scene *s)
{
    return s ? s->n_objects : 0;
}

size_t thz_scene_sensor_count(const thz_scene *s)
{
    return s ? s->n_sensors : 0;
}

long thz_scene_sensor_index(const thz_scene *s, const char *name)
{
    for (size_t i = 0; s && name && i < s->n_sensors; i++)
        if (strcmp(s->sensors[i].name, name) == 0)
            return (long)i;
    return -1;
}

long thz_scene_object_index(const thz_scene *s, const char *name)
{
    for (size_t i = 0; s && name && i < s->n_objects; i++)
        if (strcmp(s->objects[i].name, name) == 0)
            return (long)i;
    return -1;
}

size_t thz_scene_warning_count(const thz_scene *s)
{
    return s ? s->n_warnings : 0;
}

const char *thz_scene_warning(const thz_scene *s, size_t i)
{
    return s && i < s->n_warnings ? s->warnings[i] : NULL;
}

int thz_integrator_known(const char *name)
{
    thz_integrator it;
    return name && render_integrator_parse(name, &it);
}

int thz_integrator_needs_photons(const char *name)
{
    thz_integrator it;
    return name && render_integrator_parse(name, &it) && render_integrator_needs_photons(it);
}

int thz_integrator_has_passes(const char *name)
{
    thz_integrator it;
    return name && render_integrator_parse(name, &it) && render_integrator_has_passes(it);
}

thz_status thz_scene_object_mesh(const thz_scene *s, size_t i, thz_object_mesh *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_objects)
        return THZ_ERR_INPUT;
    const thz_mesh *m = &s->objects[i].mesh;
    *out = (thz_object_mesh){
        .n_vertices = m->n_vertices,
        .positions = m->positions,
        .n_triangles = m->n_triangles,
        .indices = m->indices,
        .normals = m->normals,
    };
    return THZ_OK;
}

thz_status thz_scene_material_optics(const thz_scene *s, size_t i, double freq_hz,
                                     double thickness_m, thz_surface_optics *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!s || i >= s->n_materials || !(freq_hz > 0.0) || !isfinite(freq_hz) ||
        !(thickness_m >= 0.0) || !isfinite(thickness_m))
        return THZ_ERR_INPUT;
    /* an object of this material, as the simulation would see it */
    thz_object obj = {
        .type = thickness_m > 0.0 ? OBJECT_SHELL : OBJECT_SOLID,
        .material = i,
        .thickness_m = thickness_m,
    };
    optics_point o = scene_object_optics(s, &obj, freq_hz);
    optics_prepare(&o);
    *out = (thz_surface_optics){
        .reflectance_normal = optics_reflectance(&o, 1.0),
        .reflectance_mean = optics_mean_reflectance(&o),
        .emissivity_normal = optics_emissivity(&o, 1.0),
        .emissivity_mean = optics_mean_emissivity(&o),
        .transmission_mean = optics_mean_transmission(&o),
        .attenuation_per_m = o.attenuation_per_m,
        .has_index = o.has_index,
        .n = o.has_index ? o.n : 0.0,
        .k = o.has_index ? o.k : 0.0,
    };
    if (o.has_index && !o.attenuation_given)
        out->attenuation_per_m = 4.0 * M_PI * o.k * freq_hz / THZ_SPEED_OF_LIGHT;
    return THZ_OK;
}

double thz_planck_radiance(double freq_hz, double temperature_k)
{
    if (isnan(freq_hz) || isnan(temperature_k))
        return NAN;
    return planck_radiance(freq_hz, temperature_k);
}

double thz_brightness_temperature(double freq_hz, double radiance)
{
    if (isnan(freq_hz) || isnan(radiance))
        return NAN;
    return planck_brightness_temperature(freq_hz, radiance);
}

double thz_brightness_temperature_stderr(double freq_hz, double tb_k, double stderr_l)
{
    if (isnan(freq_hz) || isnan(tb_k) || isnan(stderr_l))
        return NAN;
    return render_stderr_k(freq_hz, tb_k, stderr_l);
}
