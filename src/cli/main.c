/* thzmap: the program. Dispatches to the subcommands from a table (as git does). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"
#include "cli_mpi.h"
#include "progress.h"

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
    bool shares_ranks; /* runs as one job over several MPI ranks (docs/mpi.md) */
} command;

static const command commands[] = {
    {"validate", cmd_validate, "check a scene; print its geometry and emitted power per channel",
     false},
    {"simulate", cmd_simulate, "render every sensor of a scene (firing photons first if needed)",
     true},
    {"render", cmd_render, "re-render sensors of a scene from a saved photon map", true},
    {"atmosphere", cmd_atmosphere, "print the atmosphere's attenuation against frequency", false},
    {"batch", cmd_batch, "run a sequence of frames (keyframes, sweeps) and make movies", true},
    {"materials", cmd_materials, "list the material library, or describe one material", false},
    {"bands", cmd_bands, "choose the channel frequencies that best separate a scene's targets",
     false},
    {"classify", cmd_classify, "recognise materials in a run's cubes against its truth", false},
    {"serve", cmd_serve, "serve the browser GUI (scene editor, runs, results) and its API", false},
};

static void print_usage(FILE *f)
{
    fprintf(f, "usage: thzmap <command> [options]\n"
               "       thzmap --help | --version\n\n"
               "Simulates what a passive multispectral terahertz camera sees (photon mapping).\n\n"
               "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-11s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\n'thzmap <command> --help' describes a command's options.\n");
}

int cli_fail(const thz_error *err)
{
    const char *message = err->message[0] ? err->message : thz_status_name(err->status);
    /* a C library call that failed with ENOMEM says "Cannot allocate memory" */
    bool say_oom = err->status == THZ_ERR_NOMEM && !strstr(message, "out of memory");
    /* under ulimit -v, "out of memory" is the address space's limit, not the machine's */
    char limited[96] = "";
    struct rlimit rl;
    if (err->status == THZ_ERR_NOMEM && getrlimit(RLIMIT_AS, &rl) == 0 &&
        rl.rlim_cur != RLIM_INFINITY)
        snprintf(limited, sizeof limited, " (the address space is limited: ulimit -v %llu KiB)",
                 (unsigned long long)rl.rlim_cur / 1024);
    fprintf(stderr, "thzmap: %s%s%s\n", say_oom ? "out of memory: " : "", message, limited);
    /* THZ_ERR_LIMIT: the scene or the options ask for more than fits (memory, sizes) */
    return err->status == THZ_ERR_INPUT || err->status == THZ_ERR_LIMIT ? CLI_EXIT_USAGE
                                                                        : CLI_EXIT_FAILURE;
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "thzmap %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(see 'thzmap %s --help')\n", cmd);
    va_end(ap);
    return CLI_EXIT_USAGE;
}

double cli_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bool cli_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int cli_refuse_file_outdir(const char *cmd, const char *outdir)
{
    struct stat st;
    if (stat(outdir, &st) == 0 && !S_ISDIR(st.st_mode))
        return cli_usage_error(cmd,
                               "-o %s: exists and is not a directory (expected a directory "
                               "for the results, or a name to create one)",
                               outdir);
    return -1;
}

/* "-o" and "--output" are one option. */
static const char *cli_option_name(const char *a)
{
    return strcmp(a, "--output") == 0 ? "-o" : a;
}

int cli_refuse_repeat(const char *cmd, char **argv, int i)
{
    for (int j = 1; j < i; j++)
        if (strcmp(cli_option_name(argv[j]), cli_option_name(argv[i])) == 0)
            return cli_usage_error(cmd, "%s given twice (give each option once)", argv[i]);
    return -1;
}

