/* A member rank's side of the MPI team (mpi_team_serve): it waits for the lead's
 * broadcasts and serves them, firing its share of each photon phase, building the lead's
 * photon map and rendering its pixel tiles of each pass, taking another scene or a list
 * of dealt items, until the lead stops the team. mpi_team.c holds the team, the
 * transport and the lead's side (mpi_team_internal.h).
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "mpi/mpi_team_internal.h"
#include "photon/emission_reach.h"
#include "scene/scene_hash.h"
#include "sensor/render_context.h"

/* A member: TEAM_DEAL's list, into team->dealt. */
static thz_status team_receive_deal(mpi_team *t, const team_message *m, thz_error *err)
{
    uint64_t *items = m->scene <= SIZE_MAX / sizeof *items
                          ? thz_realloc_array(t->dealt, m->scene ? m->scene : 1, sizeof *items)
                          : NULL;
    if (!items)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for %llu dealt items",
                             (unsigned long long)m->scene);
    t->dealt = items;
    t->n_dealt = (size_t)m->scene;
    int rc = team_bcast_bytes(t, items, t->n_dealt * sizeof *items);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "receiving the dealt frames");
}

/* A member's photon share of request rq, fired and sent to the lead. */
static thz_status team_serve_phase(mpi_team *t, const thz_scene *scene, const accel *acc,
                                   const photon_phase_request *rq, int threads,
                                   emission_reach *reach, thz_error *err)
{
    photon_phase_share share;
    thz_status st = photon_phase_fire_share(scene, acc, rq, threads, reach, (size_t)t->rank,
                                            (size_t)t->size, &share, err);
    if (st != THZ_OK)
        return st;
    team_header head = {.count = share.count, .n_chunks = share.n_chunks};
    int rc = team_move(t, &head, sizeof head, 0, TEAM_TAG_HEADER, true);
    if (rc == MPI_SUCCESS)
        rc = team_move(t, share.records, share.count * sizeof *share.records, 0, TEAM_TAG_RECORDS,
                       true);
    if (rc == MPI_SUCCESS)
        rc = team_move(t, share.chunks, share.n_chunks * sizeof *share.chunks, 0, TEAM_TAG_CHUNKS,
                       true);
    photon_phase_share_fini(&share);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "sending the photon share");
}

/* A member's state of the render channel in progress: the lead's photon map, the
 * channel's tables, and per scene sensor the statistics of this member's tiles. */
typedef struct team_render {
    photon_map *map;
    render_context *ctx;
    render_options ro;
    render_accum *accs; /* per scene sensor, pixels 0 until its first pass */
    size_t n_sensors;
} team_render;

static void team_render_fini(team_render *r)
{
    render_context_destroy(r->ctx);
    photon_map_destroy(r->map);
    for (size_t i = 0; r->accs && i < r->n_sensors; i++)
        render_accum_fini(&r->accs[i]);
    free(r->accs);
    memset(r, 0, sizeof *r);
}

/* TEAM_RENDER_BEGIN: receives the lead's photon map and builds the same channel state. */
static thz_status team_serve_begin(mpi_team *t, const thz_scene *scene, const accel *acc,
                                   const team_message *m, int threads, team_render *r,
                                   thz_error *err)
{
    team_render_fini(r);
    if (m->rr.channel >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "MPI: the lead renders channel %llu, the scene has %zu",
                             (unsigned long long)m->rr.channel, scene->n_channels);
    if (m->rr.integrator != (uint64_t)scene->render.integrator) /* path was refused before */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "MPI: the lead renders with %s, process %d with %s (every process "
                             "must run with the same options)",
                             render_integrator_name((thz_integrator)m->rr.integrator), t->rank,
                             render_integrator_name(scene->render.integrator));
    if (m->rr.scene_print != scene_hash_run(scene, true))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: MPI: process %d's scene differs from the lead's (objects, "
                             "materials, air, channels, sensors or settings; every process must "
                             "load the same scene with the same options)",
                             scene->path ? scene->path : "scene", t->rank);
    r->ro = (render_options){.threads = threads,
                             .use_seed = m->rr.use_seed != 0,
                             .seed = m->rr.seed,
                             .member = (size_t)t->rank,
                             .members = (size_t)t->size};
    r->n_sensors = scene->n_sensors;
    r->accs = thz_calloc(r->n_sensors ? r->n_sensors : 1, sizeof *r->accs);
    if (!r->accs)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for the pixel statistics");
    if (m->has_map) {
        photon_record *records = NULL;
        if (m->map_count > 0) {
            records = m->map_count <= SIZE_MAX / sizeof *records
                          ? thz_malloc_array(m->map_count, sizeof *records)
                          : NULL;
            if (!records)
                return thz_error_set(err, THZ_ERR_NOMEM,
                                     "MPI: out of memory for %llu photon records",
                                     (unsigned long long)m->map_count);
            int rc = team_bcast_bytes(t, records, m->map_count * sizeof *records);
            if (rc != MPI_SUCCESS) {
                free(records);
                return team_error(err, rc, "receiving the photon map");
            }
        }
        /* takes records, also on failure; they come in the lead's map's order, which the
         * build checks in one pass and keeps */
        thz_status st =
            photon_map_create(records, m->map_count, scene->n_objects, threads, &r->map, err);
        if (st != THZ_OK)
            return st;
        photon_map_set_reference_temperature_k(r->map, m->map_t0_k);
        photon_map_set_batches(r->map, (unsigned)m->map_batches);
    }
    return render_context_create(scene, acc, r->map, m->rr.channel, &r->ro, &r->ctx, err);
}

