/* The benchmark's child processes and memory checks: see bench_child.h. */
#include "bench_child.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- Memory ------------------------------------------------------------------------- */

/* Bytes the OS says are available (MemAvailable), or 0 if unknown. */
double bench_mem_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    if (!f)
        return 0.0;
    char line[256];
    double kb = 0.0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
            break;
    fclose(f);
    return 1024.0 * kb;
}

/* The peak of a photon phase of n photons of the paper's case, with margin: 1.3 stored
 * records per photon (1.25 measured) of 28 bytes with up to a quarter of growth slack
 * (the pool's spare array, phase.c), the index build's scratch of 3/8 as many records,
 * the per-thread buffers and the render: 46 bytes per record and the buffers, counted
 * as 60 (the 32-byte record's figure, kept), times 1.3. */
double bench_bytes_needed(uint64_t photons)
{
    return (double)photons * 1.3 * 60.0 * 1.3;
}

bool bench_fits(uint64_t photons)
{
    double avail = bench_mem_available();
    return avail <= 0.0 || bench_bytes_needed(photons) <= avail;
}

/* ---- Child processes ----------------------------------------------------------------- */

typedef struct bench_child_header {
    int status;
    thz_error err;
} bench_child_header;

static bool bench_write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n > 0) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return false;
        p += k;
        n -= (size_t)k;
    }
    return true;
}

static bool bench_read_all(int fd, void *buf, size_t n)
{
    char *p = buf;
    while (n > 0) {
        ssize_t k = read(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return false;
        p += k;
        n -= (size_t)k;
    }
    return true;
}

/* Runs fn(arg, out) in a child; out (size bytes) comes back through a pipe. */
thz_status bench_fork(bench_job_fn fn, const void *arg, void *out, size_t size, bench_usage *usage,
                      thz_error *err)
{
    int fds[2];
    if (pipe(fds) != 0)
        return thz_error_set(err, THZ_ERR_IO, "bench: pipe: %s", strerror(errno));
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return thz_error_set(err, THZ_ERR_IO, "bench: fork: %s", strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        bench_child_header h;
        memset(&h, 0, sizeof h);
        memset(out, 0, size);
        h.status = (int)fn(arg, out, &h.err);
        bool ok = bench_write_all(fds[1], &h, sizeof h) && bench_write_all(fds[1], out, size);
        close(fds[1]);
        _exit(ok ? 0 : 1);
    }
    close(fds[1]);
    bench_child_header h;
    bool ok = bench_read_all(fds[0], &h, sizeof h) && bench_read_all(fds[0], out, size);
    close(fds[0]);
    int wstatus = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &wstatus, 0, &ru) < 0 && errno == EINTR) {
    }
    if (usage) {
        usage->peak_bytes = (uint64_t)ru.ru_maxrss * 1024u; /* Linux: kilobytes */
        usage->cpu_s = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                       (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    }
    if (!ok || !WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "bench: a measurement process failed");
    if (h.status != THZ_OK) {
        if (err)
            *err = h.err;
        return (thz_status)h.status;
    }
    return THZ_OK;
}

double bench_load1(void)
{
    double l[3];
    return getloadavg(l, 3) >= 1 ? l[0] : -1.0;
}
