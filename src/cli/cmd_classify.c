/* thzmap classify: material recognition on a run's brightness-temperature cubes
 * against its object_id truth (thzmap/analysis.h); writes classification.json, the
 * class map as ENVI and PNG, and prints the accuracies. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "progress.h"
#include "thzmap/thzmap.h"

#define CMD "classify"

static void print_help(void)
{
    printf("usage: thzmap classify RUN_DIR --sensor S -o OUTDIR [options]\n"
           "\n"
           "Classifies every pixel of sensor S's brightness-temperature cube in RUN_DIR (the\n"
           "output of 'thzmap simulate'; S.measured_brightness_temperature when the run has\n"
           "it, else S.brightness_temperature) into the objects its truth S.object_id shows,\n"
           "with class statistics from training pixels (a seeded half of each object's), and\n"
           "writes OUTDIR/classification.json (confusion matrix with rows the truth object\n"
           "and columns the assigned class, overall and per-class accuracy, ROC and AUC per\n"
           "class), OUTDIR/S.class.hdr/.img (ENVI, object index per pixel) and S.class.png.\n"
           "\n"
           "options:\n"
           "  --sensor S             the sensor (required)\n"
           "  -o, --output OUTDIR    where the results go (required)\n"
           "  --method NAME          sam (spectral angle, default; 2 channels or more),\n"
           "                         mahalanobis, lda, matched-filter, ace (2 channels or\n"
           "                         more; the last two each object against the rest)\n"
           "  --train-fraction F     of each object's pixels that train, 0 < F < 1 (default 0.5)\n"
           "  --seed N               chooses the training pixels and the added noise, 0 to\n"
           "                         2^63 - 1 (default 1)\n"
           "  --netd-k X             first add Gaussian noise of X K (a sensor's NETD) to every\n"
           "                         value (default 0: none)\n"
           "  -q, --quiet            print nothing but errors\n"
           "  -h, --help             this help\n");
}

int cmd_classify(int argc, char **argv)
{
    const char *run_dir = NULL, *sensor = NULL, *outdir = NULL;
    bool quiet = false;
    thz_classify_options opt;
    thz_classify_options_init(&opt);
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
            if (run_dir)
                return cli_usage_error(CMD, "unexpected argument '%s'", a);
            run_dir = a;
            continue;
        }
        static const char *const with_value[] = {
            "--sensor",         "-o",     "--output", "--method",
            "--train-fraction", "--seed", "--netd-k", NULL};
        char *v = NULL;
        int rc = cli_option_value(CMD, argc, argv, &i, with_value, &v);
        if (rc >= 0)
            return rc;
        if (strcmp(a, "--sensor") == 0) {
            sensor = v;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            outdir = v;
        } else if (strcmp(a, "--method") == 0) {
            bool ok = false;
            for (size_t k = 0; thz_classify_method(k); k++)
                ok = ok || strcmp(v, thz_classify_method(k)) == 0;
            if (!ok)
                return cli_usage_error(CMD,
                                       "--method: unknown method '%s' (sam, mahalanobis, lda, "
                                       "matched-filter, ace)",
                                       v);
            opt.method = v;
        } else if (strcmp(a, "--train-fraction") == 0) {
            char *end = NULL;
            errno = 0;
            opt.train_fraction = strtod(v, &end);
            if (!cli_decimal_text(v, strlen(v)) || *end || errno ||
                !(opt.train_fraction > 0.0 && opt.train_fraction < 1.0))
                return cli_usage_error(CMD, "%s expects a fraction 0 < F < 1, got '%s'", a, v);
        } else if (strcmp(a, "--seed") == 0) {
            if (!cli_parse_u64(CMD, a, v, 0, INT64_MAX, &opt.seed))
                return CLI_EXIT_USAGE;
        } else if (strcmp(a, "--netd-k") == 0) {
            if (!cli_parse_double(CMD, a, v, 0.0, 1e6, &opt.netd_k))
                return CLI_EXIT_USAGE;
        }
    }
    if (!run_dir)
        return cli_usage_error(CMD, "no run directory given");
    if (!sensor)
        return cli_usage_error(CMD, "--sensor is required");
    if (!outdir)
        return cli_usage_error(CMD, "-o OUTDIR is required");

    thz_error err = {0};
    thz_classification *c = NULL;
    if (thz_classify_run(run_dir, sensor, &opt, &c, &err) != THZ_OK)
        return cli_fail(&err);
    /* the write commits OUTDIR through a lock and a staging directory: a signal inside it
     * left both beside OUTDIR. Held until the write is whole, it then ends the process as
     * before (the classification fits no progress callback to stop sooner). */
    sigset_t before;
    cli_signals_hold(&before);
    thz_status written = thz_classification_write(c, outdir, &err);
    cli_signals_release(&before);
    if (written != THZ_OK) {
        thz_classification_destroy(c);
        return cli_fail(&err);
    }
    if (!quiet) {
        thz_classification_info info;
        thz_classification_get_info(c, &info);
        char noise[64] = ""; /* classification.json's added_netd_k */
        if (opt.netd_k > 0.0)
            snprintf(noise, sizeof noise, " with %g K of added noise", opt.netd_k);
        fprintf(stderr, "thzmap classify: %s%s by %s: %llu pixels, %zu classes, %llu training\n",
                info.source, noise, info.method, (unsigned long long)info.pixels, info.n_classes,
                (unsigned long long)info.training_pixels);
        for (size_t k = 0; k < info.n_classes; k++) {
            double auc = thz_classification_auc(c, k);
            char auc_text[64] = "none (no held-out pixel of it or of the rest)";
            if (isfinite(auc))
                snprintf(auc_text, sizeof auc_text, "%.4f", auc);
            fprintf(stderr, "  %-24s accuracy %6.2f %%  AUC %s\n",
                    thz_classification_class_name(c, k),
                    100.0 * thz_classification_class_accuracy(c, k), auc_text);
        }
        if (info.held_out_pixels == 0)
            fprintf(stderr,
                    "thzmap classify: warning: no pixel was held out (every pixel trained the "
                    "classifier: lower --train-fraction); the accuracies are on the training "
                    "pixels\n");
        char held[48] = "none held out";
        if (info.held_out_pixels > 0 && isfinite(info.held_out_accuracy))
            snprintf(held, sizeof held, "held-out pixels %.2f %%", 100.0 * info.held_out_accuracy);
        fprintf(stderr, "accuracy %.2f %% (%s); results in %s\n", 100.0 * info.accuracy, held,
                outdir);
    }
    thz_classification_destroy(c);
    return CLI_EXIT_OK;
}
