/* Overflow-checked allocation helpers. */
#include "core/alloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

void thz_populate(void *p, size_t bytes)
{
#if defined(__linux__)
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14; older headers lack it, older kernels refuse it */
#endif
    /* The whole pages the range touches: they are mapped, as the range is. */
    long size = sysconf(_SC_PAGESIZE);
    if (!p || bytes == 0 || size <= 0)
        return;
    const uintptr_t page = (uintptr_t)size;
    uintptr_t lo = (uintptr_t)p & ~(page - 1), hi = ((uintptr_t)p + bytes + page - 1) & ~(page - 1);
    (void)madvise((void *)lo, hi - lo, MADV_POPULATE_WRITE);
#else
    (void)p;
    (void)bytes;
#endif
}

char *thz_strdup(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

uint64_t thz_physical_memory_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES);
    long page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return 0;
    return (uint64_t)pages * (uint64_t)page;
}

/* A number from the first line of a file (cgroup's memory.max holds "max" or a number);
 * 0 when it has none. */
static uint64_t alloc_file_number(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    char line[64];
    uint64_t v = 0;
    if (fgets(line, sizeof line, f)) {
        char *end = NULL;
        unsigned long long x = strtoull(line, &end, 10);
        if (end != line)
            v = (uint64_t)x;
    }
    fclose(f);
    return v;
}

/* RLIMIT_AS (ulimit -v), UINT64_MAX when unlimited. */
static uint64_t alloc_address_space_limit(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY)
        return UINT64_MAX;
    return (uint64_t)rl.rlim_cur;
}

/* The memory limit of this process's cgroup, UINT64_MAX when unlimited or unknown: v2's
 * memory.max ("max" when unlimited), v1's memory.limit_in_bytes (a huge number then). */
static uint64_t alloc_cgroup_limit(void)
{
    FILE *f = fopen("/proc/self/cgroup", "r");
    if (!f)
        return UINT64_MAX;
    char line[4096], path[4200];
    uint64_t limit = UINT64_MAX;
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = '\0';
        uint64_t max = 0;
        if (strncmp(line, "0::", 3) == 0) {
            snprintf(path, sizeof path, "/sys/fs/cgroup%s/memory.max", line + 3);
            max = alloc_file_number(path);
        } else if (strstr(line, ":memory:")) {
            snprintf(path, sizeof path, "/sys/fs/cgroup/memory%s/memory.limit_in_bytes",
                     strstr(line, ":memory:") + 8);
            max = alloc_file_number(path);
        }
        if (max > 0 && max < limit)
            limit = max;
    }
    fclose(f);
    return limit;
}

uint64_t thz_address_space_limit_bytes(void)
{
    uint64_t as = alloc_address_space_limit();
    return as == UINT64_MAX ? 0 : as;
}

uint64_t thz_address_space_bytes(void)
{
    unsigned long long pages = 0;
    long page = sysconf(_SC_PAGESIZE);
    FILE *f = fopen("/proc/self/statm", "r"); /* its first number: the pages mapped */
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    return page > 0 ? (uint64_t)pages * (uint64_t)page : 0;
}

uint64_t thz_memory_limit_bytes(void)
{
    uint64_t have = thz_physical_memory_bytes(), as = alloc_address_space_limit(),
             group = alloc_cgroup_limit();
    if (have == 0)
        have = UINT64_MAX;
    have = as < have ? as : have;
    have = group < have ? group : have;
    return have == UINT64_MAX ? 0 : have;
}

uint64_t thz_process_memory_bytes(void)
{
    uint64_t rss = 0;
    FILE *f = fopen("/proc/self/status", "r");
    if (f) {
        char line[256];
        unsigned long long kb;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "VmRSS: %llu kB", &kb) == 1)
                rss = (uint64_t)kb * 1024u;
        fclose(f);
    }
    return rss;
}
