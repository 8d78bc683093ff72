/* simulate and render: options, scene, run, report. */
#include "cli/run_command.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/progress.h"
#include "core/clock.h"
#include "run/run.h"
#include "scene/scene.h"
#include "sensor/render.h"

static void cli_run_usage(FILE *f, bool render)
{
    if (!render)
        fprintf(f, "usage: thzmap simulate SCENE.json -o OUTDIR [options]\n\n"
                   "Fires photons and renders every sensor of the scene; writes the images,\n"
                   "previews and summary.json into OUTDIR (created if missing).\n\n"
                   "options:\n"
                   "  -o, --output OUTDIR   where the results go (required)\n"
                   "  --photons N           photons per channel (overrides photons.per_channel;\n"
                   "                        1e6 is accepted)\n"
                   "  --seed S              random seed (overrides photons.seed)\n"
                   "  --threads T           threads to use (default: all cores)\n"
                   "  --integrator NAME     path (default) | final-gather | photon-map\n"
                   "                        (overrides render.integrator; path fires no\n"
                   "                        photons; photon-map is the paper's method)\n"
                   "  --target-noise-k X    add passes to each channel until the 95th\n"
                   "                        percentile over pixels of the per-pixel standard\n"
                   "                        error of the brightness temperature is at most\n"
                   "                        X K: of gather rays (final-gather), paths (path),\n"
                   "                        or N more photons (photon-map: rendered from all\n"
                   "                        photons so far); each pass is deterministic.\n"
                   "                        Overrides render.target_noise_k. Default 0.1 K\n"
                   "                        when the scene gives no count (photons.per_channel\n"
                   "                        or --photons; render.paths_per_sample for path)\n"
                   "  --max-seconds S       stop adding passes once a channel has run for S s\n"
                   "                        (overrides render.max_seconds); the stopping\n"
                   "                        point, and so the images, then depend on the\n"
                   "                        machine's speed\n"
                   "  --save-photon-map     also write photon-map.thzpm (for render) and\n"
                   "                        photon-map.ply\n"
                   "  --ply-max-points N    at most N photons (evenly strided) in\n"
                   "                        photon-map.ply (default 2000000)\n"
                   "  --quiet               no progress output (warnings are still printed)\n");
    else
        fprintf(f, "usage: thzmap render SCENE.json --photon-map FILE -o OUTDIR [options]\n\n"
                   "Renders the scene's sensors again from a photon map saved by\n"
                   "'thzmap simulate --save-photon-map', without firing photons.\n\n"
                   "options:\n"
                   "  --photon-map FILE     the photon map (photon-map.thzpm); not needed with\n"
                   "                        --integrator path\n"
                   "  -o, --output OUTDIR   where the results go (required)\n"
                   "  --sensor NAME         render only this sensor (default: all)\n"
                   "  --threads T           threads to use (default: all cores)\n"
                   "  --integrator NAME     path (default) | final-gather | photon-map\n"
                   "  --target-noise-k X    final-gather, path: add passes until the 95th\n"
                   "                        percentile over pixels of the per-pixel standard\n"
                   "                        error of the brightness temperature is at most X K\n"
                   "                        (each pass deterministic; default as in simulate)\n"
                   "  --max-seconds S       stop adding passes once a channel has rendered for\n"
                   "                        S s (time-dependent result)\n"
                   "  --quiet               no progress output (warnings are still printed)\n");
}

typedef struct cli_run_args {
    const char *scene_path;
    bool quiet;
    run_overrides ov;
    run_options opt;
} cli_run_args;

