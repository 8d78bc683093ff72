/* The MPI transport of shared photon phases: the lead's broadcast requests, the members'
 * shares in messages of at most 1 GiB, polling waits. */
#include "mpi/mpi_team.h"

#include <mpi.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"

enum { TEAM_TAG_HEADER = 1, TEAM_TAG_RECORDS, TEAM_TAG_CHUNKS };

/* MPI counts are int: larger payloads go in pieces of this many bytes. */
#define TEAM_PIECE_BYTES ((size_t)1 << 30)

struct mpi_team {
    MPI_Comm comm; /* a duplicate of MPI_COMM_WORLD, errors returned (not fatal) */
    int rank, size;
    photon_phase_team phase; /* the lead's interface, impl = this team */
    uint64_t bytes;          /* sent and received */
};

/* What the lead broadcasts: a phase to fire, or the end of the team's work. */
typedef struct team_message {
    uint64_t stop;
    photon_phase_request rq;
} team_message;

/* What a member sends first: the sizes of its share. */
typedef struct team_header {
    uint64_t count, n_chunks;
} team_header;

static thz_status team_error(thz_error *err, int rc, const char *what)
{
    char text[MPI_MAX_ERROR_STRING] = "";
    int len = 0;
    if (MPI_Error_string(rc, text, &len) != MPI_SUCCESS)
        snprintf(text, sizeof text, "error %d", rc);
    return thz_error_set(err, THZ_ERR_IO, "MPI: %s: %s", what, text);
}

/* Waits for req, polling with a pause that doubles from 50 us to 5 ms: a waiting rank
 * (a member while rank 0 renders, for seconds) leaves the cores to the working ones. */
static int team_wait(MPI_Request *req)
{
    long pause_ns = 50000;
    for (;;) {
        int done = 0;
        int rc = MPI_Test(req, &done, MPI_STATUS_IGNORE);
        if (rc != MPI_SUCCESS || done)
            return rc;
        struct timespec pause = {.tv_sec = 0, .tv_nsec = pause_ns};
        nanosleep(&pause, NULL);
        pause_ns = pause_ns < 5000000 ? 2 * pause_ns : 5000000;
    }
}

static int team_bcast(mpi_team *t, team_message *m)
{
    MPI_Request req;
    int rc = MPI_Ibcast(m, (int)sizeof *m, MPI_BYTE, 0, t->comm, &req);
    if (rc == MPI_SUCCESS)
        rc = team_wait(&req);
    if (rc == MPI_SUCCESS)
        t->bytes += sizeof *m * (t->rank == 0 ? (uint64_t)(t->size - 1) : 1u);
    return rc;
}

/* Sends (to the lead) or receives (from rank `peer`) `bytes` bytes in pieces. */
static int team_move(mpi_team *t, void *data, size_t bytes, int peer, int tag, bool send)
{
    char *p = data;
    while (bytes > 0) {
        size_t n = bytes < TEAM_PIECE_BYTES ? bytes : TEAM_PIECE_BYTES;
        MPI_Request req;
        int rc = send ? MPI_Isend(p, (int)n, MPI_BYTE, peer, tag, t->comm, &req)
                      : MPI_Irecv(p, (int)n, MPI_BYTE, peer, tag, t->comm, &req);
        if (rc == MPI_SUCCESS)
            rc = team_wait(&req);
        if (rc != MPI_SUCCESS)
            return rc;
        p += n;
        bytes -= n;
        t->bytes += n;
    }
    return MPI_SUCCESS;
}

static thz_status team_start(void *impl, const photon_phase_request *rq, thz_error *err)
{
    team_message m = {.stop = 0, .rq = *rq};
    int rc = team_bcast(impl, &m);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "broadcasting a photon phase");
}

