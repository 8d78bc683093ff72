/* Replays inputs through a harness without libFuzzer: each argument is a file or a
 * directory of files (tests/fuzz/corpus/<harness>, tests/fuzz/regressions/<harness>),
 * each file is passed once to LLVMFuzzerTestOneInput. A crash or a sanitizer report
 * ends the program (the test fails); an input slower than --max-seconds (default 1)
 * is reported and makes the exit status 1, as libFuzzer's -timeout would. "Slower" is
 * judged on the smaller of the wall-clock and the CPU time the input took, so that
 * neither a loaded machine (wall time, not CPU) nor threads (CPU, not wall time) make a
 * fast input look slow. tests/fuzz/run.sh confirms libFuzzer's timeouts with it.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "fuzz.h"

static double wall_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* User + system CPU time of the process, all threads. */
static double cpu_s(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Runs one file; returns 1 if it was too slow, 0 otherwise; exits on a read error. */
static int replay_file(const char *path, double max_seconds)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        exit(2);
    }
    size_t cap = 4096, n = 0;
    uint8_t *data = malloc(cap);
    size_t got;
    while (data && (got = fread(data + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            uint8_t *bigger = realloc(data, cap *= 2);
            if (!bigger)
                free(data);
            data = bigger;
        }
    }
    if (!data || ferror(f)) {
        fprintf(stderr, "%s: cannot read\n", path);
        exit(2);
    }
    fclose(f);
    /* libFuzzer hands a copy of exactly `size` bytes: so does this */
    uint8_t *copy = malloc(n ? n : 1);
    memcpy(copy, data, n);
    free(data);
    double wall0 = wall_s(), cpu0 = cpu_s();
    LLVMFuzzerTestOneInput(copy, n);
    double wall = wall_s() - wall0, cpu = cpu_s() - cpu0;
    free(copy);
    if (wall > max_seconds && cpu > max_seconds) {
        fprintf(stderr, "%s: slow input: %.3f s wall-clock, %.3f s CPU (limit %.3f s)\n", path,
                wall, cpu, max_seconds);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    double max_seconds = 1.0;
    int slow = 0, files = 0;
    LLVMFuzzerInitialize(&argc, &argv);
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--max-seconds") == 0 && a + 1 < argc) {
            max_seconds = atof(argv[++a]);
            continue;
        }
        struct stat st;
        if (stat(argv[a], &st) != 0) {
            perror(argv[a]);
            return 2;
        }
        if (!S_ISDIR(st.st_mode)) {
            slow += replay_file(argv[a], max_seconds);
            files++;
            continue;
        }
        DIR *d = opendir(argv[a]);
        if (!d) {
            perror(argv[a]);
            return 2;
        }
        size_t n = 0, cap = 64;
        char **names = malloc(cap * sizeof *names);
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.')
                continue;
            if (n == cap)
                names = realloc(names, (cap *= 2) * sizeof *names);
            size_t len = strlen(argv[a]) + strlen(e->d_name) + 2;
            names[n] = malloc(len);
            snprintf(names[n++], len, "%s/%s", argv[a], e->d_name);
        }
        closedir(d);
        qsort(names, n, sizeof *names, compare_names);
        for (size_t i = 0; i < n; i++) {
            slow += replay_file(names[i], max_seconds);
            files++;
            free(names[i]);
        }
        free(names);
    }
    printf("replayed %d inputs, %d slower than %.3f s\n", files, slow, max_seconds);
    if (files == 0) {
        fprintf(stderr, "no inputs: a replay that runs nothing tests nothing\n");
        return 2;
    }
    return slow ? 1 : 0;
}
