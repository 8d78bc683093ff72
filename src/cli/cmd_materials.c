/* thzmap materials: the material library shipped with the program, listed with each
 * entry's source, or one entry described with its index at a few frequencies. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "thzmap/thzmap.h"

#define CMD "materials"
#define MAX_FREQUENCIES 64
#define MAX_THZ 1000.0 /* far past any data; the models gave NaN at 1e200 THz and beyond */

/* The frequencies of the description when --at-thz is not given, in THz. */
static const double default_thz[] = {0.1, 0.3, 0.5, 1.0, 1.5, 2.0, 3.0};

static void print_help(void)
{
    printf("usage: thzmap materials [NAME] [--at-thz F1,F2,...]\n"
           "\n"
           "Without NAME, lists the material library shipped with thzmap: each entry's\n"
           "name, index model, basis (measured, model, fit or assumed), n and k at 1 THz,\n"
           "what it is, and its source. A scene material uses one with\n"
           "{\"library\": \"NAME\"}; keys given beside it override the entry.\n"
           "\n"
           "With NAME, describes that entry: its source, the frequency range the source\n"
           "states, and n, k, the relative permittivity eps' + i eps'', the attenuation\n"
           "4 pi k nu / c (1/m) and the normal-incidence reflectance from air at a few\n"
           "frequencies.\n"
           "\n"
           "options:\n"
           "  --at-thz F1,F2,...   frequencies of the description in THz, each above 0 and\n"
           "                       at most 1000\n"
           "                       (default 0.1,0.3,0.5,1,1.5,2,3)\n"
           "  -h, --help           this help\n");
}

/* Parses a comma-separated list of frequencies in THz into out (at most max). */
static bool parse_list(const char *text, double *out, size_t max, size_t *n)
{
    *n = 0;
    const char *p = text;
    while (*p) {
        char *end = NULL;
        double v = strtod(p, &end);
        if (end == p || !cli_decimal_text(p, (size_t)(end - p)) || !(v > 0.0 && v <= MAX_THZ) ||
            (*end && *end != ',') || *n == max)
            return false;
        out[(*n)++] = v;
        p = *end ? end + 1 : end;
    }
    return *n > 0;
}

static int list_all(const thz_library *lib)
{
    size_t n = thz_library_count(lib);
    printf("%zu materials (n + ik at 1 THz; 'thzmap materials NAME' describes one)\n\n", n);
    printf("%-20s %-13s %-9s %9s %9s  %s\n", "name", "model", "basis", "n", "k", "description");
    for (size_t i = 0; i < n; i++) {
        thz_library_material_info info;
        thz_library_optics o;
        thz_library_get_info(lib, i, &info);
        thz_library_optics_at(lib, i, 1e12, &o);
        printf("%-20s %-13s %-9s %9.4g %9.4g  %s\n", info.name, info.model, info.basis, o.n, o.k,
               info.description);
        printf("%-20s source: %s\n", "", info.source);
    }
    return CLI_EXIT_OK;
}

static int describe(const thz_library *lib, const char *name, const double *thz, size_t n_thz)
{
    size_t i = 0;
    thz_error err = {0};
    if (thz_library_find(lib, name, &i, &err) != THZ_OK)
        return cli_fail(&err);
    thz_library_material_info info;
    thz_library_get_info(lib, i, &info);
    printf("%s: %s\n", info.name, info.description);
    printf("model:  %s\n", info.model);
    printf("basis:  %s\n", info.basis);
    printf("source: %s\n", info.source);
    if (info.note[0])
        printf("note:   %s\n", info.note);
    /* An entry is an index only: the lobe belongs to the scene material using it. */
    printf("reflection: not part of the entry; the scene material's \"reflection\" "
           "(diffuse, specular or ward) applies, diffuse by default\n");
    if (info.has_valid_range)
        printf("stated validity: %.4g to %.4g THz\n", info.valid_from_thz, info.valid_to_thz);
    else
        printf("stated validity: none stated\n");
    if (info.n_data_ranges > 0) {
        bool itu = strcmp(info.model, "itu-p2040") == 0;
        printf("data: ");
        for (size_t r = 0; r < info.n_data_ranges; r++) {
            double lo, hi;
            thz_library_get_range(lib, i, r, &lo, &hi);
            printf("%s%.4g to %.4g THz", r ? ", " : "", lo, hi);
        }
        printf("%s\n", itu ? " (a scene whose channel bands leave these ranges is refused)"
                           : " (end values held beyond the ends)");
    }
    printf("\n%10s %10s %10s %11s %11s %13s %9s\n", "f (THz)", "n", "k", "eps'", "eps''",
           "alpha (1/m)", "R(0 deg)");
    bool outside = false;
    for (size_t j = 0; j < n_thz; j++) {
        thz_library_optics o;
        thz_library_optics_at(lib, i, thz[j] * 1e12, &o);
        bool out = !thz_library_in_range(lib, i, thz[j] * 1e12);
        outside |= out;
        printf("%10.4g %10.5g %10.5g %11.5g %11.5g %13.5g %9.5f%s\n", thz[j], o.n, o.k, o.eps_real,
               o.eps_imag, o.attenuation_per_m, o.normal_reflectance, out ? " *" : "");
    }
    /* what thz_library_in_range tests: the stated validity, and an itu-p2040 entry's
     * rows (the data's ranges listed above) */
    if (outside) {
        bool rows = strcmp(info.model, "itu-p2040") == 0;
        printf("\n* outside %s%s%s\n", info.has_valid_range ? "the stated validity" : "",
               info.has_valid_range && rows ? " or " : "", rows ? "the ranges the data cover" : "");
    }
    return CLI_EXIT_OK;
}

int cmd_materials(int argc, char **argv)
{
    const char *name = NULL;
    double thz[MAX_FREQUENCIES];
    size_t n_thz = sizeof default_thz / sizeof default_thz[0];
    memcpy(thz, default_thz, sizeof default_thz);
    for (int i = 1; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            print_help();
            return CLI_EXIT_OK;
        }
        if (strcmp(argv[i], "--at-thz") == 0) {
            if (i + 1 >= argc)
                return cli_usage_error(CMD, "--at-thz needs a list of frequencies in THz");
            if (!parse_list(argv[++i], thz, MAX_FREQUENCIES, &n_thz))
                return cli_usage_error(CMD,
                                       "--at-thz: expected up to %d frequencies above 0 and at "
                                       "most %g THz, separated by commas, got '%s'",
                                       MAX_FREQUENCIES, MAX_THZ, argv[i]);
        } else if (argv[i][0] == '-') {
            return cli_usage_error(CMD, "unknown option '%s'", argv[i]);
        } else if (name) {
            return cli_usage_error(CMD, "one material name at most, got '%s' and '%s'", name,
                                   argv[i]);
        } else {
            name = argv[i];
        }
    }
    thz_library *lib = NULL;
    thz_error err = {0};
    if (thz_library_load(&lib, &err) != THZ_OK)
        return cli_fail(&err);
    int rc = name ? describe(lib, name, thz, n_thz) : list_all(lib);
    thz_library_destroy(lib);
    return rc;
}
