/* thzmap atmosphere: alpha(nu) of an atmosphere model as CSV, and optionally a
 * PLplot figure (attenuation in dB/km on a log axis against frequency in THz, with
 * the channels of a scene marked). */
#include <errno.h>
#include <float.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdbool.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cli.h"
#include "progress.h"
#include "thzmap/thzmap.h"

#define CMD "atmosphere"
#define MAX_POINTS 10000000.0

/* alpha in 1/m as dB/km. */
static double db_per_km(double alpha_per_m)
{
    return alpha_per_m * (THZ_NEPER_TO_DB * 1e3);
}

static void print_help(void)
{
    printf("usage: thzmap atmosphere --from-thz F1 --to-thz F2 --step-ghz S [options]\n"
           "\n"
           "Prints the atmosphere's attenuation alpha against frequency as CSV on standard\n"
           "output: frequency_thz, attenuation_per_m (1/m), attenuation_db_per_km, the parts\n"
           "per species in dB/km, and transmittance with --distance-m.\n"
           "\n"
           "options:\n"
           "  --from-thz F1, --to-thz F2   frequency range in THz, both ends included\n"
           "  --step-ghz S                 frequency step in GHz\n"
           "  --model M                    lines (default), itu-p676 (1-1000 GHz), none\n"
           "  --temperature-k T            air temperature in K, 100-400 (default 288.15)\n"
           "  --pressure-hpa P             total pressure (dry air + water vapour) in hPa,\n"
           "                               above 0, at most 2000 (default 1013.25)\n"
           "  --relative-humidity RH       0..1 over liquid water (ITU-R P.453-14), or\n"
           "  --water-vapour-g-m3 RHO      water-vapour density in g/m^3 (default 7.5), or\n"
           "  --h2o-vmr X                  water-vapour volume mixing ratio (of total air)\n"
           "  --h2o-lines FILE             lines: H2O catalogue (am CSV or HITRAN .par)\n"
           "  --o2-lines FILE              lines: uncoupled O2 catalogue (am CSV or .par)\n"
           "  --no-continuum               lines: no MT_CKD continuum (full H2O line wings)\n"
           "                               (these three apply to --model or --compare-model\n"
           "                               lines; refused when neither is)\n"
           "  --distance-m D               add the transmittance exp(-alpha D) of a D m path\n"
           "  --plot FILE.png              also draw alpha in dB/km against THz (PLplot)\n"
           "  --compare-model M            plot: overlay model M's total (same air, also\n"
           "                               the scene's)\n"
           "  --scene SCENE.json           plot: mark the scene's channels; without --model\n"
           "                               and air options, use the scene's atmosphere\n"
           "  -h, --help                   this help\n");
}

typedef struct options {
    double from_thz, to_thz, step_ghz;
    bool have_from, have_to, have_step;
    const char *model;
    const char *compare_model;
    double temperature_k, pressure_hpa;
    thz_humidity_kind humidity_kind;
    double humidity;
    int n_humidity;
    bool air_given;
    const char *h2o_lines, *o2_lines;
    bool no_continuum;
    double distance_m;
    bool have_distance;
    const char *plot;
    const char *scene;
} options;