/* TEAM_RENDER_PASS: renders this member's tiles and sends them to the lead. */
static thz_status team_serve_pass(mpi_team *t, const thz_scene *scene, const team_message *m,
                                  team_render *r, thz_error *err)
{
    if (!r->ctx || m->sensor >= r->n_sensors)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: a render pass outside a channel");
    const thz_sensor *sn = &scene->sensors[m->sensor];
    render_accum *a = &r->accs[m->sensor];
    size_t pixels = (size_t)sn->columns * sn->rows;
    thz_status st = a->pixels ? THZ_OK : render_accum_init(a, pixels, err);
    render_stats counts;
    if (st == THZ_OK)
        st = render_context_pass(r->ctx, m->sensor, (uint32_t)m->pass, a, &r->ro, &counts, err);
    if (st != THZ_OK)
        return st;
    size_t n = render_tiles_count(pixels, sn->columns, r->ro.member, r->ro.members) *
               render_tiles_doubles_per_pixel(a);
    double *tiles = thz_malloc_array(n ? n : 1, sizeof *tiles);
    if (!tiles)
        return thz_error_set(err, THZ_ERR_NOMEM, "MPI: out of memory for %zu pixels' tiles", n);
    render_tiles_pack(a, sn->columns, r->ro.member, r->ro.members, tiles);
    team_tiles_header head = {.counts = counts, .doubles = n};
    int rc = team_move(t, &head, sizeof head, 0, TEAM_TAG_HEADER, true);
    if (rc == MPI_SUCCESS)
        rc = team_move(t, tiles, n * sizeof *tiles, 0, TEAM_TAG_TILES, true);
    free(tiles);
    return rc == MPI_SUCCESS ? THZ_OK : team_error(err, rc, "sending the render tiles");
}

thz_status mpi_team_serve(mpi_team *team, const thz_scene *scene, const accel *acc, int threads,
                          uint64_t *next_scene, thz_error *err)
{
    if (next_scene)
        *next_scene = MPI_TEAM_STOPPED;
    if (team->rank == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "MPI: rank 0 leads, it does not serve");
    team_render render = {0};
    emission_reach reach = {0}; /* the scene's, for every deviation map it is asked for */
    thz_status st = THZ_OK;
    while (st == THZ_OK) {
        team_message m;
        int rc = team_bcast(team, &m);
        if (rc != MPI_SUCCESS) {
            st = team_error(err, rc, "waiting for the lead's request");
            break;
        }
        if (m.kind == TEAM_STOP)
            break;
        if (m.kind == TEAM_SCENE && next_scene) {
            *next_scene = m.scene;
            break;
        }
        if (m.kind == TEAM_DEAL && next_scene) {
            st = team_receive_deal(team, &m, err);
            *next_scene = MPI_TEAM_DEALT;
            break;
        }
        if (!scene && m.kind != TEAM_SCENE && m.kind != TEAM_DEAL) {
            st = thz_error_set(err, THZ_ERR_INTERNAL, "MPI: a request before the first scene");
            break;
        }
        switch (m.kind) {
        case TEAM_PHASE:
            if (!render_integrator_needs_photons(scene->render.integrator))
                st = thz_error_set(err, THZ_ERR_INPUT,
                                   "MPI: the lead asks for photons but process %d's integrator "
                                   "fires none (every process must run with the same options)",
                                   team->rank);
            else
                st = team_serve_phase(team, scene, acc, &m.rq, threads, &reach, err);
            break;
        case TEAM_RENDER_BEGIN:
            st = team_serve_begin(team, scene, acc, &m, threads, &render, err);
            break;
        case TEAM_RENDER_PASS:
            st = team_serve_pass(team, scene, &m, &render, err);
            break;
        case TEAM_RENDER_END:
            team_render_fini(&render);
            break;
        case TEAM_SCENE:
        case TEAM_DEAL:
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "MPI: the lead runs several scenes (batch) while process %d "
                               "serves one (every process must run the same command)",
                               team->rank);
            break;
        default:
            st = thz_error_set(err, THZ_ERR_INTERNAL, "MPI: unknown request %llu from the lead",
                               (unsigned long long)m.kind);
        }
    }
    team_render_fini(&render);
    emission_reach_fini(&reach);
    return st;
}
