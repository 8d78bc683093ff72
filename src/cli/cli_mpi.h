/* The program's side of MPI runs (docs/mpi.md): MPI is initialised only when the process
 * was launched by mpirun or srun (their environment says so), so that a plain `thzmap`
 * never needs an MPI runtime; and only here does a failure end the whole job
 * (MPI_Abort), because the other ranks may be waiting for the failed one. Without MPI
 * support (CMake found no MPI) every function acts as for one process. */
#ifndef THZ_CLI_CLI_MPI_H
#define THZ_CLI_CLI_MPI_H

#include <stdbool.h>

/* Initialises MPI when launched by mpirun or srun (MPI_THREAD_FUNNELED); returns -1 to
 * go on, or an exit status after printing why it cannot (MPI failed, or no MPI support
 * in a job of several ranks). */
int cli_mpi_init(int *argc, char ***argv);

/* MPI_Finalize if cli_mpi_init initialised MPI; returns rc. */
int cli_mpi_finalize(int rc);

/* This process's rank and the job's number of ranks (0 and 1 outside a job). */
int cli_mpi_rank(void);
int cli_mpi_size(void);

/* What to add to "interrupted" when signal sig stopped this rank of a job of several:
 * for SIGTERM, that mpirun sends it when another rank ended (a rank killed with SIGKILL
 * left rank 0 saying "interrupted", as if the user had stopped the job); else "". */
const char *cli_mpi_signal_note(int sig);

/* Ends every rank of the job with exit status rc (after this rank printed why). */
_Noreturn void cli_mpi_abort(int rc);

/* Collective: -1 when every rank may go on (go), else the lowest rank that may not;
 * *lead_rc gets rank 0's rc. */
int cli_mpi_agree(bool go, int rc, int *lead_rc);

/* On ranks other than 0 (whose argument errors and help rank 0 prints alike), stdout
 * and stderr go to /dev/null between quiet_begin and quiet_end. */
void cli_mpi_quiet_begin(void);
void cli_mpi_quiet_end(void);

#endif
