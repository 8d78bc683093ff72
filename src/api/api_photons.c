/* The photon phase as a handle: fire, load, save, merge, statistics. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "api/api.h"
#include "core/alloc.h"
#include "core/error.h"
#include "io/photon_map_file.h"
#include "photon/emission_reach.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "run/run.h"
#include "scene/scene_hash.h"

static thz_status api_photons_create(const thz_scene *scene, thz_photons **out, thz_error *err)
{
    thz_photons *ph = thz_calloc(1, sizeof *ph);
    size_t nc = scene->n_channels;
    if (ph) {
        ph->maps = thz_calloc(nc ? nc : 1, sizeof *ph->maps);
        ph->stats = thz_calloc(nc ? nc : 1, sizeof *ph->stats);
    }
    if (!ph || !ph->maps || !ph->stats) {
        if (ph) {
            free(ph->maps);
            free(ph->stats);
        }
        free(ph);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon maps");
    }
    ph->scene = scene;
    ph->effective = *scene;
    ph->n_channels = nc;
    ph->owned = true;
    *out = ph;
    return THZ_OK;
}

void thz_photons_destroy(thz_photons *ph)
{
    if (!ph || !ph->owned)
        return;
    for (size_t c = 0; c < ph->n_channels; c++)
        photon_map_destroy(ph->maps[c]);
    free(ph->maps);
    free(ph->stats);
    free(ph->spans);
    free(ph);
}

/* Refuses, before any photon is fired, maps that would not fit in memory: the channels
 * fired are all kept (as a simulate that keeps its maps). */
static thz_status api_fire_check_memory(const thz_scene *eff, const accel *acc, size_t only,
                                        emission_reach *reach, thz_error *err)
{
    run_memory need = {.held_bytes = thz_process_memory_bytes(),
                       .available_bytes = thz_memory_limit_bytes()};
    thz_status st = run_photon_map_bytes(eff, acc, only, true, reach, &need.photon_bytes, err);
    if (st != THZ_OK)
        return st;
    need.total_bytes = need.photon_bytes + need.held_bytes;
    return run_check_memory(eff, &need, err);
}

/* Fires channel `only` (or every channel when only == SIZE_MAX). */
static thz_status api_fire(thz_context *ctx, const thz_scene *scene,
                           const thz_run_settings *settings, size_t only, thz_photons **out,
                           thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_fire: no place for the photons");
    *out = NULL;
    if (!scene)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_fire: no scene");
    thz_status checked = api_check_threads(ctx, "thz_photons_fire", err);
    if (checked != THZ_OK)
        return checked;
    if (only != SIZE_MAX && only >= scene->n_channels)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_fire_channel: channel %zu of %zu",
                             only, scene->n_channels);
    thz_photons *ph = NULL;
    accel *acc = NULL;
    thz_status st = api_photons_create(scene, &ph, err);
    if (st == THZ_OK)
        st = api_effective_scene(scene, settings, &ph->effective, err);
    const thz_scene *eff = ph ? &ph->effective : NULL;
    if (st == THZ_OK)
        st = render_integrator_check(eff->render.integrator, err);
    uint64_t first = settings ? settings->first_photon : 0;
    if (st == THZ_OK && first > UINT64_MAX - eff->photons.per_channel)
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "thz_photons_fire: photons %llu to %llu + %llu leave the photon "
                           "numbers (at most 2^64 - 1): lower first_photon",
                           (unsigned long long)first, (unsigned long long)first,
                           (unsigned long long)eff->photons.per_channel);
    if (st == THZ_OK && !render_integrator_needs_photons(eff->render.integrator))
        st = thz_error_set(err, THZ_ERR_INPUT, "the %s integrator uses no photons",
                           render_integrator_name(eff->render.integrator));
    if (st == THZ_OK)
        st = accel_create(eff, &acc, err);
    emission_reach reach = {0};
    photon_phase_options prepare = {.threads = ctx ? ctx->threads : 0,
                                    .reach = &reach,
                                    .progress = ctx ? ctx->progress : NULL,
                                    .progress_user = ctx ? ctx->progress_user : NULL};
    if (st == THZ_OK)
        st = run_prepare_reach(eff, acc, only, &prepare, err);
    if (st == THZ_OK)
        st = api_fire_check_memory(eff, acc, only, &reach, err);
    for (size_t c = 0; st == THZ_OK && c < scene->n_channels; c++) {
        if (only != SIZE_MAX && c != only)
            continue;
        photon_phase_options po = {.threads = ctx ? ctx->threads : 0,
                                   .reference_temperature_k = run_photon_t0_k(eff, c),
                                   .first_photon = settings ? settings->first_photon : 0,
                                   .reach = &reach,
                                   .progress = ctx ? ctx->progress : NULL,
                                   .progress_user = ctx ? ctx->progress_user : NULL};
        st = photon_phase_run(eff, acc, c, &po, &ph->maps[c], &ph->stats[c], err);
    }
    emission_reach_fini(&reach);
    accel_destroy(acc);
    if (st != THZ_OK) {
        thz_photons_destroy(ph);
        return st;
    }
    ph->seed = eff->photons.seed;
    ph->photons_per_channel = eff->photons.per_channel;
    ph->spans = thz_calloc(scene->n_channels ? scene->n_channels : 1, sizeof *ph->spans);
    if (!ph->spans) {
        thz_photons_destroy(ph);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon maps");
    }
    for (size_t c = 0; c < scene->n_channels; c++)
        if (ph->maps[c])
            ph->spans[ph->n_spans++] =
                (api_photon_span){.channel = c, .first = first, .count = ph->photons_per_channel};
    *out = ph;
    return THZ_OK;
}

