/* The harnesses' temporary files and fixture data directory (fuzz.h). */
#include "fuzz.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char temp_dir[PATH_MAX];
static char temp_path[PATH_MAX];
static char temp_names[8][64]; /* files made, removed at exit with the directory */
static size_t n_temp_names;

static void remove_temp_dir(void)
{
    for (size_t i = 0; i < n_temp_names; i++) {
        if (snprintf(temp_path, sizeof temp_path, "%s/%s", temp_dir, temp_names[i]) <
            (int)sizeof temp_path)
            unlink(temp_path);
    }
    rmdir(temp_dir);
}

static void make_temp_dir(void)
{
    const char *tmp = getenv("TMPDIR");
    if (snprintf(temp_dir, sizeof temp_dir, "%s/thz-fuzz-XXXXXX", tmp && *tmp ? tmp : "/tmp") >=
            (int)sizeof temp_dir ||
        !mkdtemp(temp_dir)) {
        perror("fuzz: mkdtemp");
        abort();
    }
    atexit(remove_temp_dir);
}

const char *fuzz_temp_file(const char *name, const uint8_t *data, size_t size)
{
    if (!temp_dir[0])
        make_temp_dir();
    size_t i = 0;
    while (i < n_temp_names && strcmp(temp_names[i], name) != 0)
        i++;
    if (i == n_temp_names) {
        if (n_temp_names == sizeof temp_names / sizeof temp_names[0] ||
            strlen(name) >= sizeof temp_names[0])
            abort();
        strcpy(temp_names[n_temp_names++], name);
    }
    if (snprintf(temp_path, sizeof temp_path, "%s/%s", temp_dir, name) >= (int)sizeof temp_path)
        abort();
    FILE *f = fopen(temp_path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
        perror("fuzz: cannot write the input file");
        abort();
    }
    return temp_path;
}

void fuzz_use_fixture_data(void)
{
    setenv("THZMAP_DATA_DIR", FUZZ_DIR "/data", 1);
}

void fuzz_report(const char *message)
{
    if (getenv("FUZZ_VERBOSE"))
        fprintf(stderr, "fuzz: %s\n", message);
}
