/* summary.json: what a run did, for people and for scripts (scene-format.md
 * "Outputs"). Units are in the key names. Timings make it the one output file that
 * is not reproducible bit for bit.
 *
 * Fractions of the photon phase: `fraction_absorbed`, `fraction_escaped` and
 * `fraction_terminated` are per photon fired (how the photon paths ended; they sum to
 * 1), `fraction_reflected` and `fraction_transmitted` per surface hit (the Russian
 * roulette's choices, mean R and T seen by the photons). The raw counts are given too.
 */
#include "io/output.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "core/json_text.h"
#include "core/path.h"
#include "physics/channel.h"
#include "sensor/measure.h"
#include "sensor/noise.h"
#include "thzmap/thzmap.h"

/* Builders that remember an allocation failure in *ok instead of checking each call.
 * They take ownership of value, as jansson's _new functions do (which release it even
 * when they fail): when obj or arr could not be made, value is released here. */
static void sum_set(json_t *obj, const char *key, json_t *value, bool *ok)
{
    if (!obj) {
        json_decref(value);
        *ok = false;
    } else if (!value || json_object_set_new(obj, key, value) != 0) {
        *ok = false;
    }
}

static void sum_append(json_t *arr, json_t *value, bool *ok)
{
    if (!arr) {
        json_decref(value);
        *ok = false;
    } else if (!value || json_array_append_new(arr, value) != 0) {
        *ok = false;
    }
}

