/* OpenMP threads and the address space: what a thread maps, how many are running, and
 * starting them before the data that would leave them no room (threads.h). */
#define _GNU_SOURCE /* pthread_getattr_default_np */
#include "core/threads.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"

/* glibc gives each thread that allocates its own arena, reserved whole: HEAP_MAX_SIZE,
 * twice the largest mmap threshold (4 MiB x sizeof(long)), so 64 MiB on 64-bit systems. */
#define THREADS_ARENA_BYTES ((uint64_t)8u * 1024u * 1024u * sizeof(long))

uint64_t thz_thread_omp_stack_bytes(void)
{
    const char *s = getenv("OMP_STACKSIZE");
    if (!s || !*s)
        return 0;
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s)
        return 0;
    while (*end == ' ' || *end == '\t')
        end++;
    unsigned long long unit = 1024;
    if (*end) {
        switch (*end) {
        case 'b':
        case 'B':
            unit = 1;
            break;
        case 'k':
        case 'K':
            unit = 1024;
            break;
        case 'm':
        case 'M':
            unit = 1024ull * 1024;
            break;
        case 'g':
        case 'G':
            unit = 1024ull * 1024 * 1024;
            break;
        default:
            return 0;
        }
        end++;
        while (*end == ' ' || *end == '\t')
            end++;
        if (*end)
            return 0;
    }
    return v > ~0ull / unit ? ~0ull : v * unit;
}

uint64_t thz_thread_stack_bytes(void)
{
    uint64_t omp = thz_thread_omp_stack_bytes();
    if (omp > 0)
        return omp;
    size_t size = 8u * 1024u * 1024u; /* glibc's default under the usual ulimit -s 8192 */
    pthread_attr_t attr;
    if (pthread_getattr_default_np(&attr) == 0) {
        size_t s = 0;
        if (pthread_attr_getstacksize(&attr, &s) == 0 && s > 0)
            size = s;
        pthread_attr_destroy(&attr);
    }
    return size;
}

uint64_t thz_thread_address_bytes(void)
{
    long page = sysconf(_SC_PAGESIZE);
    uint64_t stack = thz_thread_stack_bytes();
    uint64_t guard = page > 0 ? (uint64_t)page : 4096u;
    return stack > UINT64_MAX - guard - THREADS_ARENA_BYTES ? UINT64_MAX
                                                            : stack + guard + THREADS_ARENA_BYTES;
}

int thz_threads_running(void)
{
    int n = 0;
    FILE *f = fopen("/proc/self/status", "r");
    if (f) {
        char line[256];
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "Threads: %d", &n) == 1)
                break;
        fclose(f);
    }
    return n > 0 ? n : 1;
}

int thz_threads_fitting(int threads)
{
    int want = thz_threads_or_all(threads);
    uint64_t limit = thz_address_space_limit_bytes();
    if (limit == 0 || want <= 1)
        return want;
    uint64_t used = thz_address_space_bytes(), per = thz_thread_address_bytes();
    /* the threads may take half the room left; the other half is the work's */
    uint64_t room = used < limit ? (limit - used) / 2 : 0;
    uint64_t more = per > 0 ? room / per : 0;
    int running = thz_threads_running(); /* the caller's team among them */
    uint64_t fit = (uint64_t)running + more;
    return fit < (uint64_t)want ? (int)(fit < 1 ? 1 : fit) : want;
}

int thz_threads_start(int threads)
{
    int n = thz_threads_fitting(threads);
#ifdef _OPENMP
    if (n < thz_threads_all())
        omp_set_num_threads(n); /* the default of the calls given no count */
    /* Their arenas come when they first allocate: glibc falls back to another arena when
     * one cannot be mapped, so a missing arena costs speed, never the run; made now they
     * would take 64 MiB each from the work (a render that ran under ulimit -v 300000 was
     * refused so). */
    if (n > 1) {
        volatile int started = 0;
#pragma omp parallel num_threads(n)
        {
#pragma omp atomic
            started++;
        }
        (void)started;
    }
#endif
    return n;
}
