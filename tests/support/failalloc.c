/* failalloc: an LD_PRELOAD shim that makes the Nth allocation fail, for
 * tests/cli/test_alloc_fail.sh (issue 20).
 *
 * Every call of malloc, calloc, realloc, reallocarray, posix_memalign, aligned_alloc,
 * memalign, valloc and pvalloc made after the shim's constructor ran (so the dynamic
 * loader's and the C library's own start-up are not counted) is numbered 1, 2, ...
 * across all threads. Environment:
 *   THZ_FAIL_ALLOC_AT=N       call N returns NULL (ENOMEM); 0 or unset: none fails
 *   THZ_FAIL_ALLOC_REPORT=F   at exit, append "PID COUNT FAILED" to file F: the calls
 *                             counted in this process and whether call N failed in it
 *   THZ_FAIL_ALLOC_IN=NAME:K  instead, the Kth call made from the code of the loaded
 *                             library whose file name contains NAME fails (calls from it
 *                             counted apart; "libzstd.so:2"); for a library's own
 *                             allocations, which a change elsewhere would move in N
 *   THZ_FAIL_ALLOC_BACKTRACE=1  print the stack of the failing call to stderr
 * (or run under gdb with a breakpoint on failalloc_hit).
 * A forked child inherits the count and goes on numbering from there; it reports too
 * (also when it leaves through _exit). The real allocator is found with
 * dlsym(RTLD_NEXT), so the shim also works in front of AddressSanitizer's allocator
 * (run with ASAN_OPTIONS=verify_asan_link_order=0). There, LeakSanitizer counts what the
 * dynamic loader allocates as reachable (the loader keeps those pointers in memory LSan
 * does not scan, such as the main program's link map), recognising it by the caller of
 * malloc; in front of it, that caller is the shim. So the shim marks the loader's
 * allocations itself (__lsan_ignore_object): without this, every process that dlopens a
 * library reports its global-scope array (320 bytes, add_to_global_resize) as a leak.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <elf.h>
#include <execinfo.h>
#include <errno.h>
#include <fcntl.h>
#include <link.h>
#include <malloc.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/auxv.h>
#include <sys/syscall.h>
#include <unistd.h>

#define EXPORT __attribute__((visibility("default")))

static void *(*real_malloc)(size_t);
static void *(*real_calloc)(size_t, size_t);
static void *(*real_realloc)(void *, size_t);
static void (*real_free)(void *);
static int (*real_posix_memalign)(void **, size_t, size_t);
static void *(*real_aligned_alloc)(size_t, size_t);
static void *(*real_memalign)(size_t, size_t);

static atomic_uint_least64_t counted;
static atomic_int armed;  /* counting starts when the constructor has run */
static atomic_int failed; /* call N failed in this process */
static uint64_t fail_at;  /* 0: never */

/* dlsym may allocate before the real functions are known: serve it from here. */
static _Alignas(16) char boot_arena[16384];
static atomic_size_t boot_used;

static void *boot_alloc(size_t n)
{
    n = (n + 15) & ~(size_t)15;
    size_t at = atomic_fetch_add(&boot_used, n);
    return at + n <= sizeof boot_arena ? boot_arena + at : NULL;
}

static int in_boot_arena(const void *p)
{
    return (const char *)p >= boot_arena && (const char *)p < boot_arena + sizeof boot_arena;
}

/* The dynamic loader's address range, and LeakSanitizer's hook (NULL without it). */
static uintptr_t loader_lo, loader_hi;
static void (*lsan_ignore_object)(const void *);

/* Finds the loader's mapped range from its ELF program headers (AT_BASE is where it is
 * loaded); reads memory only: this runs while the loader may hold its locks. */
static void find_loader(void)
{
    uintptr_t base = (uintptr_t)getauxval(AT_BASE);
    if (!base)
        return;
    const ElfW(Ehdr) *eh = (const ElfW(Ehdr) *)base;
    const ElfW(Phdr) *ph = (const ElfW(Phdr) *)(base + eh->e_phoff);
    uintptr_t lo = UINTPTR_MAX, hi = 0;
    for (int i = 0; i < eh->e_phnum; i++) {
        if (ph[i].p_type != PT_LOAD)
            continue;
        if (base + ph[i].p_vaddr < lo)
            lo = base + ph[i].p_vaddr;
        if (base + ph[i].p_vaddr + ph[i].p_memsz > hi)
            hi = base + ph[i].p_vaddr + ph[i].p_memsz;
    }
    if (hi > lo) {
        loader_lo = lo;
        loader_hi = hi;
    }
}

