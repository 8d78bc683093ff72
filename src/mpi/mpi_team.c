/* The MPI transport of shared photon phases and render passes: the lead's broadcast
 * requests (and photon maps), the members' shares and tiles in messages of at most 1 GiB,
 * polling waits; the team itself and the lead's side of it. The members' loop that
 * serves the lead is mpi_team_serve.c (mpi_team_internal.h). */
#include "mpi/mpi_team.h"

#include <mpi.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"
#include "mpi/mpi_team_internal.h"

/* MPI counts are int: larger payloads go in pieces of this many bytes. */
#define TEAM_PIECE_BYTES ((size_t)1 << 30)

/* What a member sends before a dealt item's result: the item, the status (THZ_OK: the
 * bytes are the result, else the error message) and the size of the bytes. */
typedef struct team_result_header {
    uint64_t item, status, size;
} team_result_header;

/* Set by a signal handler (mpi_team_interrupt): waits end with TEAM_INTERRUPTED. */
static volatile sig_atomic_t team_interrupted = 0;
/* team_wait's return when interrupted: MPI's error codes are >= 0. */
#define TEAM_INTERRUPTED (-1)

void mpi_team_interrupt(void)
{
    team_interrupted = 1;
}

thz_status team_error(thz_error *err, int rc, const char *what)
{
    if (rc == TEAM_INTERRUPTED)
        return thz_error_set(err, THZ_ERR_CANCELLED, "MPI: interrupted while %s", what);
    char text[MPI_MAX_ERROR_STRING] = "";
    int len = 0;
    if (MPI_Error_string(rc, text, &len) != MPI_SUCCESS)
        snprintf(text, sizeof text, "error %d", rc);
    return thz_error_set(err, THZ_ERR_IO, "MPI: %s: %s", what, text);
}

/* Waits for req, polling with a pause that doubles from 50 us to 5 ms: a waiting rank
 * (a member while rank 0 renders, for seconds) leaves the cores to the working ones.
 * TEAM_INTERRUPTED once mpi_team_interrupt was called (req is left pending: the job
 * ends). */
static int team_wait(MPI_Request *req)
{
    long pause_ns = 50000;
    for (;;) {
        if (team_interrupted)
            return TEAM_INTERRUPTED;
        int done = 0;
        int rc = MPI_Test(req, &done, MPI_STATUS_IGNORE);
        if (rc != MPI_SUCCESS || done)
            return rc;
        struct timespec pause = {.tv_sec = 0, .tv_nsec = pause_ns};
        nanosleep(&pause, NULL);
        pause_ns = pause_ns < 5000000 ? 2 * pause_ns : 5000000;
    }
}

int team_bcast(mpi_team *t, team_message *m)
{
    MPI_Request req;
    int rc = MPI_Ibcast(m, (int)sizeof *m, MPI_BYTE, 0, t->comm, &req);
    if (rc == MPI_SUCCESS)
        rc = team_wait(&req);
    if (rc == MPI_SUCCESS)
        t->bytes += sizeof *m * (t->rank == 0 ? (uint64_t)(t->size - 1) : 1u);
    return rc;
}

int team_bcast_bytes(mpi_team *t, void *data, size_t bytes)
{
    char *p = data;
    while (bytes > 0) {
        size_t n = bytes < TEAM_PIECE_BYTES ? bytes : TEAM_PIECE_BYTES;
        MPI_Request req;
        int rc = MPI_Ibcast(p, (int)n, MPI_BYTE, 0, t->comm, &req);
        if (rc == MPI_SUCCESS)
            rc = team_wait(&req);
        if (rc != MPI_SUCCESS)
            return rc;
        t->bytes += n * (t->rank == 0 ? (uint64_t)(t->size - 1) : 1u);
        p += n;
        bytes -= n;
    }
    return MPI_SUCCESS;
}

int team_move(mpi_team *t, void *data, size_t bytes, int peer, int tag, bool send)
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
    team_message m = {.kind = TEAM_PHASE, .rq = *rq};
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
    if (records) {
        share->records = records;
        share->capacity = count ? (size_t)count : 1;
    }
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

static thz_status team_render_begin(void *impl, const render_channel_request *rq,
                                    const photon_map *map, thz_error *err)
{
    mpi_team *t = impl;
    team_message m = {.kind = TEAM_RENDER_BEGIN, .rr = *rq};
    if (map) {
        m.has_map = 1;
        m.map_count = photon_map_count(map);
        m.map_batches = photon_map_batches(map);
        m.map_t0_k = photon_map_reference_temperature_k(map);
    }
    int rc = team_bcast(t, &m);
    if (rc == MPI_SUCCESS && m.map_count > 0) /* read only: MPI does not write a root's buffer */
        rc = team_bcast_bytes(t, (void *)photon_map_records(map),
                              m.map_count * sizeof(photon_record));
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "sending the photon map");
}

static thz_status team_render_pass(void *impl, size_t sensor, uint32_t pass, thz_error *err)
{
    team_message m = {.kind = TEAM_RENDER_PASS, .sensor = sensor, .pass = pass};
    int rc = team_bcast(impl, &m);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "broadcasting a render pass");
}