/* A real, or null where it is not finite (JSON has no NaN). */
static json_t *sum_real(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *sum_u64(uint64_t v)
{
    if (v <= (uint64_t)INT64_MAX) /* json_int_t is long long */
        return json_integer((json_int_t)v);
    return sum_real((double)v);
}

static json_t *sum_string(const char *s)
{
    return thz_json_text(s); /* a path need not be UTF-8 */
}

static double sum_ratio(uint64_t part, uint64_t whole)
{
    return whole ? (double)part / (double)whole : 0.0;
}

/* A channel's photon statistics into its object o: the one place photon_stats becomes
 * JSON. */
static void sum_photon_stats(json_t *o, const photon_stats *s, bool *ok)
{
    sum_set(o, "photons_fired", sum_u64(s->fired), ok);
    sum_set(o, "photons_stored", sum_u64(s->stored), ok);
    sum_set(o, "photon_reference_temperature_k", sum_real(s->reference_temperature_k), ok);
    sum_set(o, "fraction_absorbed", sum_real(sum_ratio(s->absorbed, s->fired)), ok);
    sum_set(o, "fraction_escaped", sum_real(sum_ratio(s->escaped, s->fired)), ok);
    sum_set(o, "fraction_terminated", sum_real(sum_ratio(s->terminated, s->fired)), ok);
    sum_set(o, "fraction_reflected", sum_real(sum_ratio(s->reflected, s->hits)), ok);
    sum_set(o, "fraction_transmitted", sum_real(sum_ratio(s->transmitted, s->hits)), ok);
    sum_set(o, "back_face_hits", sum_u64(s->back_face_hits), ok);
    sum_set(o, "mean_bounces", sum_real(s->mean_bounces), ok);
    json_t *counts = json_object();
    sum_set(counts, "hits", sum_u64(s->hits), ok);
    sum_set(counts, "reflected", sum_u64(s->reflected), ok);
    sum_set(counts, "transmitted", sum_u64(s->transmitted), ok);
    sum_set(counts, "absorbed", sum_u64(s->absorbed), ok);
    sum_set(counts, "escaped", sum_u64(s->escaped), ok);
    sum_set(counts, "terminated", sum_u64(s->terminated), ok);
    sum_set(o, "counts", counts, ok);
    /* Exact bookkeeping: fired = absorbed + escaped + atmosphere + terminated (the
     * low-power roulette's net removal). relative_difference compares that total
     * with the band-mean P_A: Monte Carlo noise of the fired power only (or a bug).
     * A deviation map (T0 > 0) fires the signed sources of L - B(T0), not P_A: its
     * sums balance as well, but relative_difference is null. */
    json_t *e = json_object();
    double out = s->absorbed_power_w_per_hz + s->escaped_power_w_per_hz +
                 s->atmosphere_power_w_per_hz + s->terminated_power_w_per_hz;
    sum_set(e, "emitted_w_per_hz", sum_real(s->emitted_power_w_per_hz), ok);
    sum_set(e, "fired_w_per_hz", sum_real(s->fired_power_w_per_hz), ok);
    sum_set(e, "absorbed_w_per_hz", sum_real(s->absorbed_power_w_per_hz), ok);
    sum_set(e, "escaped_w_per_hz", sum_real(s->escaped_power_w_per_hz), ok);
    sum_set(e, "atmosphere_w_per_hz", sum_real(s->atmosphere_power_w_per_hz), ok);
    sum_set(e, "terminated_w_per_hz", sum_real(s->terminated_power_w_per_hz), ok);
    sum_set(e, "relative_difference",
            s->emitted_power_w_per_hz > 0.0 && !(s->reference_temperature_k > 0.0)
                ? sum_real((s->emitted_power_w_per_hz - out) / s->emitted_power_w_per_hz)
                : json_null(),
            ok);
    sum_set(o, "energy_balance", e, ok);
    sum_set(o, "photon_phase_s", sum_real(s->seconds), ok);
}

static json_t *sum_channel(const thz_scene *scene, size_t c, const run_summary *summary, bool *ok)
{
    const thz_channel *ch = &scene->channels[c];
    json_t *o = json_object();
    sum_set(o, "name", json_string(ch->name), ok);
    sum_set(o, "frequency_thz", sum_real(ch->center_hz / 1e12), ok);
    bool table = channel_has_response(ch);
    sum_set(o, "relative_width", table ? json_null() : sum_real(ch->relative_width), ok);
    sum_set(o, "response", json_string(table ? "table" : "gaussian"), ok);
    sum_set(o, "bandwidth_ghz", sum_real(channel_bandwidth_hz(ch) * 1e-9), ok);
    sum_set(o, "noise_bandwidth_ghz", sum_real(channel_noise_bandwidth_hz(ch) * 1e-9), ok);
    /* P_A of the surfaces (physics.md; what validate prints), with or without a photon
     * phase; the air's own emission is in energy_balance.emitted_w_per_hz */
    sum_set(o, "emitted_power_w_per_hz", sum_real(scene_band_emitted_power_w_per_hz(scene, c)), ok);
    if (summary->channel_stats) {
        sum_photon_stats(o, &summary->channel_stats[c], ok);
    } else { /* path: no photon phase */
        sum_set(o, "photons_fired", json_integer(0), ok);
        sum_set(o, "photons_stored", json_integer(0), ok);
    }
    if (summary->noise) {
        sum_set(o, "median_stderr_k", sum_real(summary->noise[c].median_k), ok);
        sum_set(o, "p95_stderr_k", sum_real(summary->noise[c].p95_k), ok);
        sum_set(o, "starved_pixels", sum_u64(summary->noise[c].unknown), ok);
    }
    if (summary->object_noise) {
        /* per object: the pixels whose truth object_id is it (null figures: none, or
         * the rank falls on a pixel whose standard error is unknown) */
        json_t *objects = json_array();
        for (size_t i = 0; i < scene->n_objects; i++) {
            const run_noise *n = &summary->object_noise[c * scene->n_objects + i];
            json_t *e = json_object();
            sum_set(e, "name", json_string(scene->objects[i].name), ok);
            sum_set(e, "pixels", sum_u64(n->pixels), ok);
            sum_set(e, "median_stderr_k", n->pixels ? sum_real(n->median_k) : json_null(), ok);
            sum_set(e, "p95_stderr_k", n->pixels ? sum_real(n->p95_k) : json_null(), ok);
            sum_set(e, "starved_pixels", sum_u64(n->unknown), ok);
            sum_append(objects, e, ok);
        }
        sum_set(o, "objects", objects, ok);
    }
    if (summary->passes)
        sum_set(o, "render_passes", json_integer(summary->passes[c]), ok);
    if (summary->seconds_render_channel)
        sum_set(o, "render_s", sum_real(summary->seconds_render_channel[c]), ok);
    return o;
}

/* sensors[].model: the optics and noise that made S.measured_*, or null without them. */
static json_t *sum_sensor_model(const thz_scene *scene, const thz_sensor *s,
                                const run_summary *summary, bool *ok)
{
    if (!sensor_has_model(s))
        return json_null();
    json_t *o = json_object();
    sum_set(o, "psf", json_string(sensor_psf_name(s->psf)), ok);
    sum_set(o, "aperture_diameter_m",
            s->aperture_diameter_m > 0.0 ? sum_real(s->aperture_diameter_m) : json_null(), ok);
    if (s->psf == PSF_GAUSSIAN)
        sum_set(o, "psf_fwhm_deg", sum_real(s->psf_fwhm_deg), ok);
    const thz_sensor_noise *n = &s->noise;
    json_t *noise = json_null();
    if (n->kind != NOISE_NONE) {
        noise = json_object();
        sum_set(noise, "model", json_string(sensor_noise_name(n)), ok);
        if (n->kind == NOISE_RADIOMETER) {
            sum_set(noise, "receiver_temperature_k", sum_real(n->receiver_temperature_k), ok);
            sum_set(noise, "integration_time_s", sum_real(n->integration_time_s), ok);
        }
        /* per channel: the given NETD, or the radiometer's at the channel's reference
         * temperature (it varies per pixel with Tb) */
        json_t *netd = json_array(), *tref = json_array();
        for (size_t c = 0; c < scene->n_channels; c++) {
            double t0 = scene_reference_temperature_k(scene, c);
            sum_append(netd, sum_real(noise_netd_k(n, &scene->channels[c], c, t0)), ok);
            sum_append(tref, sum_real(t0), ok);
        }
        sum_set(noise, "netd_k", netd, ok);
        if (n->kind == NOISE_RADIOMETER)
            sum_set(noise, "netd_at_temperature_k", tref, ok);
        else
            json_decref(tref);
    }
    sum_set(o, "noise", noise, ok);
    sum_set(o, "noise_seed", sum_u64(sensor_noise_seed(s, summary->seed)), ok);
    return o;
}

static json_t *sum_sensor(const thz_scene *scene, size_t i, const run_summary *summary, bool *ok)
{
    const thz_sensor *s = &scene->sensors[i];
    json_t *o = json_object();
    sum_set(o, "name", json_string(s->name), ok);
    sum_set(o, "columns", json_integer(s->columns), ok);
    sum_set(o, "rows", json_integer(s->rows), ok);
    sum_set(o, "fov_deg", sum_real(s->fov_deg), ok);
    sum_set(o, "oversampling", json_integer(s->oversampling), ok);
    sum_set(o, "aperture_m2", sum_real(s->aperture_m2), ok);
    sum_set(o, "normalize_to_k", sum_real(s->normalize_to_k), ok);
    sum_set(o, "model", sum_sensor_model(scene, s, summary, ok), ok);
    if (summary->back_face_samples)
        sum_set(o, "back_face_samples", sum_u64(summary->back_face_samples[i]), ok);
    return o;
}

static json_t *sum_hex(uint64_t v)
{
    char hex[17];
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)v);
    return json_string(hex);
}