int cli_option_value(const char *cmd, int argc, char **argv, int *i, const char *const *with_value,
                     char **value)
{
    const char *a = argv[*i];
    bool known = false;
    for (size_t k = 0; with_value[k] && !known; k++)
        known = strcmp(a, with_value[k]) == 0;
    if (!known)
        return cli_usage_error(cmd,
                               a[0] == '-' ? "unknown option '%s'" : "unexpected argument '%s'", a);
    if (cli_refuse_repeat(cmd, argv, *i) != -1)
        return CLI_EXIT_USAGE;
    if (*i + 1 >= argc)
        return cli_usage_error(cmd, "%s needs a value", a);
    if (cli_looks_like_option(argv[*i + 1]))
        return cli_usage_error(cmd, "%s needs a value, got the option '%s'", a, argv[*i + 1]);
    *value = argv[++*i];
    return -1;
}

bool cli_decimal_text(const char *text, size_t len)
{
    size_t i = 0, digits = 0;
    if (i < len && (text[i] == '+' || text[i] == '-'))
        i++;
    for (; i < len && text[i] >= '0' && text[i] <= '9'; i++)
        digits++;
    if (i < len && text[i] == '.')
        for (i++; i < len && text[i] >= '0' && text[i] <= '9'; i++)
            digits++;
    if (digits == 0)
        return false;
    if (i < len && (text[i] == 'e' || text[i] == 'E')) {
        i++;
        if (i < len && (text[i] == '+' || text[i] == '-'))
            i++;
        size_t exponent = 0;
        for (; i < len && text[i] >= '0' && text[i] <= '9'; i++)
            exponent++;
        if (exponent == 0)
            return false;
    }
    return i == len;
}

bool cli_parse_u64(const char *cmd, const char *option, const char *text, uint64_t min,
                   uint64_t max, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    bool decimal = cli_decimal_text(text, strlen(text)) && text[0] != '-';
    unsigned long long v = strtoull(text, &end, 10);
    bool ok = decimal && !*end && !errno;
    if (!ok && decimal && strpbrk(text, ".eE")) {
        /* 1e6 or 2.5e3: a real that is a whole number, exact in a double (as in JSON) */
        errno = 0;
        double x = strtod(text, &end);
        ok = !*end && !errno && isfinite(x) && x >= 0.0 && x == floor(x) && x <= 9007199254740992.0;
        v = ok ? (unsigned long long)x : 0;
    }
    if (!ok || v < min || v > max) {
        cli_usage_error(cmd, "%s expects a whole number from %llu to %llu, got '%s'", option,
                        (unsigned long long)min, (unsigned long long)max, text);
        return false;
    }
    *out = (uint64_t)v;
    return true;
}