static thz_status team_render_end(void *impl, thz_error *err)
{
    team_message m = {.kind = TEAM_RENDER_END};
    int rc = team_bcast(impl, &m);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "ending a render channel");
}

/* The lead receives each member's counts and tiles, in member order, into acc. */
static thz_status team_render_gather(void *impl, render_accum *acc, uint32_t columns,
                                     render_stats *stats, thz_error *err)
{
    mpi_team *t = impl;
    size_t members = (size_t)t->size, per = render_tiles_doubles_per_pixel(acc), most = 0;
    for (size_t r = 1; r < members; r++) {
        size_t n = render_tiles_count(acc->pixels, columns, r, members);
        most = n > most ? n : most;
    }
    double *tiles = thz_malloc_array(most > 0 ? most * per : 1, sizeof *tiles);
    if (!tiles)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for %zu pixels' tiles", most);
    int rc = MPI_SUCCESS;
    for (size_t r = 1; rc == MPI_SUCCESS && r < members; r++) {
        team_tiles_header head;
        rc = team_move(t, &head, sizeof head, (int)r, TEAM_TAG_HEADER, false);
        size_t n = render_tiles_count(acc->pixels, columns, r, members);
        if (rc == MPI_SUCCESS && head.doubles != n * per) {
            free(tiles);
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "MPI: process %zu renders %llu values for its tiles, the lead "
                                 "expects %zu (every process must load the same scene)",
                                 r, (unsigned long long)head.doubles, n * per);
        }
        if (rc == MPI_SUCCESS)
            rc = team_move(t, tiles, n * per * sizeof *tiles, (int)r, TEAM_TAG_TILES, false);
        if (rc == MPI_SUCCESS) {
            render_tiles_unpack(acc, columns, r, members, tiles);
            render_stats_add_counts(stats, &head.counts);
        }
    }
    free(tiles);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "receiving the render tiles");
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
    t->render = (render_team){.members = (size_t)t->size,
                              .channel_begin = team_render_begin,
                              .pass_start = team_render_pass,
                              .pass_gather = team_render_gather,
                              .channel_end = team_render_end,
                              .impl = t};
    *out = t;
    return THZ_OK;
}

void mpi_team_destroy(mpi_team *team)
{
    if (!team)
        return;
    if (team->rank == 0) {
        team_message m = {.kind = TEAM_STOP};
        team_bcast(team, &m);
    }
    MPI_Comm_free(&team->comm);
    free(team->dealt);
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

thz_status mpi_team_next_scene(mpi_team *team, uint64_t scene, thz_error *err)
{
    if (team->rank != 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: only the lead changes scenes");
    team_message m = {.kind = TEAM_SCENE, .scene = scene};
    int rc = team_bcast(team, &m);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "broadcasting the next scene");
}

thz_status mpi_team_deal(mpi_team *team, const uint64_t *items, size_t n, thz_error *err)
{
    if (team->rank != 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: only the lead deals");
    team_message m = {.kind = TEAM_DEAL, .scene = n};
    int rc = team_bcast(team, &m);
    if (rc == MPI_SUCCESS) /* read only: MPI does not write a root's buffer */
        rc = team_bcast_bytes(team, (void *)items, n * sizeof *items);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "dealing the frames");
}

const uint64_t *mpi_team_dealt(const mpi_team *team, size_t *n)
{
    *n = team->n_dealt;
    return team->dealt;
}

thz_status mpi_team_send_result(mpi_team *team, uint64_t item, thz_status status, const void *data,
                                size_t size, thz_error *err)
{
    team_result_header h = {.item = item, .status = (uint64_t)status, .size = size};
    int rc = team_move(team, &h, sizeof h, 0, TEAM_TAG_RESULT_HEADER, true);
    if (rc == MPI_SUCCESS) /* read only: MPI does not write a send buffer */
        rc = team_move(team, (void *)data, size, 0, TEAM_TAG_RESULT, true);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "sending a frame to rank 0");
}

thz_status mpi_team_receive_result(mpi_team *team, size_t rank, uint64_t *item, thz_status *status,
                                   void **data, size_t *size, thz_error *err)
{
    *data = NULL;
    *size = 0;
    team_result_header h;
    int rc = team_move(team, &h, sizeof h, (int)rank, TEAM_TAG_RESULT_HEADER, false);
    if (rc != MPI_SUCCESS)
        return team_error(err, rc, "receiving a frame's size");
    char *bytes = h.size < SIZE_MAX ? thz_malloc_array((size_t)h.size + 1, 1) : NULL;
    if (!bytes)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for a frame of %llu bytes",
                             (unsigned long long)h.size);
    rc = team_move(team, bytes, (size_t)h.size, (int)rank, TEAM_TAG_RESULT, false);
    if (rc != MPI_SUCCESS) {
        free(bytes);
        return team_error(err, rc, "receiving a frame");
    }
    bytes[h.size] = '\0'; /* an error message is a string */
    *item = h.item;
    *status = (thz_status)h.status;
    *data = bytes;
    *size = (size_t)h.size;
    return THZ_OK;
}

const render_team *mpi_team_render(const mpi_team *team)
{
    return &team->render;
}

uint64_t mpi_team_bytes(const mpi_team *team)
{
    return team ? team->bytes : 0;
}