/* p was allocated for the code at caller: if that is the loader, LSan must not report it. */
static void *note_caller(void *p, const void *caller)
{
    if (p && lsan_ignore_object && (uintptr_t)caller >= loader_lo && (uintptr_t)caller < loader_hi)
        lsan_ignore_object(p);
    return p;
}

static void resolve(void)
{
    static atomic_int resolving;
    if (real_malloc || atomic_exchange(&resolving, 1))
        return;
    find_loader();
    *(void **)&lsan_ignore_object = dlsym(RTLD_DEFAULT, "__lsan_ignore_object");
    *(void **)&real_calloc = dlsym(RTLD_NEXT, "calloc");
    *(void **)&real_realloc = dlsym(RTLD_NEXT, "realloc");
    *(void **)&real_free = dlsym(RTLD_NEXT, "free");
    *(void **)&real_posix_memalign = dlsym(RTLD_NEXT, "posix_memalign");
    *(void **)&real_aligned_alloc = dlsym(RTLD_NEXT, "aligned_alloc");
    *(void **)&real_memalign = dlsym(RTLD_NEXT, "memalign");
    *(void **)&real_malloc = dlsym(RTLD_NEXT, "malloc");
}

/* Called when call N fails: a place for a debugger's breakpoint. */
__attribute__((noinline)) void failalloc_hit(uint64_t n);
EXPORT __attribute__((noinline)) void failalloc_hit(uint64_t n)
{
    __asm__ volatile("" : : "r"(n) : "memory");
    if (getenv("THZ_FAIL_ALLOC_BACKTRACE")) {
        void *frames[48];
        int depth = backtrace(frames, 48);
        dprintf(2, "failalloc: call %llu fails in process %ld:\n", (unsigned long long)n,
                (long)getpid());
        backtrace_symbols_fd(frames, depth, 2);
    }
}

/* THZ_FAIL_ALLOC_IN: the library's mapped range, its calls counted so far, and K. */
static uintptr_t in_lo, in_hi;
static atomic_uint_least64_t in_counted;
static uint64_t in_k;

/* dl_iterate_phdr's callback: the range of the first object whose name contains data. */
static int find_in(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    if (!info->dlpi_name || !strstr(info->dlpi_name, (const char *)data))
        return 0;
    uintptr_t lo = UINTPTR_MAX, hi = 0;
    for (int i = 0; i < info->dlpi_phnum; i++) {
        const ElfW(Phdr) *ph = &info->dlpi_phdr[i];
        if (ph->p_type != PT_LOAD)
            continue;
        uintptr_t a = info->dlpi_addr + ph->p_vaddr;
        lo = a < lo ? a : lo;
        hi = a + ph->p_memsz > hi ? a + ph->p_memsz : hi;
    }
    in_lo = lo;
    in_hi = hi;
    return 1;
}

/* Set while the calling thread is inside pthread_getattr_np for the sanitizer (below). */
static _Thread_local int exempt;

/* True when this call (from code at caller) is the one to fail. */
static int should_fail(const void *caller)
{
    if (!atomic_load_explicit(&armed, memory_order_relaxed) || exempt)
        return 0;
    uint64_t n = atomic_fetch_add_explicit(&counted, 1, memory_order_relaxed) + 1;
    if (in_k) {
        uintptr_t c = (uintptr_t)caller;
        if (c < in_lo || c >= in_hi ||
            atomic_fetch_add_explicit(&in_counted, 1, memory_order_relaxed) + 1 != in_k)
            return 0;
        atomic_store(&failed, 1);
        failalloc_hit(in_k);
        return 1;
    }
    if (fail_at && n == fail_at) {
        atomic_store(&failed, 1);
        failalloc_hit(n);
        return 1;
    }
    return 0;
}

static void report(void)
{
    const char *path = getenv("THZ_FAIL_ALLOC_REPORT");
    if (!path || !*path)
        return;
    char line[96];
    int n = snprintf(line, sizeof line, "%ld %llu %d\n", (long)getpid(),
                     (unsigned long long)atomic_load(&counted), atomic_load(&failed));
    int fd = open(path, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd >= 0) {
        if (n > 0 && write(fd, line, (size_t)n) < 0) {
            /* nothing to do: the report is best effort */
        }
        close(fd);
    }
}