thz_status thz_photons_fire(thz_context *ctx, const thz_scene *scene,
                            const thz_run_settings *settings, thz_photons **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    return api_done(ctx, api_fire(ctx, scene, settings, SIZE_MAX, out, err), err);
}

thz_status thz_photons_fire_channel(thz_context *ctx, const thz_scene *scene,
                                    const thz_run_settings *settings, size_t channel,
                                    thz_photons **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (channel == SIZE_MAX)
        channel = SIZE_MAX - 1; /* out of range, not "all" */
    return api_done(ctx, api_fire(ctx, scene, settings, channel, out, err), err);
}

/* The file's reading, told to the context's progress callback as the "read" stage. */
typedef struct api_read_report {
    const thz_context *ctx;
    size_t n_channels;
} api_read_report;

static int api_read_progress(void *user, size_t channel, uint64_t done, uint64_t total)
{
    const api_read_report *r = user;
    thz_progress p = {.stage = "read",
                      .channel = channel,
                      .n_channels = r->n_channels,
                      .done = done,
                      .total = total};
    return r->ctx->progress(r->ctx->progress_user, &p);
}

/* thz_photons_load of every channel (channel = SIZE_MAX) or of one. */
static thz_status api_photons_load(thz_context *ctx, const thz_scene *scene, const char *path,
                                   size_t channel, thz_photons **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_photons_load: no place for the photons"),
            err);
    *out = NULL;
    if (!scene || !path)
        return api_done(
            ctx,
            thz_error_set(err, THZ_ERR_INPUT, "thz_photons_load: no %s", scene ? "path" : "scene"),
            err);
    thz_photons *ph = NULL;
    thz_status st = api_check_threads(ctx, "thz_photons_load", err);
    if (st == THZ_OK)
        st = api_photons_create(scene, &ph, err);
    photon_map_file_info info;
    int threads = ctx ? ctx->threads : 0;
    api_read_report report = {.ctx = ctx, .n_channels = scene->n_channels};
    photon_map_file_progress progress = {.fn = api_read_progress, .user = &report};
    if (st == THZ_OK)
        st = photon_map_file_read_progress(path, scene, threads, channel,
                                           ctx && ctx->progress ? &progress : NULL, ph->maps,
                                           ph->stats, &info, err);
    if (st != THZ_OK) {
        thz_photons_destroy(ph);
        return api_done(ctx, st, err);
    }
    ph->seed = info.seed;
    ph->photons_per_channel = info.photons_per_channel;
    ph->effective.photons.seed = info.seed;
    ph->effective.photons.per_channel = info.photons_per_channel;
    *out = ph;
    return THZ_OK;
}

thz_status thz_photons_load(thz_context *ctx, const thz_scene *scene, const char *path,
                            thz_photons **out, thz_error *err)
{
    return api_photons_load(ctx, scene, path, SIZE_MAX, out, err);
}

thz_status thz_photons_load_channel(thz_context *ctx, const thz_scene *scene, const char *path,
                                    size_t channel, thz_photons **out, thz_error *err)
{
    return api_photons_load(ctx, scene, path, channel, out, err);
}

thz_status thz_photons_save(const thz_photons *ph, const char *path, thz_error *err)
{
    if (!ph || !path)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_save: no %s",
                             ph ? "path" : "photons");
    for (size_t c = 0; c < ph->n_channels; c++)
        if (!ph->maps[c])
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "%s: channel %zu has no photon map (fired one channel only?)",
                                 path, c);
    return photon_map_file_save(path, &ph->effective, (const photon_map *const *)ph->maps,
                                ph->stats, 0, err);
}

/* Whether part i, fired or loaded for another scene handle than part 0's, fits part 0's
 * scene: the test a .thzpm file's header and thz_render_run apply (scene_hash_fit). */
