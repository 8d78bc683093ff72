/* Atmosphere models through the public API (`thzmap atmosphere`): a model made from
 * options or borrowed from a scene, its attenuation, and its figure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "atmosphere/atmosphere.h"
#include "core/alloc.h"
#include "io/plot.h"

/* The public limits repeat the module's (whole numbers: a cast of a floating constant is
 * an integer constant expression); THZ_NEPER_TO_DB is ATM_NEPER_TO_DB's literal. */
_Static_assert((long)THZ_AIR_MIN_TEMPERATURE_K == (long)ATM_AIR_MIN_TEMPERATURE_K &&
                   (long)THZ_AIR_MAX_TEMPERATURE_K == (long)ATM_AIR_MAX_TEMPERATURE_K &&
                   (long)THZ_AIR_MAX_PRESSURE_HPA == (long)ATM_AIR_MAX_PRESSURE_HPA,
               "the public air limits must be the atmosphere module's");

struct thz_atm {
    thz_atmosphere own;
    const thz_atmosphere *atm; /* &own, or a scene's */
};

static atm_humidity_kind api_humidity_kind(thz_humidity_kind kind)
{
    switch (kind) {
    case THZ_HUMIDITY_RELATIVE:
        return ATM_HUMIDITY_RELATIVE;
    case THZ_HUMIDITY_DENSITY_G_M3:
        return ATM_HUMIDITY_DENSITY_G_M3;
    case THZ_HUMIDITY_VMR:
        return ATM_HUMIDITY_VMR;
    case THZ_HUMIDITY_DRY:
        break;
    }
    return ATM_HUMIDITY_NONE;
}

/* A humidity kind the enum does not have is refused (it gave dry air silently). */
static thz_status api_humidity_check(const thz_atm_options *opt, const char *fn, thz_error *err)
{
    int kind = (int)opt->humidity_kind; /* an enum may be unsigned: compare ints */
    if (kind < (int)THZ_HUMIDITY_DRY || kind > (int)THZ_HUMIDITY_VMR)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: humidity_kind %d: expected THZ_HUMIDITY_DRY, _RELATIVE, "
                             "_DENSITY_G_M3 or _VMR",
                             fn, kind);
    return THZ_OK;
}

void thz_atm_options_init(thz_atm_options *opt)
{
    if (!opt)
        return;
    *opt = (thz_atm_options){.model = "lines",
                             .temperature_k = 288.15,
                             .pressure_hpa = 1013.25,
                             .humidity_kind = THZ_HUMIDITY_DENSITY_G_M3,
                             .humidity = 7.5};
}

thz_status thz_atm_check_air(const thz_atm_options *opt, thz_error *err)
{
    if (!opt)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_check_air: no options");
    thz_status checked = api_humidity_check(opt, "thz_atm_check_air", err);
    if (checked != THZ_OK)
        return checked;
    atm_air_state air;
    return atm_air_state_init(&air, opt->temperature_k, opt->pressure_hpa,
                              api_humidity_kind(opt->humidity_kind), opt->humidity, err);
}

thz_status thz_atm_create(const thz_atm_options *opt, const thz_atm *air_from, thz_atm **out,
                          thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_create: no place for the atmosphere");
    *out = NULL;
    if (!opt)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_atm_create: no options (thz_atm_options_init gives the "
                             "defaults)");
    thz_status checked = api_humidity_check(opt, "thz_atm_create", err);
    if (checked != THZ_OK)
        return checked;
    const char *name = opt->model ? opt->model : "lines";
    atm_model model;
    if (!atmosphere_model_from_name(name, &model) ||
        (model != ATM_LINES && model != ATM_ITU_P676 && model != ATM_NONE))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "atmosphere: unknown model '%s' (expected lines, itu-p676 or none; "
                             "constant and table come from a scene)",
                             name);
    thz_atm *a = thz_calloc(1, sizeof *a);
    if (!a)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    a->atm = &a->own;
    thz_status st = THZ_OK;
    if (model != ATM_NONE) {
        atm_air_state own_air;
        const atm_air_state *air = air_from && air_from->atm->has_air ? &air_from->atm->air : NULL;
        if (!air) {
            st = atm_air_state_init(&own_air, opt->temperature_k, opt->pressure_hpa,
                                    api_humidity_kind(opt->humidity_kind), opt->humidity, err);
            air = &own_air;
        }
        if (st == THZ_OK && model == ATM_ITU_P676) {
            st = atmosphere_init_itu_p676(&a->own, air, NULL, err);
        } else if (st == THZ_OK) {
            atm_lines_options lo;
            atmosphere_lines_options_default(&lo);
            lo.h2o_lines_file = opt->h2o_lines_file;
            lo.o2_lines_file = opt->o2_lines_file;
            lo.continuum = !opt->no_continuum;
            st = atmosphere_init_lines(&a->own, air, &lo, err);
        }
    }
    if (st != THZ_OK) {
        thz_atm_destroy(a);
        return st;
    }
    *out = a;
    return THZ_OK;
}