static int parse_options(int argc, char **argv, options *o, bool *help)
{
    memset(o, 0, sizeof *o);
    o->temperature_k = 288.15;
    o->pressure_hpa = 1013.25;
    o->humidity_kind = THZ_HUMIDITY_DENSITY_G_M3;
    o->humidity = 7.5;
    *help = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (cli_is_help(a)) {
            *help = true;
            return CLI_EXIT_OK;
        }
        if (strcmp(a, "--no-continuum") == 0) {
            o->no_continuum = true;
            continue;
        }
        static const char *const with_value[] = {
            "--from-thz",          "--to-thz",        "--step-ghz",     "--model",
            "--compare-model",     "--temperature-k", "--pressure-hpa", "--relative-humidity",
            "--water-vapour-g-m3", "--h2o-vmr",       "--h2o-lines",    "--o2-lines",
            "--distance-m",        "--plot",          "--scene",        NULL};
        char *v = NULL;
        int rc = cli_option_value(CMD, argc, argv, &i, with_value, &v);
        if (rc >= 0)
            return rc;
        if (strcmp(a, "--from-thz") == 0) {
            if (!cli_parse_positive(CMD, a, v, 1000.0, &o->from_thz))
                return CLI_EXIT_USAGE;
            o->have_from = true;
        } else if (strcmp(a, "--to-thz") == 0) {
            if (!cli_parse_positive(CMD, a, v, 1000.0, &o->to_thz))
                return CLI_EXIT_USAGE;
            o->have_to = true;
        } else if (strcmp(a, "--step-ghz") == 0) {
            if (!cli_parse_positive(CMD, a, v, 1e6, &o->step_ghz))
                return CLI_EXIT_USAGE;
            o->have_step = true;
        } else if (strcmp(a, "--model") == 0) {
            o->model = v;
        } else if (strcmp(a, "--compare-model") == 0) {
            o->compare_model = v;
        } else if (strcmp(a, "--temperature-k") == 0) {
            if (!cli_parse_double(CMD, a, v, THZ_AIR_MIN_TEMPERATURE_K, THZ_AIR_MAX_TEMPERATURE_K,
                                  &o->temperature_k))
                return CLI_EXIT_USAGE;
            o->air_given = true;
        } else if (strcmp(a, "--pressure-hpa") == 0) {
            if (!cli_parse_positive(CMD, a, v, THZ_AIR_MAX_PRESSURE_HPA, &o->pressure_hpa))
                return CLI_EXIT_USAGE;
            o->air_given = true;
        } else if (strcmp(a, "--relative-humidity") == 0 || strcmp(a, "--water-vapour-g-m3") == 0 ||
                   strcmp(a, "--h2o-vmr") == 0) {
            /* any number: the air model says the range of each kind */
            if (!cli_parse_double(CMD, a, v, -DBL_MAX, DBL_MAX, &o->humidity))
                return CLI_EXIT_USAGE;
            o->humidity_kind = a[2] == 'r'   ? THZ_HUMIDITY_RELATIVE
                               : a[2] == 'w' ? THZ_HUMIDITY_DENSITY_G_M3
                                             : THZ_HUMIDITY_VMR;
            o->n_humidity++;
            o->air_given = true;
        } else if (strcmp(a, "--h2o-lines") == 0) {
            o->h2o_lines = v;
        } else if (strcmp(a, "--o2-lines") == 0) {
            o->o2_lines = v;
        } else if (strcmp(a, "--distance-m") == 0) {
            if (!cli_parse_double(CMD, a, v, 0.0, 1e9, &o->distance_m))
                return CLI_EXIT_USAGE;
            o->have_distance = true;
        } else if (strcmp(a, "--plot") == 0) {
            o->plot = v;
        } else if (strcmp(a, "--scene") == 0) {
            o->scene = v;
        } else {
            return cli_usage_error(CMD, "unknown option '%s'", a);
        }
    }
    if (!o->have_from || !o->have_to || !o->have_step)
        return cli_usage_error(CMD, "--from-thz, --to-thz and --step-ghz are required");
    if (!(o->to_thz >= o->from_thz))
        return cli_usage_error(CMD, "--to-thz (%g THz) must not be below --from-thz (%g THz)",
                               o->to_thz, o->from_thz);
    if (o->n_humidity > 1)
        return cli_usage_error(CMD, "give only one of --relative-humidity, --water-vapour-g-m3, "
                                    "--h2o-vmr");
    if ((o->to_thz - o->from_thz) * 1e3 / o->step_ghz + 1.0 > MAX_POINTS)
        return cli_usage_error(CMD, "more than %.0f frequencies; raise --step-ghz", MAX_POINTS);
    if (o->compare_model && !o->plot)
        return cli_usage_error(CMD, "--compare-model needs --plot");
    size_t len = o->plot ? strlen(o->plot) : 0;
    if (o->plot && (len < 5 || strcasecmp(o->plot + len - 4, ".png") != 0))
        return cli_usage_error(CMD, "--plot expects a file name ending in .png, got '%s'", o->plot);
    return CLI_EXIT_OK;
}

/* The file beside `plot` the figure is drawn into; false when the name does not fit
 * (then partial is ""). */
static bool plot_partial_name(const char *plot, char *partial, size_t size)
{
    int n = snprintf(partial, size, "%s.%ld.partial.png", plot, (long)getpid());
    if (n < 0 || (size_t)n >= size) {
        partial[0] = '\0';
        return false;
    }
    return true;
}

/* Draws the figure into a file beside plot->path and renames it over that: a failure
 * leaves the file that was there (or none). Signals wait until the figure is whole or
 * gone, so that none leaves the partial file behind. */