/* Parses argv into args; returns -1 to go on, or the exit status. */
static int cli_run_parse(int argc, char **argv, bool render, cli_run_args *a)
{
    const char *cmd = argv[0];
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (cli_is_help(arg)) {
            cli_run_usage(stdout, render);
            return CLI_EXIT_OK;
        }
        bool takes_value =
            strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0 ||
            strcmp(arg, "--threads") == 0 || strcmp(arg, "--integrator") == 0 ||
            strcmp(arg, "--target-noise-k") == 0 || strcmp(arg, "--max-seconds") == 0 ||
            (!render && (strcmp(arg, "--photons") == 0 || strcmp(arg, "--seed") == 0 ||
                         strcmp(arg, "--ply-max-points") == 0)) ||
            (render && (strcmp(arg, "--photon-map") == 0 || strcmp(arg, "--sensor") == 0));
        if (takes_value) {
            if (i + 1 >= argc)
                return cli_usage_error(cmd, "%s needs a value", arg);
            const char *val = argv[++i];
            if (strncmp(val, "--", 2) == 0) /* -o --quiet: a forgotten value, not a name */
                return cli_usage_error(cmd, "%s needs a value, got the option '%s'", arg, val);
            uint64_t u = 0;
            if (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0) {
                a->opt.outdir = val;
            } else if (strcmp(arg, "--threads") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, 4096, &u))
                    return CLI_EXIT_USAGE;
                a->opt.threads = (int)u;
            } else if (strcmp(arg, "--integrator") == 0) {
                if (!render_integrator_parse(val, &a->ov.integrator))
                    return cli_usage_error(cmd,
                                           "--integrator expects photon-map, final-gather or "
                                           "path, got '%s'",
                                           val);
                a->ov.has_integrator = true;
            } else if (strcmp(arg, "--target-noise-k") == 0 || strcmp(arg, "--max-seconds") == 0) {
                bool target = strcmp(arg, "--target-noise-k") == 0;
                char *end = NULL;
                errno = 0;
                double x = strtod(val, &end);
                if (end == val || *end || errno || !isfinite(x) || !(x > 0.0))
                    return cli_usage_error(cmd, "%s expects a positive number (%s), got '%s'", arg,
                                           target ? "K" : "s", val);
                *(target ? &a->opt.target_noise_k : &a->opt.max_seconds) = x;
            } else if (strcmp(arg, "--photons") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, UINT64_C(1000000000000), &u))
                    return CLI_EXIT_USAGE;
                a->ov.photons = u;
            } else if (strcmp(arg, "--seed") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 0, UINT64_MAX, &u))
                    return CLI_EXIT_USAGE;
                a->ov.has_seed = true;
                a->ov.seed = u;
            } else if (strcmp(arg, "--ply-max-points") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, UINT64_C(1000000000000), &u))
                    return CLI_EXIT_USAGE;
                a->opt.ply_max_points = u;
            } else if (strcmp(arg, "--photon-map") == 0) {
                a->opt.photon_map_path = val;
            } else {
                a->opt.sensor_name = val;
            }
        } else if (strcmp(arg, "--quiet") == 0 || strcmp(arg, "-q") == 0) {
            a->quiet = true;
        } else if (!render && strcmp(arg, "--save-photon-map") == 0) {
            a->opt.save_photon_map = true;
        } else if (arg[0] == '-' && arg[1]) {
            return cli_usage_error(cmd, "unknown option '%s'", arg);
        } else if (!a->scene_path) {
            a->scene_path = arg;
        } else {
            return cli_usage_error(cmd, "unexpected argument '%s'", arg);
        }
    }
    if (!a->scene_path)
        return cli_usage_error(cmd, "no scene file given");
    if (!a->opt.outdir)
        return cli_usage_error(cmd, "no output directory given (-o OUTDIR)");
    return -1;
}

int cli_run_command(int argc, char **argv, bool render)
{
    const char *cmd = argv[0];
    cli_run_args a;
    memset(&a, 0, sizeof a);
    int rc = cli_run_parse(argc, argv, render, &a);
    if (rc >= 0)
        return rc;

    cli_signals_install();
    thz_error err;
    thz_error_clear(&err);
    double t0 = thz_now_s();
    thz_scene *scene = NULL;
    thz_status st = thz_scene_load(a.scene_path, &scene, &err);
    if (st != THZ_OK)
        return cli_fail(&err);
    run_apply_overrides(scene, &a.ov);
    if (render && !a.opt.photon_map_path &&
        render_integrator_needs_photons(scene->render.integrator)) {
        scene_destroy(scene);
        return cli_usage_error(cmd, "no photon map given (--photon-map FILE); only the path "
                                    "integrator renders without one");
    }
    for (size_t i = 0; i < scene->n_warnings; i++) /* --quiet hides progress, not these */
        fprintf(stderr, "thzmap %s: warning: %s\n", cmd, scene->warnings[i]);

    cli_progress progress;
    cli_progress_init(&progress, cmd, a.quiet);
    a.opt.progress = cli_progress_report;
    a.opt.progress_user = &progress;
    a.opt.warning = cli_progress_warning;
    a.opt.warning_user = &progress;
    a.opt.plan = cli_progress_plan;
    a.opt.seconds_load = thz_now_s() - t0;
    run_result result;
    st = render ? run_render(scene, &a.opt, &result, &err)
                : run_simulate(scene, &a.opt, &result, &err);
    cli_progress_finish(&progress);

    if (st == THZ_ERR_CANCELLED) {
        fprintf(stderr, "thzmap %s: interrupted; no results written to %s\n", cmd, a.opt.outdir);
        rc = CLI_EXIT_INTERRUPTED;
    } else if (st != THZ_OK) {
        rc = cli_fail(&err);
    } else {
        rc = CLI_EXIT_OK;
        if (!a.quiet) {
            printf("thzmap %s: %zu sensor%s x %zu channel%s", cmd, result.n_sensors,
                   result.n_sensors == 1 ? "" : "s", result.n_channels,
                   result.n_channels == 1 ? "" : "s");
            if (result.photons_fired)
                printf(", %llu photons fired, %llu stored",
                       (unsigned long long)result.photons_fired,
                       (unsigned long long)result.photons_stored);
            if (result.worst_p95_stderr_k > 0.0)
                printf(", pixel standard error: median <= %.3g K, 95th percentile <= %.3g K",
                       result.worst_median_stderr_k, result.worst_p95_stderr_k);
            if (result.max_passes > 1)
                printf(" after up to %u passes", result.max_passes);
            printf(", %.2f s; results in %s\n", result.seconds, a.opt.outdir);
            if (result.worst_object != SIZE_MAX && result.worst_p95_stderr_k > 0.0)
                printf("thzmap %s: noisiest object: '%s', 95th percentile standard error "
                       "%.3g K at %s\n",
                       cmd, scene->objects[result.worst_object].name,
                       result.worst_object_p95_stderr_k,
                       scene->channels[result.worst_object_channel].name);
        }
    }
    scene_destroy(scene);
    return rc;
}
