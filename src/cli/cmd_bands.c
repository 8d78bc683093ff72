/* thzmap bands: choose the K channel centres that best separate a scene's targets, from
 * a candidate grid, with the sensor's noise and nuisance variations as the classes'
 * spread (thzmap/analysis.h); writes bands.json and its figures. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <unistd.h>

#include "cli.h"
#include "progress.h"
#include "thzmap/thzmap.h"

#define CMD "bands"
enum { MAX_TARGETS = 256, MAX_WIDTHS = 16 };

static void print_help(void)
{
    printf("usage: thzmap bands SCENE.json -o OUTDIR --count K [options]\n"
           "\n"
           "Chooses the K channel centres, among candidates from --from-thz to --to-thz every\n"
           "--step-ghz, that best separate the scene's targets (every object the sensor sees,\n"
           "or --targets and the rest as 'background'). Renders the scene with the candidates\n"
           "as its channels (path integrator), as it is and with each nuisance changed, takes\n"
           "each class's pixels from the object_id truth, and maximises the worst pair's\n"
           "Jeffries-Matusita distance; writes OUTDIR/bands.json (selected_thz, score, the\n"
           "best set for every k <= K), bands-score.png, bands-spectra.png and, when the air\n"
           "attenuates, bands-air.png.\n"
           "\n"
           "options:\n"
           "  -o, --output OUTDIR         where the results go (required)\n"
           "  --count K                   channels to choose, 1 to 32 (required)\n"
           "  --from-thz A, --to-thz B    candidate centres, THz, both ends included\n"
           "                              (default 0.1 to 1.5)\n"
           "  --step-ghz S                candidate spacing, GHz (default 10)\n"
           "  --relative-width W          FWHM / centre of every candidate (default: the\n"
           "                              scene's first channel's; of a measured response,\n"
           "                              its FWHM / centre, at most 0.5)\n"
           "  --widths W1,W2,...          search the widths too: every centre with each of\n"
           "                              these relative widths (FWHM / centre, up to 16);\n"
           "                              a chosen set holds each centre once\n"
           "  --targets OBJ,...           the objects to recognise (default: every object seen)\n"
           "  --sensor NAME               the sensor (default: the scene's first)\n"
           "  --netd-k X                  the sensor's noise per channel, K (default: the\n"
           "                              sensor's noise block, else 0.5)\n"
           "  --temperature-range-k X     each target's temperature within +-X K,\n"
           "                              independently: a render per target (default 2)\n"
           "  --ambient-range-k X         the other objects' and the air's temperature\n"
           "                              within +-X K (default 2)\n"
           "  --humidity-range F          the air's humidity within +-F of its value\n"
           "                              (a fraction; default 0.2)\n"
           "  --thickness-range F         every shell's (cover's) thickness within +-F of\n"
           "                              its own (a fraction; default 0: not varied)\n"
           "  --angle-range-deg X         the viewing angle within +-X degrees: the sensor\n"
           "                              turned about its up axis around the point it looks\n"
           "                              at (default 0: not varied)\n"
           "  --paths N                   path-integrator paths per sample (default 16)\n"
           "  --seed S                    the renders' seed, 0 to 2^63 - 1 (default: the\n"
           "                              scene's)\n"
           "  --threads T                 threads (default: all cores); results do not depend\n"
           "                              on it\n"
           "  -q, --quiet                 print nothing but errors\n"
           "  -h, --help                  this help\n");
}

/* Splits "a,b,c" in place into at most `max` items; false for none, too many or an
 * empty one ("a,,b", "a,": a typo, not a shorter list). */
static bool split_list(char *list, char **items, size_t max, size_t *n)
{
    *n = 0;
    for (char *p = list;;) {
        char *comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        if (!*p || *n == max)
            return false;
        items[(*n)++] = p;
        if (!comma)
            return true;
        p = comma + 1;
    }
}

static bool split_targets(char *list, const char **names, size_t *n)
{
    char *items[MAX_TARGETS];
    if (!split_list(list, items, MAX_TARGETS, n))
        return false;
    for (size_t i = 0; i < *n; i++)
        names[i] = items[i];
    return true;
}

/* Parses "w1,w2,..." (relative widths in (0, 0.5]) in place; false, saying nothing,
 * when it is not such a list (the caller says what is expected). */
static bool split_widths(char *list, double *w, size_t *n)
{
    char *items[MAX_WIDTHS];
    if (!split_list(list, items, MAX_WIDTHS, n))
        return false;
    for (size_t i = 0; i < *n; i++) {
        char *end = NULL;
        errno = 0;
        w[i] = strtod(items[i], &end);
        if (!cli_decimal_text(items[i], strlen(items[i])) || *end || errno ||
            !(w[i] > 0.0 && w[i] <= 0.5))
            return false;
    }
    return true;
}