static thz_status draw_plot_whole(const thz_atm_plot *plot, thz_error *err)
{
    char partial[4096];
    if (!plot_partial_name(plot->path, partial, sizeof partial)) {
        err->status = THZ_ERR_INPUT;
        snprintf(err->message, sizeof err->message, "--plot %s: the name is too long", plot->path);
        return err->status;
    }
    sigset_t before;
    cli_signals_hold(&before);
    thz_atm_plot into = *plot;
    into.path = partial;
    thz_status st = thz_atm_draw_plot(&into, err);
    char *at = st != THZ_OK ? strstr(err->message, partial) : NULL;
    if (at) { /* the message names the figure, not the file it was drawn into */
        char said[sizeof err->message];
        snprintf(said, sizeof said, "%.*s%s%s", (int)(at - err->message), err->message, plot->path,
                 at + strlen(partial));
        snprintf(err->message, sizeof err->message, "%s", said);
    }
    if (st == THZ_OK && rename(partial, plot->path) != 0) {
        err->status = st = THZ_ERR_IO;
        snprintf(err->message, sizeof err->message, "--plot %s: cannot replace: %s", plot->path,
                 strerror(errno));
    }
    if (st != THZ_OK)
        unlink(partial);
    cli_signals_release(&before);
    return st;
}

static const char *humidity_option(thz_humidity_kind kind)
{
    switch (kind) {
    case THZ_HUMIDITY_RELATIVE:
        return "--relative-humidity";
    case THZ_HUMIDITY_VMR:
        return "--h2o-vmr";
    case THZ_HUMIDITY_DRY:
    case THZ_HUMIDITY_DENSITY_G_M3:
        break;
    }
    return "--water-vapour-g-m3";
}

/* Builds the atmosphere `name` from the options (catalogues) in the air of `air_from`
 * when it has one, or else in the air of the options (their values are then named in an
 * error about the air). */
static thz_status build_model(const options *o, const char *name, const thz_atm *air_from,
                              thz_atm **out, thz_error *err)
{
    thz_atm_options ao;
    thz_atm_options_init(&ao);
    ao.model = name;
    ao.temperature_k = o->temperature_k;
    ao.pressure_hpa = o->pressure_hpa;
    ao.humidity_kind = o->humidity_kind;
    ao.humidity = o->humidity;
    ao.h2o_lines_file = o->h2o_lines;
    ao.o2_lines_file = o->o2_lines;
    ao.no_continuum = o->no_continuum;
    thz_atm_info from = {0};
    if (air_from)
        thz_atm_get_info(air_from, &from);
    bool needs_air = strcmp(name, "lines") == 0 || strcmp(name, "itu-p676") == 0;
    if (needs_air && !from.has_air && thz_atm_check_air(&ao, err) != THZ_OK) {
        char message[sizeof err->message];
        int n = snprintf(message, sizeof message,
                         "--temperature-k %g, --pressure-hpa %g, %s %g: ", o->temperature_k,
                         o->pressure_hpa, humidity_option(o->humidity_kind), o->humidity);
        size_t used = n > 0 && (size_t)n < sizeof message ? (size_t)n : 0;
        size_t rest = strnlen(err->message, sizeof message - 1 - used);
        memcpy(message + used, err->message, rest); /* as thz_error_prefix cuts */
        message[used + rest] = '\0';
        memcpy(err->message, message, sizeof message);
        return err->status;
    }
    return thz_atm_create(&ao, air_from, out, err);
}

typedef struct series {
    size_t n;
    double *f_thz, *alpha_per_m;
    double *total_db, *h2o_lines_db, *h2o_cont_db, *o2_db, *dry_db, *compare_db;
} series;

static void series_fini(series *s)
{
    free(s->f_thz);
    free(s->alpha_per_m);
    free(s->total_db);
    free(s->h2o_lines_db);
    free(s->h2o_cont_db);
    free(s->o2_db);
    free(s->dry_db);
    free(s->compare_db);
}

static double *series_array(size_t n)
{
    return n <= SIZE_MAX / sizeof(double) ? malloc(n * sizeof(double)) : NULL;
}