bool cli_parse_positive(const char *cmd, const char *option, const char *text, double max,
                        double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (!cli_decimal_text(text, strlen(text)) || *end || errno || !isfinite(v) || !(v > 0.0) ||
        v > max) {
        cli_usage_error(cmd, "%s expects a number above 0 and at most %g, got '%s'", option, max,
                        text);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_double(const char *cmd, const char *option, const char *text, double min, double max,
                      double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (!cli_decimal_text(text, strlen(text)) || *end || errno || !isfinite(v) || v < min ||
        v > max) {
        if (min == -DBL_MAX && max == DBL_MAX) /* the range is checked later, by the library */
            cli_usage_error(cmd, "%s expects a number, got '%s'", option, text);
        else
            cli_usage_error(cmd, "%s expects a number from %g to %g, got '%s'", option, min, max,
                            text);
        return false;
    }
    *out = v;
    return true;
}

/* The command's exit status; under mpirun, after MPI started and before it ends. */
static int main_run(const command *c, int argc, char **argv)
{
    if (cli_mpi_size() > 1 && !c->shares_ranks) {
        if (cli_mpi_rank() == 0)
            fprintf(stderr,
                    "thzmap %s: does not run over several MPI ranks (simulate, render and "
                    "batch do); run it without mpirun\n",
                    c->name);
        return CLI_EXIT_USAGE;
    }
    /* OpenMP's default team started before any work, under ulimit -v (a command's
     * --threads starts more, or fewer, once parsed) */
    cli_threads_prepare(c->name, 0);
    return c->run(argc, argv);
}

/* The values split_assignments took from "--name=value": given with their option, so
 * values even when they begin with "-" ("--sensor=-cam"). */
static char **assigned_values;
static int n_assigned_values;

bool cli_looks_like_option(const char *value)
{
    for (int i = 0; i < n_assigned_values; i++)
        if (value == assigned_values[i])
            return false;
    /* "-" alone (a file name) and negative numbers ("-1", "-.5") are values */
    return value[0] == '-' && value[1] && value[1] != '.' && !(value[1] >= '0' && value[1] <= '9');
}

/* argv with every "--name=value" written as "--name" "value", as GNU's getopt takes it:
 * every command's parser then sees one form. NULL when out of memory. */
static char **split_assignments(int argc, char **argv, int *out_argc)
{
    int n = argc;
    for (int i = 1; i < argc; i++)
        n += strncmp(argv[i], "--", 2) == 0 && strchr(argv[i], '=') != NULL;
    char **out = calloc((size_t)n + 1, sizeof *out);
    assigned_values = calloc((size_t)(n - argc) + 1, sizeof *assigned_values);
    if (!out || !assigned_values) {
        free(out);
        return NULL;
    }
    int k = 0;
    for (int i = 0; i < argc; i++) {
        char *eq = i > 0 && strncmp(argv[i], "--", 2) == 0 ? strchr(argv[i], '=') : NULL;
        if (eq) {
            *eq = '\0'; /* argv's strings are the program's to change (C17 5.1.2.2.1) */
            out[k++] = argv[i];
            out[k++] = assigned_values[n_assigned_values++] = eq + 1;
        } else {
            out[k++] = argv[i];
        }
    }
    *out_argc = n;
    return out;
}

int main(int argc, char **argv)
{
    int rc = cli_environment_check();
    if (rc >= 0)
        return rc;
    if (argc < 2) {
        print_usage(stderr);
        return CLI_EXIT_USAGE;
    }
    char **split = split_assignments(argc, argv, &argc);
    if (!split) {
        fprintf(stderr, "thzmap: out of memory\n");
        return CLI_EXIT_FAILURE;
    }
    static char **process_argv; /* the process's: reachable until it ends */
    argv = process_argv = split;
    if (cli_is_help(argv[1]) || strcmp(argv[1], "--version") == 0) {
        if (argc > 2) {
            fprintf(stderr, "thzmap: %s takes no arguments, got '%s'\n\n", argv[1], argv[2]);
            print_usage(stderr);
            return CLI_EXIT_USAGE;
        }
        if (cli_is_help(argv[1]))
            print_usage(stdout);
        else
            printf("thzmap %s (revision %s)\n", thz_version(), thz_revision());
        return cli_stdout_finish(CLI_EXIT_OK);
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        if (strcmp(argv[1], commands[i].name) != 0)
            continue;
        rc = cli_mpi_init(&argc, &argv);
        if (rc >= 0)
            return rc;
        bool shared = cli_mpi_size() > 1; /* mpirun reports a rank's exit status itself */
        rc = cli_mpi_finalize(cli_stdout_finish(main_run(&commands[i], argc - 1, argv + 1)));
        return shared ? rc : cli_end_by_signal(rc);
    }
    /* under mpirun, rank 0 alone says so (every rank printed the usage) */
    const char *unknown = argv[1];
    rc = cli_mpi_init(&argc, &argv);
    if (rc >= 0)
        return rc;
    if (cli_mpi_rank() == 0) {
        fprintf(stderr, "thzmap: unknown %s '%s'\n\n", unknown[0] == '-' ? "option" : "command",
                unknown);
        print_usage(stderr);
    }
    return cli_mpi_finalize(CLI_EXIT_USAGE);
}
