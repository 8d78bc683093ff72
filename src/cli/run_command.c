/* simulate and render: options, scene, run, report. */
#include "run_command.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "cli_mpi.h"
#include "progress.h"
#include "thzmap/thzmap.h"

static void cli_run_usage(FILE *f, bool render)
{
    if (!render)
        fprintf(f, "usage: thzmap simulate SCENE.json -o OUTDIR [options]\n\n"
                   "Renders every sensor of the scene (photon-map and final-gather fire their\n"
                   "photons first; path, the default, fires none); writes the images,\n"
                   "previews and summary.json into OUTDIR (created if missing).\n\n"
                   "options:\n"
                   "  -o, --output OUTDIR   where the results go (required)\n"
                   "  --photons N           photons per channel (overrides photons.per_channel;\n"
                   "                        1e6 is accepted)\n"
                   "  --seed S              random seed, 0 to 2^63 - 1 (overrides photons.seed)\n"
                   "  --threads T           threads to use (default: all cores)\n"
                   "  --integrator NAME     path (default) | final-gather | photon-map\n"
                   "                        (overrides render.integrator; path fires no\n"
                   "                        photons; photon-map is the paper's method)\n"
                   "  --target-noise-k X    add passes to each channel until the 95th\n"
                   "                        percentile over pixels of the per-pixel standard\n"
                   "                        error of the brightness temperature is at most\n"
                   "                        X K: of gather rays (final-gather), paths (path),\n"
                   "                        or N more photons (photon-map: rendered from all\n"
                   "                        photons so far at checks); each pass is\n"
                   "                        deterministic.\n"
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
                   "  -q, --quiet           no progress output and no up-front estimate\n"
                   "                        (warnings are still printed)\n"
                   "  -h, --help            this help\n");
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
                   "                        (overrides render.integrator, as for simulate)\n"
                   "  --target-noise-k X    final-gather, path: add passes until the 95th\n"
                   "                        percentile over pixels of the per-pixel standard\n"
                   "                        error of the brightness temperature is at most X K\n"
                   "                        (each pass deterministic; default as in simulate)\n"
                   "  --max-seconds S       stop adding passes once a channel has rendered for\n"
                   "                        S s (overrides render.max_seconds; the images\n"
                   "                        then depend on the machine's speed)\n"
                   "  -q, --quiet           no progress output and no up-front estimate\n"
                   "                        (warnings are still printed)\n"
                   "  -h, --help            this help\n");
}

typedef struct cli_run_args {
    const char *scene_path;
    const char *outdir;
    const char *photon_map_path; /* render */
    const char *sensor_name;     /* render: only this sensor */
    int threads;
    bool quiet;
    thz_run_settings settings;
    thz_write_options write;
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
            if (cli_refuse_repeat(cmd, argv, i) != -1)
                return CLI_EXIT_USAGE;
            if (i + 1 >= argc)
                return cli_usage_error(cmd, "%s needs a value", arg);
            const char *val = argv[++i];
            if (cli_looks_like_option(val)) /* -o --quiet: a forgotten value, not a name */
                return cli_usage_error(cmd, "%s needs a value, got the option '%s'", arg, val);
            uint64_t u = 0;
            if (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0) {
                a->outdir = val;
            } else if (strcmp(arg, "--threads") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, THZ_MAX_THREADS, &u))
                    return CLI_EXIT_USAGE;
                a->threads = (int)u;
            } else if (strcmp(arg, "--integrator") == 0) {
                if (!thz_integrator_known(val))
                    return cli_usage_error(cmd,
                                           "--integrator expects photon-map, final-gather or "
                                           "path, got '%s'",
                                           val);
                a->settings.integrator = val;
            } else if (strcmp(arg, "--target-noise-k") == 0 || strcmp(arg, "--max-seconds") == 0) {
                bool target = strcmp(arg, "--target-noise-k") == 0;
                char *end = NULL;
                errno = 0;
                double x = strtod(val, &end);
                if (!cli_decimal_text(val, strlen(val)) || *end || errno || !isfinite(x) ||
                    !(x > 0.0))
                    return cli_usage_error(cmd, "%s expects a positive number (%s), got '%s'", arg,
                                           target ? "K" : "s", val);
                *(target ? &a->settings.target_noise_k : &a->settings.max_seconds) = x;
            } else if (strcmp(arg, "--photons") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, UINT64_C(1000000000000), &u))
                    return CLI_EXIT_USAGE;
                a->settings.photons_per_channel = u;
            } else if (strcmp(arg, "--seed") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 0, (uint64_t)INT64_MAX, &u))
                    return CLI_EXIT_USAGE;
                a->settings.has_seed = 1;
                a->settings.seed = u;
            } else if (strcmp(arg, "--ply-max-points") == 0) {
                if (!cli_parse_u64(cmd, arg, val, 1, UINT64_C(1000000000000), &u))
                    return CLI_EXIT_USAGE;
                a->write.ply_max_points = u;
            } else if (strcmp(arg, "--photon-map") == 0) {
                a->photon_map_path = val;
            } else {
                a->sensor_name = val;
            }
        } else if (strcmp(arg, "--quiet") == 0 || strcmp(arg, "-q") == 0) {
            a->quiet = true;
        } else if (!render && strcmp(arg, "--save-photon-map") == 0) {
            a->settings.keep_photons = 1;
            a->write.photon_map = 1;
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
    if (!a->outdir)
        return cli_usage_error(cmd, "no output directory given (-o OUTDIR)");
    return -1;
}