int cmd_atmosphere(int argc, char **argv)
{
    options o;
    bool help;
    int rc = parse_options(argc, argv, &o, &help);
    if (rc != CLI_EXIT_OK || help) {
        if (help)
            print_help();
        return rc;
    }
    thz_error err = {0};
    thz_scene *scene = NULL;
    thz_atm *atm = NULL, *compare = NULL;
    const char *model_name = o.model ? o.model : "lines";
    series s = {0};
    FILE *out = stdout;
    if (o.scene && thz_scene_load(o.scene, &scene, &err) != THZ_OK) {
        rc = cli_fail(&err);
        goto cleanup;
    }
    bool from_scene = scene && !o.model && !o.air_given;
    bool lines_options = o.h2o_lines || o.o2_lines || o.no_continuum;
    if (lines_options && (from_scene || strcmp(model_name, "lines") != 0) &&
        !(o.compare_model && strcmp(o.compare_model, "lines") == 0)) {
        rc = cli_usage_error(CMD,
                             "--h2o-lines, --o2-lines and --no-continuum apply to a lines model "
                             "built from the options (--model lines or --compare-model lines)%s",
                             from_scene ? "; the scene's atmosphere is used as its file sets it"
                                        : "");
        goto cleanup;
    }
    if (o.air_given && !strcmp(model_name, "none") &&
        !(o.compare_model && strcmp(o.compare_model, "none") != 0)) {
        rc = cli_usage_error(CMD, "--temperature-k, --pressure-hpa and the humidity options "
                                  "describe the air of a lines or itu-p676 model; --model none "
                                  "has no air");
        goto cleanup;
    }
    if (from_scene ? thz_atm_from_scene(scene, &atm, &err) != THZ_OK
                   : build_model(&o, model_name, NULL, &atm, &err) != THZ_OK) {
        rc = cli_fail(&err);
        goto cleanup;
    }
    thz_atm_info info;
    thz_atm_get_info(atm, &info);
    if (from_scene)
        model_name = info.model;
    /* The comparison is computed in the same air: the scene's when that is used. */
    if (o.compare_model && build_model(&o, o.compare_model, atm, &compare, &err) != THZ_OK) {
        rc = cli_fail(&err);
        goto cleanup;
    }
    double lo_hz = o.from_thz * 1e12, hi_hz = o.to_thz * 1e12;
    if (thz_atm_check_range(atm, lo_hz, hi_hz, "--from-thz/--to-thz", &err) != THZ_OK ||
        (o.compare_model &&
         thz_atm_check_range(compare, lo_hz, hi_hz, "--from-thz/--to-thz", &err) != THZ_OK)) {
        rc = cli_fail(&err);
        goto cleanup;
    }

    /* The figure's device and file are checked before the work: a missing device or
     * an unwritable path fails at once, with nothing printed. */
    if (o.plot) {
        if (thz_plot_check(&err) != THZ_OK) {
            rc = cli_fail(&err);
            goto cleanup;
        }
        /* opened to append, not "wb": that emptied an existing figure before the work,
         * and a run stopped or failing before the plot left it 0 bytes; a new file made
         * for the check goes again until the plot writes it */
        bool existed = access(o.plot, F_OK) == 0;
        FILE *f = fopen(o.plot, "ab");
        if (!f) {
            err.status = THZ_ERR_INPUT;
            snprintf(err.message, sizeof err.message, "--plot %s: cannot create: %s", o.plot,
                     strerror(errno));
            rc = cli_fail(&err);
            goto cleanup;
        }
        fclose(f);
        if (!existed)
            unlink(o.plot);
        /* and the file the figure is drawn into beside it (draw_plot_whole) */
        char partial[4096];
        int fd = -1;
        if (plot_partial_name(o.plot, partial, sizeof partial))
            fd = open(partial, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd < 0) {
            err.status = THZ_ERR_INPUT;
            snprintf(err.message, sizeof err.message,
                     "--plot %s: cannot create a file beside it (the figure is drawn there, "
                     "then renamed): %s",
                     o.plot, partial[0] ? strerror(errno) : "the name is too long");
            rc = cli_fail(&err);
            goto cleanup;
        }
        close(fd);
        unlink(partial);
    }

    double step_thz = o.step_ghz * 1e-3;
    size_t n = (size_t)floor((o.to_thz - o.from_thz) / step_thz * (1.0 + 1e-12)) + 1;
    bool add_end = o.from_thz + (double)(n - 1) * step_thz < o.to_thz * (1.0 - 1e-12);
    s.n = n + (add_end ? 1 : 0);
    s.f_thz = series_array(s.n);
    s.alpha_per_m = series_array(s.n);
    s.total_db = series_array(s.n);
    s.h2o_lines_db = series_array(s.n);
    s.h2o_cont_db = series_array(s.n);
    s.o2_db = series_array(s.n);
    s.dry_db = series_array(s.n);
    if (o.compare_model)
        s.compare_db = series_array(s.n);
    if (!s.f_thz || !s.alpha_per_m || !s.total_db || !s.h2o_lines_db || !s.h2o_cont_db ||
        !s.o2_db || !s.dry_db || (o.compare_model && !s.compare_db)) {
        fprintf(stderr, "thzmap atmosphere: out of memory\n");
        rc = CLI_EXIT_FAILURE;
        goto cleanup;
    }

    for (size_t i = 0; i < s.n; i++) { /* all first: nothing is printed for a bad input */
        double f_thz = i < n ? o.from_thz + (double)i * step_thz : o.to_thz;
        double f_hz = f_thz * 1e12;
        thz_atm_attenuation p;
        thz_atm_attenuation_parts(atm, f_hz, &p);
        double other = compare ? thz_atm_attenuation_per_m(compare, f_hz) : 0.0;
        if (!isfinite(p.total_per_m) || !isfinite(other)) {
            bool mine = !isfinite(p.total_per_m);
            fprintf(stderr,
                    "thzmap atmosphere: the attenuation%s at %.9g THz is not a finite number "
                    "(%g /m); a line catalogue with values beyond the physical range?\n",
                    mine ? "" : " of --compare-model", f_thz, mine ? p.total_per_m : other);
            rc = CLI_EXIT_USAGE; /* nothing printed or drawn: a figure there stays */
            goto cleanup;
        }
        s.f_thz[i] = f_thz;
        s.alpha_per_m[i] = p.total_per_m;
        s.total_db[i] = db_per_km(p.total_per_m);
        s.h2o_lines_db[i] = db_per_km(p.h2o_lines_per_m);
        s.h2o_cont_db[i] = db_per_km(p.h2o_continuum_per_m);
        s.o2_db[i] = db_per_km(p.o2_per_m);
        s.dry_db[i] = db_per_km(p.dry_continuum_per_m);
        if (s.compare_db)
            s.compare_db[i] = db_per_km(other);
    }
    if (info.has_air)
        fprintf(out,
                "# thzmap atmosphere: model %s; air %.2f K, %.2f hPa total, water vapour %.4g hPa "
                "(%.4g g/m^3, volume mixing ratio %.4g)",
                model_name, info.temperature_k, info.pressure_hpa, info.h2o_pressure_hpa,
                info.h2o_density_g_m3, info.h2o_vmr);
    else
        fprintf(out, "# thzmap atmosphere: model %s", model_name);
    if (o.have_distance) /* what the transmittance column is of */
        fprintf(out, "; transmittance over a path of %.9g m", o.distance_m);
    fprintf(out, "\n");
    fprintf(out, "frequency_thz,attenuation_per_m,attenuation_db_per_km");
    bool lines = strcmp(info.model, "lines") == 0, itu = strcmp(info.model, "itu-p676") == 0;
    if (lines)
        fprintf(out, ",h2o_lines_db_per_km,h2o_continuum_db_per_km,o2_db_per_km,"
                     "dry_continuum_db_per_km");
    else if (itu)
        fprintf(out, ",h2o_db_per_km,o2_db_per_km,dry_continuum_db_per_km");
    if (o.have_distance)
        fprintf(out, ",transmittance");
    fprintf(out, "\n");

    for (size_t i = 0; i < s.n; i++) {
        double f_thz = s.f_thz[i], alpha = s.alpha_per_m[i];
        fprintf(out, "%.9g,%.6e,%.6e", f_thz, alpha, s.total_db[i]);
        if (lines)
            fprintf(out, ",%.6e,%.6e,%.6e,%.6e", s.h2o_lines_db[i], s.h2o_cont_db[i], s.o2_db[i],
                    s.dry_db[i]);
        else if (itu)
            fprintf(out, ",%.6e,%.6e,%.6e", s.h2o_lines_db[i], s.o2_db[i], s.dry_db[i]);
        if (o.have_distance)
            fprintf(out, ",%.6e", exp(-alpha * o.distance_m));
        fprintf(out, "\n");
    }
    if (fflush(out) != 0 || ferror(out)) {
        fprintf(stderr, "thzmap atmosphere: error writing standard output\n");
        rc = CLI_EXIT_FAILURE;
        goto cleanup;
    }
    if (o.plot) {
        thz_atm_plot plot = {.path = o.plot,
                             .atm = atm,
                             .model_name = model_name,
                             .compare = compare,
                             .compare_name = o.compare_model,
                             .scene = scene,
                             .n = s.n,
                             .f_thz = s.f_thz,
                             .total_db = s.total_db,
                             .h2o_lines_db = s.h2o_lines_db,
                             .h2o_continuum_db = s.h2o_cont_db,
                             .o2_db = s.o2_db,
                             .dry_db = s.dry_db,
                             .compare_db = s.compare_db};
        if (draw_plot_whole(&plot, &err) != THZ_OK)
            rc = cli_fail(&err);
    }
cleanup:
    series_fini(&s);
    thz_atm_destroy(atm);
    thz_atm_destroy(compare);
    thz_scene_destroy(scene);
    return rc;
}
