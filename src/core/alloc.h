/* Overflow-checked allocation. Every array allocation goes through these so that a
 * size computed from user input cannot wrap around. */
#ifndef THZ_CORE_ALLOC_H
#define THZ_CORE_ALLOC_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/* calloc-like: n elements of size bytes, zeroed; NULL on overflow or exhaustion. */
static inline void *thz_calloc(size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size)
        return NULL;
    return calloc(n ? n : 1, size ? size : 1);
}

/* malloc of n*size bytes; NULL on overflow or exhaustion. */
static inline void *thz_malloc_array(size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size)
        return NULL;
    size_t bytes = n * size;
    return malloc(bytes ? bytes : 1);
}

/* realloc of n*size bytes; NULL (and p untouched) on overflow or exhaustion. */
static inline void *thz_realloc_array(void *p, size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size)
        return NULL;
    size_t bytes = n * size;
    return realloc(p, bytes ? bytes : 1);
}

/* An array's next capacity: `first` elements, then twice as many each time (amortised
 * O(1) appends). Reallocates p for it and sets *capacity; NULL (p and *capacity
 * untouched) on overflow or exhaustion. */
static inline void *thz_grow_array(void *p, size_t *capacity, size_t first, size_t size)
{
    size_t cap = *capacity ? 2 * *capacity : first;
    if (cap < *capacity)
        return NULL;
    void *q = thz_realloc_array(p, cap, size);
    if (q)
        *capacity = cap;
    return q;
}

/* Asks the kernel to map the pages under [p, p + bytes) for writing now, in one call
 * (MADV_POPULATE_WRITE, Linux 5.14 on), rather than a fault on each page's first write; the
 * contents are unchanged. A hint: where it is not supported nothing happens. For memory
 * about to be written whole: on this project's VMs (a shadow-paging hypervisor) a 4 KB page
 * new to the process cost ~10 us on its first write, and the call halves that (512 MB, 2
 * threads: 0.78 -> 0.42 s, 2026-12-05). */
void thz_populate(void *p, size_t bytes);

/* strdup that returns NULL for NULL. */
char *thz_strdup(const char *s);

/* Bytes of physical memory of this machine (0 if unknown). Used to refuse runs whose
 * images or photon maps would not fit, before they start. */
uint64_t thz_physical_memory_bytes(void);
/* The memory a run may count on (0 if unknown): the machine's, or less where the process
 * is held to less: its address-space limit (ulimit -v), its cgroup's memory limit (a
 * container, a Slurm job). Runs are refused against it before they start: under
 * `ulimit -v 6G` a run estimated at 14.9 GiB was accepted and failed after 26 s. */
uint64_t thz_memory_limit_bytes(void);
/* The memory this process holds now (its resident set; 0 if unknown): the scene's
 * meshes and the ray-casting structure, which a run's estimate counts. */
uint64_t thz_process_memory_bytes(void);
/* The address space this process has mapped now (0 if unknown): beside what it holds,
 * its libraries, thread stacks, malloc arenas and Embree's reserved pool, which count
 * against an address-space limit though little of them is resident. */
uint64_t thz_address_space_bytes(void);
/* RLIMIT_AS (ulimit -v) in bytes, 0 when unlimited. */
uint64_t thz_address_space_limit_bytes(void);

#endif