static thz_status api_merge_fits(const thz_photons *p, const thz_photons *a, size_t i,
                                 thz_error *err)
{
    if (p->scene == a->scene)
        return THZ_OK;
    scene_hash made;
    scene_hash_compute(&p->effective, &made);
    char maps[96];
    snprintf(maps, sizeof maps, "thz_photons_merge: part %zu (another scene handle than part 0's)",
             i);
    return scene_hash_fit(&made, p->effective.n_objects, p->n_channels, a->scene, maps,
                          "fire every part for the same scene", err);
}

/* Whether the parts can merge: one scene (or handles of scenes that fit one another),
 * seed, photon count and T0 per channel. */
static thz_status api_merge_check(const thz_photons *const *parts, size_t n, thz_error *err)
{
    if (!parts || n == 0)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_merge: no photons to merge");
    for (size_t i = 0; i < n; i++) {
        const thz_photons *p = parts[i], *a = parts[0];
        if (!p)
            return thz_error_set(err, THZ_ERR_INPUT, "thz_photons_merge: part %zu is NULL", i);
        if (p->seed != a->seed || p->photons_per_channel != a->photons_per_channel)
            return thz_error_set(err, THZ_ERR_INPUT,
                                 "thz_photons_merge: part %zu has another seed or photon count "
                                 "than part 0",
                                 i);
        thz_status fits = api_merge_fits(p, a, i, err);
        if (fits != THZ_OK)
            return fits;
        /* the same photons twice would count as twice as many */
        for (size_t j = 0; j < i; j++)
            if (parts[j] == p)
                return thz_error_set(err, THZ_ERR_INPUT,
                                     "thz_photons_merge: parts %zu and %zu are the same photon "
                                     "maps: their photons would count twice",
                                     j, i);
    }
    /* per channel against the first part that holds it: part 0 may hold none of it */
    for (size_t c = 0; c < parts[0]->n_channels; c++) {
        const photon_map *first = NULL;
        for (size_t i = 0; i < n; i++) {
            const photon_map *m = parts[i]->maps[c];
            if (m && !first)
                first = m;
            else if (m && photon_map_reference_temperature_k(m) !=
                              photon_map_reference_temperature_k(first))
                return thz_error_set(err, THZ_ERR_INPUT,
                                     "thz_photons_merge: part %zu was fired for another "
                                     "integrator (reference temperature of channel %zu)",
                                     i, c);
        }
    }
    return THZ_OK;
}

static int api_span_order(const void *a, const void *b)
{
    const api_photon_span *x = a, *y = b;
    if (x->channel != y->channel)
        return x->channel < y->channel ? -1 : 1;
    return x->first < y->first ? -1 : x->first > y->first;
}

/* The merged map's ranges: the union of the parts', refused where two overlap in a
 * channel (its photons would count twice). The parts that know their ranges are checked
 * among themselves however many do not; the merged map knows its ranges only when every
 * part knows its own. */
static thz_status api_merge_spans(const thz_photons *const *parts, size_t n, thz_photons *ph,
                                  thz_error *err)
{
    size_t total = 0;
    bool all_known = true;
    for (size_t i = 0; i < n; i++) {
        all_known = all_known && parts[i]->n_spans > 0;
        total += parts[i]->n_spans;
    }
    if (total == 0)
        return THZ_OK;
    api_photon_span *s = thz_calloc(total, sizeof *s);
    if (!s)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory for merging photon maps");
    for (size_t i = 0, k = 0; i < n; i++)
        for (size_t j = 0; j < parts[i]->n_spans; j++, k++)
            s[k] = parts[i]->spans[j];
    qsort(s, total, sizeof *s, api_span_order);
    thz_status st = THZ_OK;
    size_t m = 0;
    for (size_t k = 0; k < total && st == THZ_OK; k++) {
        api_photon_span *last = m > 0 && s[m - 1].channel == s[k].channel ? &s[m - 1] : NULL;
        if (last && s[k].first - last->first < last->count)
            st = thz_error_set(err, THZ_ERR_INPUT,
                               "thz_photons_merge: two parts hold the same photons of channel "
                               "%zu (photons %llu to %llu, and %llu photons from %llu): merge "
                               "maps of disjoint ranges (thz_run_settings.first_photon)",
                               s[k].channel, (unsigned long long)last->first,
                               (unsigned long long)(last->first + last->count - 1),
                               (unsigned long long)s[k].count, (unsigned long long)s[k].first);
        else if (last && s[k].first - last->first == last->count)
            last->count += s[k].count; /* contiguous: one range */
        else
            s[m++] = s[k];
    }
    if (st != THZ_OK || !all_known) {
        free(s);
        return st;
    }
    ph->spans = s;
    ph->n_spans = m;
    return THZ_OK;
}

