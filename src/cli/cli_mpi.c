/* MPI start, agreement, abort and end for the commands that share ranks. */
#include "cli_mpi.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "cli.h"

#ifdef THZ_HAVE_MPI
#include <mpi.h>
#endif

/* Process state, like MPI's own: the rank, the job size, whether MPI was initialised
 * here, and the saved descriptors of a quiet rank. */
static int cli_rank = 0, cli_size = 1;
static bool cli_initialised = false;
static int cli_saved_out = -1, cli_saved_err = -1;

/* The launchers' environment: Open MPI's mpirun (OMPI_COMM_WORLD_SIZE), Slurm's srun
 * (PMI_SIZE with PMI-2, PMIX_RANK with PMIx, whose size is not in the environment: 1). */
static int cli_launched_size(void)
{
    const char *names[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        const char *v = getenv(names[i]);
        if (v && *v)
            return i < 2 && atoi(v) > 1 ? atoi(v) : 1;
    }
    return 0; /* not launched by an MPI launcher */
}

int cli_mpi_init(int *argc, char ***argv)
{
    int launched = cli_launched_size();
    if (launched == 0)
        return -1;
#ifdef THZ_HAVE_MPI
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "thzmap: MPI could not start\n");
        return CLI_EXIT_FAILURE;
    }
    cli_initialised = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &cli_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &cli_size);
    if (provided < MPI_THREAD_FUNNELED) {
        if (cli_rank == 0)
            fprintf(stderr, "thzmap: the MPI library does not allow threads "
                            "(MPI_THREAD_FUNNELED)\n");
        return cli_mpi_finalize(CLI_EXIT_FAILURE);
    }
    return -1;
#else
    (void)argc;
    (void)argv;
    if (launched == 1) /* srun -n 1 or mpirun -np 1: one process is what this thzmap does */
        return -1;
    fprintf(stderr,
            "thzmap: launched as one of %d MPI ranks, but this thzmap was built without "
            "MPI support (install libopenmpi-dev and rebuild); run it without mpirun\n",
            launched);
    return CLI_EXIT_USAGE;
#endif
}

int cli_mpi_finalize(int rc)
{
#ifdef THZ_HAVE_MPI
    if (cli_initialised)
        MPI_Finalize();
#endif
    cli_initialised = false;
    return rc;
}

int cli_mpi_rank(void)
{
    return cli_rank;
}

int cli_mpi_size(void)
{
    return cli_size;
}

const char *cli_mpi_signal_note(int sig)
{
    if (cli_size < 2 || sig != SIGTERM)
        return "";
    return " by SIGTERM, which mpirun sends every rank when one has ended (failed or killed: "
           "mpirun names it) or when mpirun itself was signalled";
}

void cli_mpi_abort(int rc)
{
    fflush(stdout);
    fflush(stderr);
#ifdef THZ_HAVE_MPI
    if (cli_initialised && cli_size > 1)
        MPI_Abort(MPI_COMM_WORLD, rc);
#endif
    exit(rc);
}

int cli_mpi_agree(bool go, int rc, int *lead_rc)
{
    *lead_rc = rc;
#ifdef THZ_HAVE_MPI
    if (cli_initialised && cli_size > 1) {
        int mine = go ? cli_size : cli_rank, first = cli_size;
        MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        MPI_Bcast(lead_rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
        return first < cli_size ? first : -1;
    }
#endif
    return go ? -1 : 0;
}

void cli_mpi_quiet_begin(void)
{
    if (cli_rank == 0 || cli_saved_out >= 0)
        return;
    fflush(stdout);
    fflush(stderr);
    int null = open("/dev/null", O_WRONLY);
    if (null < 0)
        return;
    cli_saved_out = dup(STDOUT_FILENO);
    cli_saved_err = dup(STDERR_FILENO);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    close(null);
}

void cli_mpi_quiet_end(void)
{
    if (cli_saved_out < 0)
        return;
    fflush(stdout);
    fflush(stderr);
    dup2(cli_saved_out, STDOUT_FILENO);
    dup2(cli_saved_err, STDERR_FILENO);
    close(cli_saved_out);
    close(cli_saved_err);
    cli_saved_out = cli_saved_err = -1;
}