static thz_status team_gather(void *impl, photon_phase_share *share, thz_error *err)
{
    mpi_team *t = impl;
    team_header *head = thz_calloc((size_t)t->size, sizeof *head);
    if (!head)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for the shares' sizes");
    thz_status st = THZ_OK;
    int rc = MPI_SUCCESS;
    uint64_t count = share->count, n_chunks = share->n_chunks;
    photon_record *records = NULL;
    trace_counters *chunks = NULL;
    for (int r = 1; rc == MPI_SUCCESS && r < t->size; r++) {
        rc = team_move(t, &head[r], sizeof head[r], r, TEAM_TAG_HEADER, false);
        count += head[r].count;
        n_chunks += head[r].n_chunks;
    }
    if (rc != MPI_SUCCESS) {
        st = team_error(err, rc, "receiving the sizes of the photon shares");
        goto cleanup;
    }
    records = count <= SIZE_MAX
                  ? thz_realloc_array(share->records, count ? count : 1, sizeof *records)
                  : NULL;
    if (records)
        share->records = records;
    chunks = n_chunks <= SIZE_MAX
                 ? thz_realloc_array(share->chunks, n_chunks ? n_chunks : 1, sizeof *chunks)
                 : NULL;
    if (chunks)
        share->chunks = chunks;
    if (!records || !chunks) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for %llu photon records",
                           (unsigned long long)count);
        goto cleanup;
    }
    for (int r = 1; rc == MPI_SUCCESS && r < t->size; r++) {
        rc = team_move(t, share->records + share->count, head[r].count * sizeof *records, r,
                       TEAM_TAG_RECORDS, false);
        if (rc == MPI_SUCCESS)
            rc = team_move(t, share->chunks + share->n_chunks, head[r].n_chunks * sizeof *chunks, r,
                           TEAM_TAG_CHUNKS, false);
        if (rc == MPI_SUCCESS) {
            share->count += head[r].count;
            share->n_chunks += head[r].n_chunks;
        }
    }
    if (rc != MPI_SUCCESS)
        st = team_error(err, rc, "receiving the photon shares");
cleanup:
    free(head);
    return st;
}

thz_status mpi_team_create(mpi_team **out, thz_error *err)
{
    *out = NULL;
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: not initialised (MPI_Init first)");
    mpi_team *t = thz_calloc(1, sizeof *t);
    if (!t)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory");
    int rc = MPI_Comm_dup(MPI_COMM_WORLD, &t->comm);
    if (rc != MPI_SUCCESS) {
        free(t);
        return team_error(err, rc, "duplicating MPI_COMM_WORLD");
    }
    MPI_Comm_set_errhandler(t->comm, MPI_ERRORS_RETURN);
    MPI_Comm_rank(t->comm, &t->rank);
    MPI_Comm_size(t->comm, &t->size);
    t->phase = (photon_phase_team){
        .members = (size_t)t->size, .start = team_start, .gather = team_gather, .impl = t};
    *out = t;
    return THZ_OK;
}

void mpi_team_destroy(mpi_team *team)
{
    if (!team)
        return;
    if (team->rank == 0) {
        team_message m = {.stop = 1};
        team_bcast(team, &m);
    }
    MPI_Comm_free(&team->comm);
    free(team);
}

size_t mpi_team_rank(const mpi_team *team)
{
    return (size_t)team->rank;
}

size_t mpi_team_size(const mpi_team *team)
{
    return (size_t)team->size;
}

const photon_phase_team *mpi_team_phase(const mpi_team *team)
{
    return &team->phase;
}

uint64_t mpi_team_bytes(const mpi_team *team)
{
    return team ? team->bytes : 0;
}

thz_status mpi_team_serve(mpi_team *team, const thz_scene *scene, const accel *acc, int threads,
                          thz_error *err)
{
    if (team->rank == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: rank 0 leads, it does not serve");
    for (;;) {
        team_message m;
        int rc = team_bcast(team, &m);
        if (rc != MPI_SUCCESS)
            return team_error(err, rc, "waiting for the lead's request");
        if (m.stop)
            return THZ_OK;
        if (!acc) /* this rank's settings need no photons, the lead's do */
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "MPI: the lead asks for photons but process %d's integrator "
                                 "fires none (every process must run with the same options)",
                                 team->rank);
        photon_phase_share share;
        thz_status st = photon_phase_fire_share(scene, acc, &m.rq, threads, (size_t)team->rank,
                                                (size_t)team->size, &share, err);
        if (st != THZ_OK)
            return st;
        team_header head = {.count = share.count, .n_chunks = share.n_chunks};
        rc = team_move(team, &head, sizeof head, 0, TEAM_TAG_HEADER, true);
        if (rc == MPI_SUCCESS)
            rc = team_move(team, share.records, share.count * sizeof *share.records, 0,
                           TEAM_TAG_RECORDS, true);
        if (rc == MPI_SUCCESS)
            rc = team_move(team, share.chunks, share.n_chunks * sizeof *share.chunks, 0,
                           TEAM_TAG_CHUNKS, true);
        photon_phase_share_fini(&share);
        if (rc != MPI_SUCCESS)
            return team_error(err, rc, "sending the photon share");
    }
}