thz_status thz_atm_from_scene(const thz_scene *scene, thz_atm **out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_from_scene: no place for the atmosphere");
    *out = NULL;
    if (!scene)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_from_scene: no scene");
    thz_atm *a = thz_calloc(1, sizeof *a);
    if (!a)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    a->atm = &scene->atmosphere;
    *out = a;
    return THZ_OK;
}

void thz_atm_destroy(thz_atm *a)
{
    if (!a)
        return;
    atmosphere_fini(&a->own); /* a scene's is the scene's */
    free(a);
}

void thz_atm_get_info(const thz_atm *a, thz_atm_info *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!a)
        return;
    const thz_atmosphere *atm = a->atm;
    out->model = atmosphere_model_name(atm->model);
    if (atm->emitting && atm->model != ATM_NONE) {
        out->emitting = 1;
        out->emission_temperature_k = atm->air.temperature_k;
        out->background_temperature_k = atm->background_temperature_k;
    }
    if (!atm->has_air)
        return;
    out->has_air = 1;
    out->temperature_k = atm->air.temperature_k;
    out->pressure_hpa = atm->air.pressure_hpa;
    out->h2o_pressure_hpa = atm->air.h2o_pressure_hpa;
    out->h2o_density_g_m3 = atm_air_h2o_density_g_m3(&atm->air);
    out->h2o_vmr = atm_air_h2o_vmr(&atm->air);
}

thz_status thz_atm_check_range(const thz_atm *a, double lo_hz, double hi_hz, const char *what,
                               thz_error *err)
{
    if (!a)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_check_range: no atmosphere");
    return atmosphere_check_range(a->atm, lo_hz, hi_hz, what ? what : "range", err);
}

void thz_atm_attenuation_parts(const thz_atm *a, double freq_hz, thz_atm_attenuation *out)
{
    if (!out)
        return;
    if (!a || !isfinite(freq_hz) || !(freq_hz >= 0.0)) {
        *out = (thz_atm_attenuation){NAN, NAN, NAN, NAN, NAN};
        return;
    }
    atm_alpha_parts p;
    atmosphere_alpha_parts(a->atm, freq_hz, &p);
    *out = (thz_atm_attenuation){.total_per_m = atmosphere_alpha_parts_sum(&p),
                                 .h2o_lines_per_m = p.h2o_lines_per_m,
                                 .h2o_continuum_per_m = p.h2o_continuum_per_m,
                                 .o2_per_m = p.o2_per_m,
                                 .dry_continuum_per_m = p.dry_continuum_per_m};
}

double thz_atm_attenuation_per_m(const thz_atm *a, double freq_hz)
{
    if (!a || !isfinite(freq_hz) || !(freq_hz >= 0.0))
        return NAN;
    return atmosphere_alpha_direct_per_m(a->atm, freq_hz);
}

thz_status thz_plot_check(thz_error *err)
{
    return plot_check_device(err);
}

/* THZ_ERR_INPUT unless the figure has a path, an atmosphere, n > 0 points and every
 * curve it draws for that atmosphere's model. */
static thz_status api_plot_check(const thz_atm_plot *d, thz_error *err)
{
    if (!d || !d->atm)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_draw_plot: no %s",
                             d ? "atmosphere" : "figure");
    if (!d->path || !d->path[0])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_atm_draw_plot: no path for the PNG file");
    if (d->n == 0)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_atm_draw_plot: no points (expected n > 0 frequencies)");
    atm_model model = d->atm->atm->model;
    bool lines = model == ATM_LINES, parts = lines || model == ATM_ITU_P676;
    const char *missing = !d->f_thz                       ? "f_thz"
                          : !d->total_db                  ? "total_db"
                          : parts && !d->h2o_lines_db     ? "h2o_lines_db"
                          : lines && !d->h2o_continuum_db ? "h2o_continuum_db"
                          : parts && !d->o2_db            ? "o2_db"
                          : parts && !d->dry_db           ? "dry_db"
                                                          : NULL;
    if (missing)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_atm_draw_plot: %s is NULL (expected %zu values for model '%s')",
                             missing, d->n, atmosphere_model_name(model));
    return THZ_OK;
}

