/* A sensor's optics and noise keys (scene-format.md "Sensors: optics and noise"):
 * aperture_diameter_m, psf, psf_fwhm_deg, noise and noise_seed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "scene/load.h"

/* The radiometer names of the `noise` block, indexed by thz_radiometer. */
static const char *const load_radiometers[] = {"total-power", "dicke", NULL};

/* noise.netd_k: one number for every channel, or a list of one per channel. */
static thz_status load_netd(load_ctx *ctx, const load_cursor *noise, size_t n_channels,
                            double *netd_k)
{
    load_cursor k = load_key(noise, "netd_k");
    const char *what = "a NETD in K (> 0), or a list of one per channel";
    if (json_is_number(k.value)) {
        double x = json_number_value(k.value);
        if (!(x > 0.0) || !isfinite(x))
            return load_fail(ctx, &k, "expected %s, got %g", what, x);
        for (size_t c = 0; c < n_channels; c++)
            netd_k[c] = x;
        return THZ_OK;
    }
    if (!json_is_array(k.value))
        return load_fail(ctx, &k, "expected %s, got %s", what, load_type_name(k.value));
    if (json_array_size(k.value) != n_channels)
        return load_fail(ctx, &k, "expected one value per channel (%zu), got %zu", n_channels,
                         json_array_size(k.value));
    for (size_t c = 0; c < n_channels; c++) {
        load_cursor e = load_index(&k, c);
        double x = json_is_number(e.value) ? json_number_value(e.value) : NAN;
        if (!(x > 0.0) || !isfinite(x))
            return load_fail(ctx, &e, "expected a NETD in K (> 0), got %s",
                             json_is_number(e.value) ? "a value <= 0" : load_type_name(e.value));
    }
    for (size_t c = 0; c < n_channels; c++)
        netd_k[c] = json_number_value(json_array_get(k.value, c));
    return THZ_OK;
}

/* The `noise` block: {"netd_k": ...} or the radiometer form, not both. */
static thz_status load_noise(load_ctx *ctx, const load_cursor *c, size_t n_channels,
                             thz_sensor_noise *noise)
{
    static const char *const keys[] = {"netd_k", "receiver_temperature_k", "integration_time_s",
                                       "radiometer", NULL};
    load_cursor k = load_key(c, "noise");
    if (!k.value)
        return THZ_OK;
    thz_status st = load_expect_object(ctx, &k, keys);
    if (st != THZ_OK)
        return st;
    bool netd = json_object_get(k.value, "netd_k") != NULL;
    bool radiometer = json_object_get(k.value, "receiver_temperature_k") ||
                      json_object_get(k.value, "integration_time_s") ||
                      json_object_get(k.value, "radiometer");
    if (netd && radiometer)
        return load_fail(ctx, &k,
                         "give either netd_k or the radiometer form (receiver_temperature_k, "
                         "integration_time_s, radiometer), not both");
    if (netd) {
        noise->netd_k = thz_calloc(n_channels, sizeof *noise->netd_k);
        if (!noise->netd_k)
            return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        noise->kind = NOISE_NETD;
        return load_netd(ctx, &k, n_channels, noise->netd_k);
    }
    if (!radiometer)
        return load_fail(ctx, &k,
                         "expected {\"netd_k\": x} or {\"receiver_temperature_k\": T_rec, "
                         "\"integration_time_s\": tau, \"radiometer\": \"total-power\" | "
                         "\"dicke\"}, got an empty object");
    size_t type = 0;
    st = load_number(ctx, &k, "receiver_temperature_k", LOAD_TEMPERATURE, true, 0.0,
                     &noise->receiver_temperature_k);
    if (st == THZ_OK)
        st = load_number(ctx, &k, "integration_time_s", LOAD_POSITIVE, true, 0.0,
                         &noise->integration_time_s);
    if (st == THZ_OK)
        st = load_require(ctx, &k, "radiometer", "\"total-power\" or \"dicke\"");
    if (st == THZ_OK)
        st = load_choice(ctx, &k, "radiometer", load_radiometers, true, 0, &type);
    if (st != THZ_OK)
        return st;
    noise->kind = NOISE_RADIOMETER;
    noise->radiometer = (thz_radiometer)type;
    return THZ_OK;
}

thz_status load_sensor_model(load_ctx *ctx, const load_cursor *c, size_t n_channels, thz_sensor *sn)
{
    static const char *const psfs[] = {"none", "airy", "gaussian", NULL}; /* thz_psf_kind */
    const load_range diameter = {LOAD_MIN_APERTURE_DIAMETER_M, LOAD_MAX_APERTURE_DIAMETER_M, false,
                                 false};
    thz_status st =
        load_number(ctx, c, "aperture_diameter_m", diameter, false, 0.0, &sn->aperture_diameter_m);
    if (st != THZ_OK)
        return st;
    double circle_m2 = M_PI * sn->aperture_diameter_m * sn->aperture_diameter_m / 4.0;
    if (sn->aperture_diameter_m > 0.0 && !json_object_get(c->value, "aperture_m2"))
        sn->aperture_m2 = circle_m2;
    /* an area no circular aperture of that diameter has: the power then collects through
     * one aperture and the diffraction PSF spreads it as another (up to a thousandth over:
     * the circle's area rounded up to four digits, 0.007854 for D = 0.1 m) */
    if (sn->aperture_diameter_m > 0.0 && sn->aperture_m2 > circle_m2 * (1.0 + 1e-3) &&
        !scene_add_warning(ctx->scene,
                           "%s.aperture_m2: %.6g m^2 is more than a circular aperture of "
                           "aperture_diameter_m %.6g m can have (pi D^2 / 4 = %.6g m^2): the "
                           "power is collected over the one and the diffraction PSF is that "
                           "of the other; give one of them, or both of one aperture",
                           c->path, sn->aperture_m2, sn->aperture_diameter_m, circle_m2))
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    size_t psf = sn->aperture_diameter_m > 0.0 ? PSF_AIRY : PSF_NONE;
    st = load_choice(ctx, c, "psf", psfs, false, psf, &psf);
    if (st != THZ_OK)
        return st;
    sn->psf = (thz_psf_kind)psf;
    load_cursor p = load_key(c, "psf");
    load_cursor fwhm = load_key(c, "psf_fwhm_deg");
    if (sn->psf == PSF_AIRY && !(sn->aperture_diameter_m > 0.0))
        return load_fail(ctx, &p,
                         "\"airy\" needs the aperture: give aperture_diameter_m (m), or choose "
                         "\"gaussian\" with psf_fwhm_deg, or \"none\"");
    if (sn->psf == PSF_GAUSSIAN) {
        const load_range deg = {0.0, 180.0, true, true};
        st = load_number(ctx, c, "psf_fwhm_deg", deg, true, 0.0, &sn->psf_fwhm_deg);
        if (st != THZ_OK)
            return st;
    } else if (fwhm.value) {
        return load_fail(ctx, &fwhm,
                         "psf_fwhm_deg is for \"psf\": \"gaussian\" only (the PSF "
                         "here is \"%s\")",
                         psfs[psf]);
    }
    st = load_noise(ctx, c, n_channels, &sn->noise);
    if (st != THZ_OK)
        return st;
    load_cursor seed = load_key(c, "noise_seed");
    sn->noise_seed_given = seed.value != NULL;
    return load_integer(ctx, c, "noise_seed", 0, INT64_MAX, false, 0, &sn->noise_seed);
}
