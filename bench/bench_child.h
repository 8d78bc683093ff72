/* The benchmark's child processes and memory checks (bench/thzbench.c).
 *
 * Every measurement runs in a child process of its own (fork), so that the peak memory
 * the OS reports for it (wait4's rusage) is that measurement's alone and no OpenMP state
 * is shared across measurements; its results come back through a pipe as a fixed-size
 * struct.
 */
#ifndef THZ_BENCH_CHILD_H
#define THZ_BENCH_CHILD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* What the OS reports for a child: its peak resident memory and CPU time (user +
 * system, all threads: against wall time it shows how many cores the child got). */
typedef struct bench_usage {
    uint64_t peak_bytes;
    double cpu_s;
} bench_usage;

typedef thz_status (*bench_job_fn)(const void *arg, void *out, thz_error *err);

/* Runs fn(arg, out) in a child; out (size bytes) comes back through a pipe, usage (may
 * be NULL) from wait4. A child that fails returns its status and error. */
thz_status bench_fork(bench_job_fn fn, const void *arg, void *out, size_t size, bench_usage *usage,
                      thz_error *err);

/* Bytes the OS says are available (MemAvailable), or 0 if unknown. */
double bench_mem_available(void);

/* The peak of a photon phase of n photons of the paper's case, with margin. */
double bench_bytes_needed(uint64_t photons);

/* Whether a photon phase of n photons fits in the memory available now (true when
 * that is unknown). */
bool bench_fits(uint64_t photons);

/* The 1-minute load average, or -1 if unknown. */
double bench_load1(void);

#endif