/* The output directory of the run in progress and the process that opened it. libgomp
 * calls exit() when it cannot allocate or start a thread; the exit handler then removes
 * the staging directory and the lock, which would otherwise stay beside OUTDIR until
 * the next run. Process state, like the signal flag (progress.c): an exit handler can
 * reach nothing else. (PLplot, the other library that exits, runs in child processes,
 * which _exit() past this handler or find another process id.) */
static thz_output *cli_open_output;
static pid_t cli_output_pid;

static void cli_exit_cleanup(void)
{
    thz_output *output = cli_open_output;
    if (!output || getpid() != cli_output_pid)
        return;
    cli_open_output = NULL;
    thz_output_destroy(output);
    fprintf(stderr, "thzmap: a library ended the process early (out of memory, or no thread "
                    "could be started); the output being written was removed and its "
                    "directory left as it was\n");
}

thz_output **cli_exit_guard(void)
{
    static bool handler_installed = false;
    if (!handler_installed)
        handler_installed = atexit(cli_exit_cleanup) == 0;
    cli_output_pid = getpid();
    return &cli_open_output;
}

/* The run: photons read (render) or fired, images rendered, results written through
 * `output` (opened before, so that a bad OUTDIR fails before any work; destroyed here). */
static thz_status cli_run(thz_context *ctx, const thz_scene *scene, const cli_run_args *a,
                          bool render, thz_output *output, thz_run **run, thz_error *err)
{
    /* (a sensor the scene lacks was refused on loading, on every rank) */
    long sensor = render && a->sensor_name ? thz_scene_sensor_index(scene, a->sensor_name) : -1;
    thz_status st;
    /* render reads the photon-map file a channel at a time: one channel's map in memory */
    if (render && a->photon_map_path)
        st = thz_render_file(ctx, scene, a->photon_map_path, sensor, &a->settings, run, err);
    else
        st = render ? thz_render_run(ctx, scene, NULL, sensor, &a->settings, run, err)
                    : thz_simulate(ctx, scene, &a->settings, run, err);
    /* the library's memory refusal names the scene key; simulate also has --photons */
    if (st == THZ_ERR_LIMIT && !render && strstr(err->message, "; lower photons.per_channel (")) {
        size_t len = strlen(err->message);
        snprintf(err->message + len, sizeof err->message - len, " (or --photons)");
    }
    if (st == THZ_OK)
        st = thz_output_add_run(ctx, output, *run, &a->write, err);
    if (st == THZ_OK)
        st = thz_output_commit(output, err);
    *cli_exit_guard() = NULL;
    thz_output_destroy(output);
    return st;
}

/* The scene of the run and the checks of the options against it; -1 to go on, or the
 * exit status after printing why not. */
