/* What the files of the MPI team share: the team, the messages the lead broadcasts and
 * the headers the members send, and the transport (polling waits, payloads in pieces of
 * at most 1 GiB). mpi_team.c holds the team, the transport and the lead's side (its
 * phase and render interfaces, dealt items' results); mpi_team_serve.c the members' loop
 * (mpi_team_serve). Compiled only with MPI; nothing here is public.
 */
#ifndef THZ_MPI_MPI_TEAM_INTERNAL_H
#define THZ_MPI_MPI_TEAM_INTERNAL_H

#include <mpi.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mpi/mpi_team.h"

enum {
    TEAM_TAG_HEADER = 1,
    TEAM_TAG_RECORDS,
    TEAM_TAG_CHUNKS,
    TEAM_TAG_TILES,
    TEAM_TAG_RESULT_HEADER,
    TEAM_TAG_RESULT
};

struct mpi_team {
    MPI_Comm comm; /* a duplicate of MPI_COMM_WORLD, errors returned (not fatal) */
    int rank, size;
    photon_phase_team phase; /* the lead's interfaces, impl = this team */
    render_team render;
    uint64_t bytes;  /* sent and received */
    uint64_t *dealt; /* a member: the items the lead dealt last (mpi_team_deal) */
    size_t n_dealt;
};

/* What the lead broadcasts: a phase to fire, a render channel to begin (the photon map's
 * records follow) or end, a render pass, another scene (batch frames), items dealt whole
 * (batch frames: the list follows), or the end of the team's work. */
enum {
    TEAM_PHASE,
    TEAM_STOP,
    TEAM_RENDER_BEGIN,
    TEAM_RENDER_PASS,
    TEAM_RENDER_END,
    TEAM_SCENE,
    TEAM_DEAL
};

typedef struct team_message {
    uint64_t kind;
    photon_phase_request rq;   /* TEAM_PHASE */
    render_channel_request rr; /* TEAM_RENDER_BEGIN */
    uint64_t has_map;          /* TEAM_RENDER_BEGIN: 1 when rendered from a map (not path) */
    uint64_t map_count;        /* its records (0 for an empty map: an isothermal deviation) */
    uint64_t map_batches;      /* its photon_map_batches */
    double map_t0_k;           /* its reference temperature */
    uint64_t sensor, pass;     /* TEAM_RENDER_PASS */
    uint64_t scene;            /* TEAM_SCENE: the caller's index of the next scene; TEAM_DEAL:
                                  the number of items dealt */
} team_message;

/* What a member sends before its tiles of a render pass: its counts and how many doubles
 * its tiles are, which the lead checks before receiving them (a message longer than the
 * buffer is written past its end by some transports, not refused). */
typedef struct team_tiles_header {
    render_stats counts;
    uint64_t doubles;
} team_tiles_header;

/* What a member sends first: the sizes of its share. */
typedef struct team_header {
    uint64_t count, n_chunks;
} team_header;

/* ---- mpi_team.c: the transport ---- */

/* rc (an MPI error code, or an interrupted wait) as err, saying what failed. */
thz_status team_error(thz_error *err, int rc, const char *what);
/* Broadcasts m from the lead (every rank calls it); an MPI error code. */
int team_bcast(mpi_team *t, team_message *m);
/* Broadcasts `bytes` bytes from the lead, in pieces. */
int team_bcast_bytes(mpi_team *t, void *data, size_t bytes);
/* Sends (to the lead) or receives (from rank `peer`) `bytes` bytes in pieces. */
int team_move(mpi_team *t, void *data, size_t bytes, int peer, int tag, bool send);

#endif