__attribute__((constructor)) static void failalloc_init(void)
{
    resolve();
    if (getenv("THZ_FAIL_ALLOC_BACKTRACE")) { /* backtrace() loads libgcc_s once: not later */
        void *frame;
        backtrace(&frame, 1);
    }
    const char *at = getenv("THZ_FAIL_ALLOC_AT");
    fail_at = at ? strtoull(at, NULL, 10) : 0;
    const char *in = getenv("THZ_FAIL_ALLOC_IN");
    const char *colon = in ? strrchr(in, ':') : NULL;
    if (colon && colon > in && colon - in < 256) {
        char name[256];
        memcpy(name, in, (size_t)(colon - in));
        name[colon - in] = '\0';
        dl_iterate_phdr(find_in, name);
        in_k = in_hi > in_lo ? strtoull(colon + 1, NULL, 10) : 0;
    }
    atomic_store(&armed, 1);
}

__attribute__((destructor)) static void failalloc_fini(void)
{
    atomic_store(&armed, 0); /* exit handlers after this one may still allocate */
    report();
}

EXPORT void _exit(int status)
{
    atomic_store(&armed, 0);
    report();
    syscall(SYS_exit_group, status);
    __builtin_unreachable();
}

EXPORT void _Exit(int status)
{
    _exit(status);
}

/* AddressSanitizer's runtime calls pthread_getattr_np as each thread starts, and stops
 * the process (a failed CHECK) when that cannot allocate: not a failure thzmap could
 * handle, nor one the release build has. In the sanitizer build (where LSan's hook
 * exists), what it allocates is neither counted nor made to fail, whoever calls it. */
EXPORT int pthread_getattr_np(pthread_t thread, pthread_attr_t *attr)
{
    static int (*real_getattr)(pthread_t, pthread_attr_t *);
    if (!real_getattr)
        *(void **)&real_getattr = dlsym(RTLD_NEXT, "pthread_getattr_np");
    if (!lsan_ignore_object)
        return real_getattr(thread, attr);
    exempt++;
    int r = real_getattr(thread, attr);
    exempt--;
    return r;
}

EXPORT void *malloc(size_t n)
{
    if (!real_malloc) {
        resolve();
        if (!real_malloc)
            return boot_alloc(n);
    }
    if (should_fail(__builtin_return_address(0))) {
        errno = ENOMEM;
        return NULL;
    }
    return note_caller(real_malloc(n), __builtin_return_address(0));
}

EXPORT void *calloc(size_t n, size_t size)
{
    if (!real_calloc) {
        resolve();
        if (!real_calloc)
            return boot_alloc(n * size); /* the arena is zeroed */
    }
    if (should_fail(__builtin_return_address(0))) {
        errno = ENOMEM;
        return NULL;
    }
    return note_caller(real_calloc(n, size), __builtin_return_address(0));
}

EXPORT void *realloc(void *p, size_t n)
{
    if (in_boot_arena(p)) { /* grow a boot allocation into a real one */
        size_t avail = (size_t)(boot_arena + sizeof boot_arena - (char *)p);
        void *q = malloc(n);
        if (q)
            memcpy(q, p, n < avail ? n : avail);
        return q;
    }
    if (!real_realloc)
        resolve();
    if (should_fail(__builtin_return_address(0))) {
        errno = ENOMEM;
        return NULL;
    }
    return note_caller(real_realloc(p, n), __builtin_return_address(0));
}

EXPORT void *reallocarray(void *p, size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size) {
        errno = ENOMEM;
        return NULL;
    }
    return realloc(p, n * size);
}

EXPORT void free(void *p)
{
    if (!p || in_boot_arena(p))
        return;
    if (!real_free)
        resolve();
    real_free(p);
}

EXPORT int posix_memalign(void **out, size_t align, size_t n)
{
    if (!real_posix_memalign)
        resolve();
    if (should_fail(__builtin_return_address(0)))
        return ENOMEM;
    return real_posix_memalign(out, align, n);
}

EXPORT void *aligned_alloc(size_t align, size_t n)
{
    if (!real_aligned_alloc)
        resolve();
    if (should_fail(__builtin_return_address(0))) {
        errno = ENOMEM;
        return NULL;
    }
    return real_aligned_alloc(align, n);
}

EXPORT void *memalign(size_t align, size_t n)
{
    if (!real_memalign)
        resolve();
    if (should_fail(__builtin_return_address(0))) {
        errno = ENOMEM;
        return NULL;
    }
    return real_memalign(align, n);
}

EXPORT void *valloc(size_t n)
{
    return memalign((size_t)sysconf(_SC_PAGESIZE), n);
}

EXPORT void *pvalloc(size_t n)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    return memalign(page, (n + page - 1) / page * page);
}