int cmd_bands(int argc, char **argv)
{
    const char *scene = NULL, *outdir = NULL;
    const char *targets[MAX_TARGETS];
    double widths[MAX_WIDTHS];
    bool quiet = false, have_count = false;
    uint64_t count = 0, paths = 0, threads = 0, seed = 0;
    thz_bands_options opt;
    thz_bands_options_init(&opt);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (cli_is_help(a)) {
            print_help();
            return CLI_EXIT_OK;
        }
        if (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0) {
            quiet = true;
            continue;
        }
        if (a[0] != '-') {
            if (scene)
                return cli_usage_error(CMD, "unexpected argument '%s'", a);
            scene = a;
            continue;
        }
        static const char *const with_value[] = {"-o",
                                                 "--output",
                                                 "--count",
                                                 "--from-thz",
                                                 "--to-thz",
                                                 "--step-ghz",
                                                 "--relative-width",
                                                 "--widths",
                                                 "--thickness-range",
                                                 "--angle-range-deg",
                                                 "--targets",
                                                 "--sensor",
                                                 "--netd-k",
                                                 "--temperature-range-k",
                                                 "--ambient-range-k",
                                                 "--humidity-range",
                                                 "--paths",
                                                 "--seed",
                                                 "--threads",
                                                 NULL};
        char *v = NULL;
        int rc = cli_option_value(CMD, argc, argv, &i, with_value, &v);
        if (rc >= 0)
            return rc;
        bool ok = true;
        if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            outdir = v;
        } else if (strcmp(a, "--count") == 0) {
            ok = cli_parse_u64(CMD, a, v, 1, THZ_BANDS_MAX_COUNT, &count);
            have_count = true;
        } else if (strcmp(a, "--from-thz") == 0) {
            ok = cli_parse_positive(CMD, a, v, 1000.0, &opt.from_thz);
        } else if (strcmp(a, "--to-thz") == 0) {
            ok = cli_parse_positive(CMD, a, v, 1000.0, &opt.to_thz);
        } else if (strcmp(a, "--step-ghz") == 0) {
            ok = cli_parse_positive(CMD, a, v, 1e6, &opt.step_ghz);
        } else if (strcmp(a, "--relative-width") == 0) {
            ok = cli_parse_positive(CMD, a, v, 0.5, &opt.relative_width);
        } else if (strcmp(a, "--widths") == 0) {
            if (!split_widths(v, widths, &opt.n_widths))
                return cli_usage_error(CMD,
                                       "--widths expects 1 to %d relative widths in (0, 0.5], "
                                       "comma separated",
                                       MAX_WIDTHS);
            opt.relative_widths = widths;
        } else if (strcmp(a, "--thickness-range") == 0) {
            ok = cli_parse_double(CMD, a, v, 0.0, 0.99, &opt.thickness_range);
        } else if (strcmp(a, "--angle-range-deg") == 0) {
            ok = cli_parse_double(CMD, a, v, 0.0, 90.0, &opt.angle_range_deg);
        } else if (strcmp(a, "--targets") == 0) {
            if (!split_targets(v, targets, &opt.n_targets))
                return cli_usage_error(CMD,
                                       "--targets expects 1 to %d object names, comma "
                                       "separated",
                                       MAX_TARGETS);
            opt.targets = targets;
        } else if (strcmp(a, "--sensor") == 0) {
            opt.sensor = v;
        } else if (strcmp(a, "--netd-k") == 0) {
            ok = cli_parse_positive(CMD, a, v, 1e6, &opt.netd_k);
            opt.has_netd = 1;
        } else if (strcmp(a, "--temperature-range-k") == 0) {
            ok = cli_parse_double(CMD, a, v, 0.0, 1000.0, &opt.target_temperature_range_k);
        } else if (strcmp(a, "--ambient-range-k") == 0) {
            ok = cli_parse_double(CMD, a, v, 0.0, 1000.0, &opt.ambient_temperature_range_k);
        } else if (strcmp(a, "--humidity-range") == 0) {
            ok = cli_parse_double(CMD, a, v, 0.0, 0.99, &opt.humidity_range);
        } else if (strcmp(a, "--paths") == 0) {
            ok = cli_parse_u64(CMD, a, v, 1, 1000000, &paths);
            opt.paths_per_sample = (uint32_t)paths;
        } else if (strcmp(a, "--seed") == 0) {
            ok = cli_parse_u64(CMD, a, v, 0, INT64_MAX, &seed);
            opt.has_seed = 1;
            opt.seed = seed;
        } else if (strcmp(a, "--threads") == 0) {
            ok = cli_parse_u64(CMD, a, v, 1, THZ_MAX_THREADS, &threads);
        }
        if (!ok)
            return CLI_EXIT_USAGE;
    }
    if (!scene)
        return cli_usage_error(CMD, "no scene file given");
    if (!outdir)
        return cli_usage_error(CMD, "-o OUTDIR is required");
    if (!have_count)
        return cli_usage_error(CMD, "--count K is required");
    if (!(opt.to_thz >= opt.from_thz))
        return cli_usage_error(CMD, "--to-thz (%g THz) must not be below --from-thz (%g THz)",
                               opt.to_thz, opt.from_thz);
    /* what the library would refuse only after loading the scene, said by option */
    double centres = thz_bands_candidate_centres(&opt);
    if ((double)count > centres)
        return cli_usage_error(CMD,
                               "--count %llu: only %.0f candidate centres from %g to %g THz "
                               "every %g GHz (--from-thz, --to-thz, --step-ghz)",
                               (unsigned long long)count, centres, opt.from_thz, opt.to_thz,
                               opt.step_ghz);
    if (opt.n_widths && opt.relative_width > 0.0)
        return cli_usage_error(CMD,
                               "--relative-width %g and --widths: give one (the candidates' "
                               "one width, or the widths searched)",
                               opt.relative_width);
    /* an OUTDIR that cannot be one is refused before the renders, not after them */
    int refused = cli_refuse_file_outdir(CMD, outdir);
    if (refused >= 0)
        return refused;
    opt.count = (size_t)count;
    /* nor one the results cannot be staged beside (a read-only parent, another run
     * writing there): refused after every render before, the work lost */
    thz_output *probe = NULL;
    thz_error probe_err = {0};
    if (thz_output_open(outdir, &probe, &probe_err) != THZ_OK)
        return cli_fail(&probe_err);
    thz_output_destroy(probe);

    thz_context *ctx = thz_context_create();
    if (!ctx) {
        fprintf(stderr, "thzmap: out of memory\n");
        return CLI_EXIT_FAILURE;
    }
    thz_context_set_threads(ctx, (int)threads);
    /* Progress by render (stage "bands": the nominal render, then the nuisances'), on a
     * terminal redrawn, in a log a line as each ends; the callback also carries Ctrl-C
     * into the run. */
    cli_progress progress;
    cli_progress_init(&progress, CMD, quiet);
    thz_context_set_progress(ctx, cli_progress_report, &progress);
    thz_context_set_warning(ctx, cli_progress_warning, &progress);
    cli_signals_install();
    thz_error err = {0};
    thz_bands *b = NULL;
    double t0 = cli_now_s();
    int rc = CLI_EXIT_OK;
    thz_status st = thz_bands_select(ctx, scene, &opt, &b, &err);
    /* The progress callback carries a stop only while the renders run: one that came
     * during the search, which reports no progress, stops here, before anything is
     * written (it was ignored: the results written, exit status 0). */
    if (st == THZ_OK && cli_interrupt_signal())
        st = THZ_ERR_CANCELLED;
    if (st == THZ_OK)
        st = thz_bands_write(b, outdir, &err);
    cli_progress_finish(&progress);
    /* a failure under an interrupt is the interrupt's (a child ended by the same Ctrl-C) */
    if (st != THZ_OK && cli_interrupt_signal()) {
        fprintf(stderr, "thzmap bands: interrupted; nothing written\n");
        rc = 128 + cli_interrupt_signal();
    } else if (st != THZ_OK) {
        rc = cli_fail(&err);
    } else if (cli_interrupt_signal()) {
        /* the stop came while the results were written, which nothing interrupts: they
         * are whole, and the process still ends by the signal, as classify's does */
        fprintf(stderr, "thzmap bands: interrupted; the results in %s are complete\n", outdir);
        rc = 128 + cli_interrupt_signal();
    } else if (!quiet) {
        thz_bands_info info;
        thz_bands_get_info(b, &info);
        fprintf(stderr, "thzmap bands: %zu candidates, %zu classes, %s search, %.1f s\n",
                info.n_candidates, info.n_classes, info.search, cli_now_s() - t0);
        for (size_t k = 1; k <= info.count; k++)
            fprintf(stderr, "  K = %zu: worst-pair Jeffries-Matusita distance %.4f\n", k,
                    thz_bands_score(b, k));
        fprintf(stderr, "chosen:");
        for (size_t i = 0; i < info.count; i++)
            fprintf(stderr, " %.4g THz (relative width %.3g)", thz_bands_selected_thz(b, i),
                    thz_bands_selected_relative_width(b, i));
        fprintf(stderr, "; results in %s\n", outdir);
    }
    thz_bands_destroy(b);
    thz_context_destroy(ctx);
    return rc;
}