/* What identifies the scene as run (thz_scene_get_fingerprint): its geometry, optics and
 * channels, and with the sensors and settings but for the photon count and seed, which
 * summary.json gives beside it. */
static json_t *sum_fingerprint(const thz_scene *scene, bool *ok)
{
    thz_scene_fingerprint f;
    thz_scene_get_fingerprint(scene, &f);
    json_t *o = json_object();
    sum_set(o, "geometry", sum_hex(f.geometry), ok);
    sum_set(o, "optics", sum_hex(f.optics), ok);
    sum_set(o, "channels", sum_hex(f.channels), ok);
    sum_set(o, "run", sum_hex(f.run), ok);
    return o;
}

/* The document, or NULL when out of memory. */
static json_t *summary_build(const thz_scene *scene, const run_summary *summary)
{
    bool ok = true;
    json_t *root = json_object();
    sum_set(root, "thzmap_version", json_string(THZ_VERSION_STRING), &ok);
    sum_set(root, "thzmap_revision", json_string(thz_revision()), &ok);
    sum_set(root, "command", sum_string(summary->command), &ok);
    json_t *sc = json_object();
    sum_set(sc, "name", sum_string(scene->name), &ok);
    sum_set(sc, "path", sum_string(scene->path), &ok);
    sum_set(sc, "fingerprint", sum_fingerprint(scene, &ok), &ok);
    sum_set(root, "scene", sc, &ok);
    sum_set(root, "seed", sum_u64(summary->seed), &ok);
    sum_set(root, "photons_per_channel", sum_u64(summary->photons_per_channel), &ok);
    sum_set(root, "integrator", sum_string(summary->integrator), &ok);
    /* the 95th percentile over pixels of the standard error of Tb_c aimed at */
    sum_set(root, "target_noise_k",
            summary->target_noise_k > 0.0 ? sum_real(summary->target_noise_k) : json_null(), &ok);
    sum_set(root, "target_noise_source", sum_string(summary->target_source), &ok);
    /* the settings that, with the scene and seed, make the images */
    sum_set(root, "max_seconds",
            scene->render.max_seconds > 0.0 ? sum_real(scene->render.max_seconds) : json_null(),
            &ok);
    sum_set(root, "paths_per_sample", json_integer(scene->render.paths_per_sample), &ok);
    sum_set(root, "gather_rays", json_integer(scene->render.gather_rays), &ok);
    sum_set(root, "gather_min_photons", json_integer(scene->photons.gather_min_photons), &ok);
    sum_set(root, "min_relative_power", sum_real(scene->photons.min_relative_power), &ok);
    sum_set(root, "threads", json_integer(summary->threads), &ok);
    sum_set(root, "mpi_ranks", json_integer(summary->mpi_ranks > 1 ? summary->mpi_ranks : 1), &ok);
    sum_set(root, "atmosphere_model", json_string(atmosphere_model_name(scene->atmosphere.model)),
            &ok);

    json_t *channels = json_array();
    for (size_t c = 0; c < scene->n_channels; c++)
        sum_append(channels, sum_channel(scene, c, summary, &ok), &ok);
    sum_set(root, "channels", channels, &ok);

    json_t *sensors = json_array();
    for (size_t i = 0; i < scene->n_sensors; i++)
        sum_append(sensors, sum_sensor(scene, i, summary, &ok), &ok);
    sum_set(root, "sensors", sensors, &ok);

    json_t *t = json_object();
    sum_set(t, "load", sum_real(summary->seconds_load), &ok);
    sum_set(t, "accel", sum_real(summary->seconds_accel), &ok);
    sum_set(t, "photons", sum_real(summary->seconds_photons), &ok);
    sum_set(t, "render", sum_real(summary->seconds_render), &ok);
    sum_set(t, "output", sum_real(summary->seconds_output), &ok);
    sum_set(root, "timings_s", t, &ok);

    json_t *warnings = json_array();
    for (size_t i = 0; i < scene->n_warnings; i++)
        sum_append(warnings, sum_string(scene->warnings[i]), &ok);
    for (size_t i = 0; i < summary->n_run_warnings; i++)
        sum_append(warnings, sum_string(summary->run_warnings[i]), &ok);
    sum_set(root, "warnings", warnings, &ok);

    if (!ok) {
        json_decref(root);
        return NULL;
    }
    return root;
}

#define SUMMARY_FLAGS (JSON_INDENT(2) | JSON_REAL_PRECISION(12))

char *summary_text(const thz_scene *scene, const run_summary *summary, thz_error *err)
{
    json_t *root = summary_build(scene, summary);
    char *text = root ? json_dumps(root, SUMMARY_FLAGS) : NULL;
    json_decref(root);
    if (!text)
        thz_error_set(err, THZ_ERR_NOMEM, "summary.json: out of memory");
    return text;
}

thz_status summary_write(const char *dir, const thz_scene *scene, const run_summary *summary,
                         thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status status = thz_path_join(path, sizeof path, dir, "summary.json", err);
    if (status != THZ_OK)
        return status;
    json_t *root = summary_build(scene, summary);
    if (!root)
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    else {
        errno = 0; /* ENOMEM after a failure: out of memory, not a write error */
        if (json_dump_file(root, path, SUMMARY_FLAGS) != 0)
            status = thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO), "%s: cannot write: %s",
                                   path,
                                   errno == ENOMEM ? "out of memory"
                                   : errno         ? strerror(errno)
                                                   : "write failed");
    }
    json_decref(root);
    return status;
}