thz_status thz_atm_draw_plot(const thz_atm_plot *d, thz_error *err)
{
    thz_status checked = api_plot_check(d, err);
    if (checked != THZ_OK)
        return checked;
    const thz_atmosphere *atm = d->atm->atm;
    const thz_atmosphere *compare = d->compare ? d->compare->atm : NULL;
    /* names the caller left NULL: the models' own */
    const char *model_name = d->model_name ? d->model_name : atmosphere_model_name(atm->model);
    const char *compare_name = d->compare_name ? d->compare_name
                               : compare       ? atmosphere_model_name(compare->model)
                                               : "comparison";
    plot_curve curves[6];
    size_t n = 0;
    if (atm->model == ATM_LINES || atm->model == ATM_ITU_P676) {
        curves[n++] = (plot_curve){atm->model == ATM_LINES ? "H#d2#uO lines" : "H#d2#uO",
                                   d->h2o_lines_db,
                                   {31, 119, 180},
                                   1.0,
                                   false};
        if (atm->model == ATM_LINES)
            curves[n++] = (plot_curve){
                "H#d2#uO continuum (MT_CKD)", d->h2o_continuum_db, {44, 160, 44}, 1.0, false};
        curves[n++] = (plot_curve){"O#d2#u", d->o2_db, {214, 39, 40}, 1.0, false};
        curves[n++] = (plot_curve){"dry-air continuum", d->dry_db, {148, 103, 189}, 1.0, false};
    }
    char total_text[96], compare_text[96];
    snprintf(total_text, sizeof total_text, "total, %s", model_name);
    curves[n++] = (plot_curve){total_text, d->total_db, {0, 0, 0}, 2.0, false};
    if (d->compare_db) {
        snprintf(compare_text, sizeof compare_text, "total, %s", compare_name);
        curves[n++] = (plot_curve){compare_text, d->compare_db, {255, 127, 14}, 2.0, true};
    }

    const thz_scene *scene = d->scene;
    size_t n_bands = scene ? scene->n_channels : 0;
    plot_band *bands = thz_calloc(n_bands ? n_bands : 1, sizeof *bands);
    if (!bands)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    for (size_t c = 0; c < n_bands; c++) {
        const thz_channel *ch = &scene->channels[c];
        double fc = ch->center_hz * 1e-12, lo, hi;
        if (channel_has_response(ch)) {
            channel_support_hz(ch, 0.0, &lo, &hi); /* where the measured response is > 0 */
            lo *= 1e-12;
            hi *= 1e-12;
        } else {
            double half = 0.5 * channel_fwhm_hz(ch) * 1e-12;
            lo = fc - half;
            hi = fc + half;
        }
        bands[c] = (plot_band){ch->name, lo, fc, hi};
    }

    /* The air in the title: the model's, or else the comparison's. */
    char title[256];
    const thz_atmosphere *with_air = atm->has_air                    ? atm
                                     : (compare && compare->has_air) ? compare
                                                                     : NULL;
    const atm_air_state *air = with_air ? &with_air->air : NULL;
    if (with_air == atm)
        snprintf(title, sizeof title,
                 "atmosphere '%s': %.2f K, %.6g hPa, water vapour %.2f g/m\u00b3", model_name,
                 air->temperature_k, air->pressure_hpa, atm_air_h2o_density_g_m3(air));
    else if (with_air)
        snprintf(title, sizeof title,
                 "atmosphere '%s'; %s air: %.2f K, %.6g hPa, %.2f g/m\u00b3 vapour", model_name,
                 compare_name, air->temperature_k, air->pressure_hpa,
                 atm_air_h2o_density_g_m3(air));
    else
        snprintf(title, sizeof title, "atmosphere '%s'", model_name);
    thz_status st = plot_attenuation(d->path, d->n, d->f_thz, n, curves, n_bands, bands, title,
                                     "frequency (THz)", "attenuation (dB/km)", err);
    free(bands);
    return st;
}