static int cli_run_load(const char *cmd, cli_run_args *a, bool render, thz_scene **scene)
{
    thz_error err = {0};
    double t0 = cli_now_s();
    thz_status st = thz_scene_load(a->scene_path, scene, &err);
    if (st != THZ_OK)
        return cli_fail(&err);
    thz_scene_info info;
    thz_scene_get_info(*scene, &info);
    double load_s = cli_now_s() - t0;
    if (!a->quiet && load_s >= 1.0) { /* what the silence before the estimate was */
        size_t triangles = 0;
        for (size_t i = 0; i < info.n_objects; i++) {
            thz_object_info o;
            if (thz_scene_object(*scene, i, &o) == THZ_OK)
                triangles += o.triangles;
        }
        fprintf(stderr, "thzmap %s: loaded %s in %.1f s (%zu object%s, %zu triangles)\n", cmd,
                a->scene_path, load_s, info.n_objects, info.n_objects == 1 ? "" : "s", triangles);
    }
    const char *integrator = a->settings.integrator ? a->settings.integrator : info.integrator;
    if (a->write.photon_map && !thz_integrator_needs_photons(integrator))
        return cli_usage_error(cmd,
                               "--save-photon-map: the %s integrator fires no photons (give "
                               "--integrator final-gather or photon-map, or render.integrator)",
                               integrator);
    if (render && !a->photon_map_path && thz_integrator_needs_photons(integrator))
        return cli_usage_error(cmd, "no photon map given (--photon-map FILE); only the path "
                                    "integrator renders without one");
    /* here, before the ranks of an MPI run work together: every rank refuses it alike */
    if (render && a->sensor_name && thz_scene_sensor_index(*scene, a->sensor_name) < 0) {
        char names[512] = "";
        for (size_t i = 0, n = 0; i < thz_scene_sensor_count(*scene); i++) {
            thz_sensor_info s;
            if (thz_scene_sensor(*scene, i, &s) == THZ_OK && n < sizeof names)
                n += (size_t)snprintf(names + n, sizeof names - n, "%s'%s'", i ? ", " : "", s.name);
        }
        return cli_usage_error(cmd, "--sensor: the scene has no sensor named '%s'; its sensors: %s",
                               a->sensor_name, names);
    }
    if (render && a->settings.target_noise_k > 0.0 && !thz_integrator_has_passes(integrator))
        return cli_usage_error(cmd,
                               "--target-noise-k: the %s integrator renders its photon map in one "
                               "deterministic pass, and render fires no photons (simulate fires "
                               "them until the target is met; or give --integrator final-gather "
                               "or path)",
                               integrator);
    /* options the integrator has no use for: said, not silently dropped */
    if (!render && a->settings.photons_per_channel && !thz_integrator_needs_photons(integrator))
        fprintf(stderr,
                "thzmap %s: warning: --photons %" PRIu64 " is not used: the %s integrator fires "
                "no photons (give --integrator photon-map or final-gather to fire them)\n",
                cmd, a->settings.photons_per_channel, integrator);
    if (!render && a->write.ply_max_points && !a->write.photon_map)
        fprintf(stderr,
                "thzmap %s: warning: --ply-max-points %" PRIu64 " is not used: photon-map.ply is "
                "written only with --save-photon-map\n",
                cmd, a->write.ply_max_points);
    if (render && a->photon_map_path && !thz_integrator_needs_photons(integrator)) {
        fprintf(stderr,
                "thzmap %s: warning: --photon-map %s is not used: the %s integrator renders "
                "without photons (give --integrator photon-map or final-gather to render from "
                "it)\n",
                cmd, a->photon_map_path, integrator);
        a->photon_map_path = NULL;
    }
    a->threads = (int)cli_threads_check(cmd, (uint64_t)a->threads);
    for (size_t i = 0; i < thz_scene_warning_count(*scene); i++) /* --quiet hides progress only */
        fprintf(stderr, "thzmap %s: warning: %s\n", cmd, thz_scene_warning(*scene, i));
    return -1;
}

/* A rank other than 0 of an MPI run: fires its shares of rank 0's photon phases and
 * renders its pixel tiles of rank 0's render passes. A failure ends the job, since rank 0
 * waits for the share. */
