/* The process thzmap starts in: standard streams, signals and limits it cannot work
 * with, mended or refused before any work; and its standard output checked at the end. */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* The least stack a thread of thzmap's needs, with room: a photon-map gather takes 66 KiB
 * of it, and 64 KiB stacks (OMP_STACKSIZE=64K, ulimit -s 64) ended runs in SIGSEGV. */
#define CLI_MIN_STACK_BYTES (256u * 1024u)
/* Open files: a run holds a few (the lock, the output files, PLplot's driver and fonts
 * in the figure children); 16 sufficed for the examples, 8 did not. */
#define CLI_MIN_FILES 32u
#define CLI_WANT_FILES 1024u

int cli_environment_check(void)
{
    /* Standard streams closed at start: the first files opened would take their numbers
     * (the lock file beside OUTDIR received the progress lines). /dev/null takes them. */
    for (int fd = 0; fd <= 2; fd++) {
        if (fcntl(fd, F_GETFD) >= 0 || errno != EBADF)
            continue;
        int n = open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
        if (n >= 0 && n != fd) {
            dup2(n, fd);
            close(n);
        }
    }
    /* A file-size limit (ulimit -f): a write past it fails with EFBIG, which the writers
     * report and clean up after, instead of SIGXFSZ ending the process and leaving the
     * lock and the staging directory. */
    signal(SIGXFSZ, SIG_IGN);
    /* Few open files (ulimit -n 8): PLplot could not load its driver, and the message
     * named a missing package. The soft limit is raised towards the hard one, which any
     * process may do; below CLI_MIN_FILES even then, refused. */
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
        rl.rlim_cur < CLI_WANT_FILES) {
        rlim_t want = rl.rlim_max == RLIM_INFINITY || rl.rlim_max > CLI_WANT_FILES ? CLI_WANT_FILES
                                                                                   : rl.rlim_max;
        struct rlimit raised = {want, rl.rlim_max};
        if (want > rl.rlim_cur && setrlimit(RLIMIT_NOFILE, &raised) == 0)
            rl.rlim_cur = want;
        if (rl.rlim_cur < CLI_MIN_FILES) {
            fprintf(stderr,
                    "thzmap: the limit on open files (ulimit -n) is %llu, and no more than %llu "
                    "may be had; thzmap needs at least %u\n",
                    (unsigned long long)rl.rlim_cur, (unsigned long long)rl.rlim_max,
                    CLI_MIN_FILES);
            return CLI_EXIT_USAGE;
        }
    }
    if (getrlimit(RLIMIT_STACK, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
        rl.rlim_cur < CLI_MIN_STACK_BYTES) {
        fprintf(stderr,
                "thzmap: the stack size limit (ulimit -s) is %llu KiB; thzmap's threads need at "
                "least %u KiB (ulimit -s 8192, the usual limit, is plenty)\n",
                (unsigned long long)rl.rlim_cur / 1024, CLI_MIN_STACK_BYTES / 1024);
        return CLI_EXIT_USAGE;
    }
    unsigned long long omp = thz_omp_stack_bytes();
    if (omp > 0 && omp < CLI_MIN_STACK_BYTES) {
        fprintf(stderr,
                "thzmap: OMP_STACKSIZE=%s gives each thread %llu KiB of stack; thzmap's threads "
                "need at least %u KiB (unset it, or set 1M or more)\n",
                getenv("OMP_STACKSIZE"), omp / 1024, CLI_MIN_STACK_BYTES / 1024);
        return CLI_EXIT_USAGE;
    }
    return -1;
}

uint64_t cli_threads_prepare(const char *command, uint64_t threads)
{
    static int said; /* the count last warned of: main's default team, then the command's */
    int n = thz_threads_prepare((int)threads);
    if ((uint64_t)n == threads || n == said)
        return (uint64_t)n;
    said = n;
    struct rlimit rl;
    unsigned long long kib =
        getrlimit(RLIMIT_AS, &rl) == 0 ? (unsigned long long)rl.rlim_cur / 1024 : 0;
    fprintf(stderr,
            "thzmap %s: warning: the address space is limited (ulimit -v %llu KiB), and "
            "each thread maps its stack and a 64 MiB malloc arena: running with %d thread%s, "
            "as many as fit (raise ulimit -v, or lower OMP_STACKSIZE)\n",
            command, kib, n, n == 1 ? "" : "s");
    return (uint64_t)n;
}

uint64_t cli_threads_check(const char *command, uint64_t threads)
{
    threads = cli_threads_prepare(command, threads);
    cpu_set_t set;
    CPU_ZERO(&set);
    if (threads == 0 || sched_getaffinity(0, sizeof set, &set) != 0)
        return threads;
    int cpus = CPU_COUNT(&set);
    if (cpus < 1 || threads <= (uint64_t)cpus)
        return threads;
    /* Open MPI 4 binds each rank to a core (2 ranks or fewer) or a socket, Slurm's srun to
     * its --cpus-per-task (Slurm 22.05 to 23.02 do not take sbatch's): docs/mpi.md's hybrid
     * example ran its 8 threads a rank on one core, and nothing said so */
    fprintf(stderr,
            "thzmap %s: warning: --threads %llu, but this process may run on only %d CPU%s "
            "(its affinity: mpirun binds each rank to one core or socket unless given "
            "--bind-to none or --map-by slot:PE=%llu, srun to its --cpus-per-task); the threads "
            "will share %s\n",
            command, (unsigned long long)threads, cpus, cpus == 1 ? "" : "s",
            (unsigned long long)threads, cpus == 1 ? "it" : "them");
    return threads;
}

int cli_stdout_finish(int rc)
{
    errno = 0;
    bool failed = fflush(stdout) != 0 || ferror(stdout);
    if (!failed)
        return rc;
    int e = errno;
    /* a reader of the output that left (`| head -1`) under an ignored SIGPIPE: the run's
     * results stand (without that, SIGPIPE ends the process, 141) */
    struct stat st;
    if (e == EPIPE || (e == 0 && fstat(STDOUT_FILENO, &st) == 0 && S_ISFIFO(st.st_mode)))
        return rc;
    fprintf(stderr, "thzmap: cannot write the standard output%s%s\n", e ? ": " : "",
            e ? strerror(e) : "");
    return rc != CLI_EXIT_OK ? rc : CLI_EXIT_FAILURE;
}