thz_status thz_photons_merge(thz_context *ctx, const thz_photons *const *parts, size_t n,
                             thz_photons **out, thz_error *err)
{
    thz_error local;
    err = api_err(err, &local);
    if (!out)
        return api_done(
            ctx, thz_error_set(err, THZ_ERR_INPUT, "thz_photons_merge: no place for the photons"),
            err);
    *out = NULL;
    thz_photons *ph = NULL;
    thz_status st = api_merge_check(parts, n, err);
    if (st == THZ_OK)
        st = api_check_threads(ctx, "thz_photons_merge", err);
    if (st == THZ_OK)
        st = api_photons_create(parts[0]->scene, &ph, err);
    if (st == THZ_OK)
        st = api_merge_spans(parts, n, ph, err);
    const photon_map **maps = st == THZ_OK ? thz_calloc(n, sizeof *maps) : NULL;
    if (st == THZ_OK && !maps)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for merging photon maps");
    uint64_t per_channel = 0; /* the largest over channels of the parts' sum */
    for (size_t c = 0; st == THZ_OK && c < ph->n_channels; c++) {
        size_t m = 0;
        uint64_t fired = 0;
        for (size_t i = 0; i < n; i++) {
            if (!parts[i]->maps[c])
                continue;
            maps[m++] = parts[i]->maps[c];
            fired += parts[i]->photons_per_channel;
            photon_stats_merge(&ph->stats[c], &parts[i]->stats[c], (uint32_t)m);
        }
        if (m > 0)
            st = photon_map_merge(maps, m, ph->effective.n_objects, ctx ? ctx->threads : 0, NULL,
                                  &ph->maps[c], err);
        if (st == THZ_OK && ph->maps[c])
            ph->stats[c].stored = photon_map_count(ph->maps[c]);
        if (fired > per_channel)
            per_channel = fired;
    }
    free(maps);
    if (st != THZ_OK) {
        thz_photons_destroy(ph);
        return api_done(ctx, st, err);
    }
    ph->effective = parts[0]->effective;
    ph->seed = parts[0]->seed;
    ph->photons_per_channel = per_channel;
    ph->effective.photons.per_channel = ph->photons_per_channel;
    *out = ph;
    return THZ_OK;
}

size_t thz_photons_channel_count(const thz_photons *ph)
{
    return ph ? ph->n_channels : 0;
}

int thz_photons_has_channel(const thz_photons *ph, size_t c)
{
    return ph && c < ph->n_channels && ph->maps[c] != NULL;
}

uint64_t thz_photons_seed(const thz_photons *ph)
{
    return ph ? ph->seed : 0;
}

uint64_t thz_photons_per_channel(const thz_photons *ph)
{
    return ph ? ph->photons_per_channel : 0;
}

thz_status thz_photons_stats(const thz_photons *ph, size_t c, thz_photon_stats *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!ph || c >= ph->n_channels)
        return THZ_ERR_INPUT;
    const photon_stats *s = &ph->stats[c];
    *out = (thz_photon_stats){
        .fired = s->fired,
        .stored = s->stored,
        .hits = s->hits,
        .reflected = s->reflected,
        .transmitted = s->transmitted,
        .absorbed = s->absorbed,
        .escaped = s->escaped,
        .back_face_hits = s->back_face_hits,
        .terminated = s->terminated,
        .bounce_capped = s->bounce_capped,
        .rays = s->rays,
        .emitted_power_w_per_hz = s->emitted_power_w_per_hz,
        .fired_power_w_per_hz = s->fired_power_w_per_hz,
        .absorbed_power_w_per_hz = s->absorbed_power_w_per_hz,
        .escaped_power_w_per_hz = s->escaped_power_w_per_hz,
        .atmosphere_power_w_per_hz = s->atmosphere_power_w_per_hz,
        .terminated_power_w_per_hz = s->terminated_power_w_per_hz,
        .mean_bounces = s->mean_bounces,
        .reference_temperature_k = s->reference_temperature_k,
        .seconds = s->seconds,
    };
    return THZ_OK;
}

size_t thz_photons_count(const thz_photons *ph, size_t c)
{
    return thz_photons_has_channel(ph, c) ? photon_map_count(ph->maps[c]) : 0;
}

size_t thz_photons_points(const thz_photons *ph, size_t c, size_t first, size_t n,
                          thz_photon_point *out)
{
    size_t count = thz_photons_count(ph, c);
    if (!out || first >= count)
        return 0;
    if (n > count - first)
        n = count - first;
    const photon_record *rec = photon_map_records(ph->maps[c]) + first;
    for (size_t i = 0; i < n; i++) {
        vec3 d = photon_decode_direction(rec[i].dir_oct);
        out[i] = (thz_photon_point){
            .position_m = {rec[i].position_m[0], rec[i].position_m[1], rec[i].position_m[2]},
            .direction = {(float)d.x, (float)d.y, (float)d.z},
            .power_w_per_hz = rec[i].power_w_per_hz,
            .object = photon_object(&rec[i]),
        };
    }
    return n;
}