static int cli_run_member(const char *cmd, const cli_run_args *a, const thz_scene *scene)
{
    thz_error err = {0};
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        fprintf(stderr, "thzmap %s (MPI rank %d): out of memory\n", cmd, cli_mpi_rank());
        cli_mpi_abort(CLI_EXIT_FAILURE);
    }
    thz_context_set_threads(ctx, a->threads);
    thz_status st = thz_mpi_serve(ctx, scene, &a->settings, &err);
    if (st != THZ_OK) {
        char message[sizeof err.message + 64];
        snprintf(message, sizeof message, "%s (MPI rank %d): %s", cmd, cli_mpi_rank(), err.message);
        memcpy(err.message, message, sizeof err.message - 1);
        err.message[sizeof err.message - 1] = '\0';
        cli_mpi_abort(cli_fail(&err));
    }
    thz_context_destroy(ctx);
    return CLI_EXIT_OK;
}

int cli_run_command(int argc, char **argv, bool render)
{
    const char *cmd = argv[0];
    cli_run_args a;
    memset(&a, 0, sizeof a);
    double t0 = cli_now_s();
    thz_scene *scene = NULL;
    /* Under mpirun every rank parses and loads alike; rank 0 alone says what is wrong. */
    cli_mpi_quiet_begin();
    int rc = cli_run_parse(argc, argv, render, &a);
    if (rc < 0)
        rc = cli_run_load(cmd, &a, render, &scene);
    /* OUTDIR (its lock, its staging directory) before the ranks work together: rank 0
     * alone writes, and a bad OUTDIR (a file, a busy one) found after would abort the
     * job; now every rank exits as rank 0 does */
    thz_output *output = NULL;
    if (rc < 0 && cli_mpi_rank() == 0) {
        thz_error oerr = {0};
        if (thz_output_open(a.outdir, &output, &oerr) != THZ_OK)
            rc = cli_fail(&oerr);
        *cli_exit_guard() = output;
    }
    cli_mpi_quiet_end();
    int lead_rc = rc, failed = cli_mpi_agree(rc < 0, rc, &lead_rc);
    if (failed >= 0) {
        *cli_exit_guard() = NULL;
        thz_output_destroy(output);
        thz_scene_destroy(scene);
        if (lead_rc >= 0)
            return lead_rc;
        if (cli_mpi_rank() == 0)
            fprintf(stderr,
                    "thzmap %s: MPI rank %d could not load the scene or options rank 0 did (is "
                    "%s the same file on every node?)\n",
                    cmd, failed, a.scene_path);
        return CLI_EXIT_FAILURE;
    }
    bool shared = cli_mpi_size() > 1;
    if (shared && cli_mpi_rank() > 0) {
        rc = cli_run_member(cmd, &a, scene);
        thz_scene_destroy(scene);
        return rc;
    }

    cli_signals_install();
    thz_error err = {0};
    thz_status st = THZ_OK;
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        *cli_exit_guard() = NULL;
        thz_output_destroy(output);
        thz_scene_destroy(scene);
        fprintf(stderr, "thzmap %s: out of memory\n", cmd);
        if (shared) /* the other ranks wait for this one: end them too */
            cli_mpi_abort(CLI_EXIT_FAILURE);
        return CLI_EXIT_FAILURE;
    }
    cli_progress progress;
    cli_progress_init(&progress, cmd, a.quiet);
    cli_progress_sensors(&progress, scene,
                         render && a.sensor_name ? thz_scene_sensor_index(scene, a.sensor_name)
                                                 : -1);
    thz_context_set_threads(ctx, a.threads);
    if (shared && thz_context_set_mpi(ctx, &err) != THZ_OK) {
        *cli_exit_guard() = NULL;
        thz_output_destroy(output); /* nothing staged yet: removed, OUTDIR as it was */
        cli_mpi_abort(cli_fail(&err));
    }
    thz_context_set_progress(ctx, cli_progress_report, &progress);
    thz_context_set_warning(ctx, cli_progress_warning, &progress);
    if (!a.quiet) { /* the estimate is printed only; its pilot costs a moment */
        a.settings.plan = cli_progress_plan;
        a.settings.plan_user = &progress;
    }
    a.settings.seconds_load = cli_now_s() - t0;
    double t_run = cli_now_s();
    thz_run *run = NULL;
    st = cli_run(ctx, scene, &a, render, output, &run, &err);
    cli_progress_finish(&progress);

    /* a failure under an interrupt is the interrupt's: a Ctrl-C at the terminal also ends
     * the figure or mesh-import child, whose death the library reports as a failure */
    if (st == THZ_ERR_CANCELLED || (st != THZ_OK && cli_interrupt_signal())) {
        fprintf(stderr, "thzmap %s: interrupted%s; no results written to %s\n", cmd,
                cli_mpi_signal_note(cli_interrupt_signal()), a.outdir);
        rc = cli_interrupt_signal() ? 128 + cli_interrupt_signal() : CLI_EXIT_INTERRUPTED;
    } else if (st != THZ_OK) {
        rc = cli_fail(&err);
    } else {
        rc = CLI_EXIT_OK;
        thz_run_totals result;
        thz_run_get_totals(run, &result);
        result.seconds = cli_now_s() - t_run; /* the run and its writing */
        if (!a.quiet) {
            printf("thzmap %s: %zu sensor%s x %zu channel%s", cmd, result.n_sensors,
                   result.n_sensors == 1 ? "" : "s", result.n_channels,
                   result.n_channels == 1 ? "" : "s");
            if (result.photons_fired)
                printf(", %llu photons fired, %llu stored",
                       (unsigned long long)result.photons_fired,
                       (unsigned long long)result.photons_stored);
            /* infinite: the figure falls on pixels whose samples were short of photons,
             * whose error is unknown (not 0: their reflected radiance is missing) */
            if (isinf(result.worst_median_stderr_k))
                printf(", pixel standard error unknown (samples short of photons)");
            else if (isinf(result.worst_p95_stderr_k))
                printf(", pixel standard error: median <= %.3g K, 95th percentile unknown "
                       "(samples short of photons)",
                       result.worst_median_stderr_k);
            else if (result.worst_p95_stderr_k > 0.0)
                printf(", pixel standard error: median <= %.3g K, 95th percentile <= %.3g K",
                       result.worst_median_stderr_k, result.worst_p95_stderr_k);
            if (result.max_passes > 1)
                printf(" after up to %u passes", result.max_passes);
            if (shared)
                printf(", %d MPI ranks (%.3g MB communicated)", cli_mpi_size(),
                       1e-6 * (double)thz_context_mpi_bytes(ctx));
            printf(", %.2f s; results in %s\n", result.seconds, a.outdir);
            thz_object_info obj;
            thz_channel_info ch;
            if (result.worst_object >= 0 && result.worst_p95_stderr_k > 0.0 &&
                thz_scene_object(scene, (size_t)result.worst_object, &obj) == THZ_OK &&
                thz_scene_channel(scene, result.worst_object_channel, &ch) == THZ_OK) {
                /* a channel named by its frequency (the default) is not named twice */
                char freq[64] = "";
                size_t n = strlen(ch.name);
                if (n < 4 || strcmp(ch.name + n - 4, " THz") != 0)
                    snprintf(freq, sizeof freq, " (%.4g THz)", ch.frequency_thz);
                char value[64];
                if (isinf(result.worst_object_p95_stderr_k))
                    snprintf(value, sizeof value, "unknown (samples short of photons)");
                else
                    snprintf(value, sizeof value, "%.3g K", result.worst_object_p95_stderr_k);
                printf("thzmap %s: noisiest object: '%s', 95th percentile standard error "
                       "%s at %s%s\n",
                       cmd, obj.name, value, ch.name, freq);
            }
        }
    }
    /* a stop that came while the results were committed, after the library's last check:
     * they are whole, and the process still ends by the signal (it ended with status 0) */
    if (rc == CLI_EXIT_OK && cli_interrupt_signal()) {
        fprintf(stderr, "thzmap %s: interrupted; the results in %s are complete\n", cmd, a.outdir);
        rc = 128 + cli_interrupt_signal();
    }
    if (shared && rc != CLI_EXIT_OK) /* the other ranks may be waiting for rank 0 */
        cli_mpi_abort(rc);
    thz_run_destroy(run);
    thz_context_destroy(ctx); /* ends the other ranks' thz_mpi_serve */
    thz_scene_destroy(scene);
    return rc;
}
