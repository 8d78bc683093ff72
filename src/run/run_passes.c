/* A channel's passes (run.h): render passes until the noise target, the time limit or
 * final-gather's photon-map floor; photon-map's photon passes. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "scene/scene_hash.h"
#include "run/run.h"
#include "run/run_noise.h"
#include "sensor/render.h"
#include "sensor/render_accum.h"
#include "sensor/render_tiles.h"

/* A noise target stops here at the latest (with a run warning). */
#define RUN_MAX_PASSES 100000u
/* final-gather stops at its photon map's floor from this pass on (run_at_map_floor): the
 * floor's estimate from one pass of 32 gather rays was within 2 % of its value after 11
 * on the paper's scene. */
#define RUN_FLOOR_PASSES 2u

/* The 95th percentile over the rendered pixels of channel c (all selected sensors) of
 * the standard error of Tb_c in K (run_noise.h): what a noise target aims at. A
 * negative value (never below a target) on allocation failure: the caller stops. */
static double run_channel_p95_stderr_k(const run_state *rs, size_t c)
{
    run_noise all;
    thz_error ignored;
    if (run_noise_channel(rs->images, rs->n_selected, c, rs->scene->channels[c].center_hz, 0, &all,
                          NULL, &ignored) != THZ_OK)
        return -1.0;
    return all.p95_k;
}

/* Samples of channel c's last render (all selected sensors) whose density estimate found
 * fewer photons than it needs and took the reflected radiance as 0: their standard error
 * says nothing of that error, so a noise target is not met while any remain. */
static uint64_t run_channel_starved(const run_state *rs, size_t c)
{
    uint64_t n = 0;
    for (size_t i = 0; i < rs->n_selected; i++)
        n += rs->last[c * rs->n_selected + i].starved_gathers;
    return n;
}

/* What a photon-pass warning says of where the channel stopped: above the target, or
 * below it or unknown (infinite: the rank falls on a pixel short of photons) with samples
 * still lacking photons. */
typedef struct run_stop_text {
    char text[256];
} run_stop_text;

static run_stop_text run_stop_where(double p95, double target, uint64_t starved)
{
    run_stop_text s;
    if (p95 > target && isfinite(p95))
        snprintf(s.text, sizeof s.text,
                 "at %.3g K (95th percentile of the pixels' standard error) above the noise "
                 "target of %g K",
                 p95, target);
    else
        snprintf(s.text, sizeof s.text,
                 "short of the noise target of %g K: %llu samples still hit objects holding "
                 "fewer photons than a density estimate needs",
                 target, (unsigned long long)starved);
    return s;
}

/* How a warning names channel c: as the progress lines count it, and by its name (the
 * frequency unless the scene names it), "channel 1/6 (0.200 THz)". */
typedef struct run_channel_label {
    char text[160];
} run_channel_label;

static run_channel_label run_channel_name(const run_state *rs, size_t c)
{
    run_channel_label l;
    snprintf(l.text, sizeof l.text, "channel %zu/%zu (%s)", c + 1, rs->scene->n_channels,
             rs->scene->channels[c].name);
    return l;
}

/* final-gather: whether the photon map's own noise (run_noise_map_floor_k) keeps channel
 * c's 95th percentile at or above the target: more gather rays from the same map cannot
 * lower it, so the passes stop there, with a warning that says what would (*st: THZ_OK,
 * or the warning's failure). */
static bool run_at_map_floor(run_state *rs, size_t c, const render_accum *acc, double target,
                             thz_status *st, thz_error *err)
{
    double floor_k =
        run_noise_map_floor_k(acc, rs->images, rs->n_selected, c, rs->scene->channels[c].center_hz);
    if (floor_k < target) /* below, or no batches (0), or out of memory (-1): go on */
        return false;
    bool render = strcmp(rs->command, "render") == 0;
    *st = run_add_warning(
        rs, err,
        "%s: final-gather's photon map alone leaves %.3g K at the 95th percentile, "
        "at or above the noise target of %g K, which more gather rays cannot lower: stopped "
        "after %u passes. A map of more photons lowers it (%s %llu per channel), and the "
        "path integrator has no such floor",
        run_channel_name(rs, c).text, floor_k, target, rs->passes[c],
        render ? "the map read has" : "now", (unsigned long long)rs->photons_per_channel);
    return true;
}

/* run.h. The passes stop at the first of: the target reached (the 95th percentile of the
 * channel's standard error), final-gather's map floor at or above it (from
 * RUN_FLOOR_PASSES on), the time limit, RUN_MAX_PASSES. */
thz_status run_render_channel(run_state *rs, size_t c, const photon_map *map, thz_error *err)
{
    render_options ro = {.threads = rs->opt->threads,
                         .use_seed = true,
                         .seed = rs->seed, /* the photon map's, for render */
                         .progress = rs->opt->progress,
                         .progress_user = rs->opt->progress_user};
    const render_team *team = rs->opt->render_team;
    if (team) /* this process renders its tiles, the others theirs */
        ro.members = team->members;
    double t0 = thz_now_s();
    double target =
        render_integrator_has_passes(rs->scene->render.integrator) ? rs->target_noise_k : 0.0;
    thz_status st = THZ_OK;
    /* the stage starts here, before the channel's tables (its time, render_s, does too):
     * a display of the stage's time starts its clock at this report */
    if (ro.progress && rs->n_selected > 0) {
        thz_progress p = {.stage = "render",
                          .channel = c,
                          .n_channels = rs->scene->n_channels,
                          .done = 0,
                          .total = rs->scene->sensors[rs->selected[0]].rows};
        if (ro.progress(ro.progress_user, &p) != 0)
            return thz_error_set(err, THZ_ERR_CANCELLED, "render: cancelled");
    }
    render_accum *acc = thz_calloc(rs->n_selected, sizeof *acc);
    if (!acc)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the pixel statistics");
    for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
        const thz_sensor *s = &rs->scene->sensors[rs->selected[i]];
        st = render_accum_init(&acc[i], (size_t)s->columns * s->rows, err);
    }
    /* the channel's tables, built once for all its passes and sensors */
    render_context *ctx = NULL;
    if (st == THZ_OK && team) {
        render_channel_request rq = {.channel = c,
                                     .use_seed = ro.use_seed,
                                     .seed = ro.seed,
                                     .integrator = (uint64_t)rs->scene->render.integrator,
                                     .scene_print = scene_hash_run(rs->scene, true)};
        st = team->channel_begin(team->impl, &rq, map, err);
    }
    if (st == THZ_OK)
        st = render_context_create(rs->scene, rs->accel, map, c, &ro, &ctx, err);
    for (uint32_t pass = 0; st == THZ_OK; pass++) {
        for (size_t i = 0; i < rs->n_selected && st == THZ_OK; i++) {
            render_stats rst;
            if (team)
                st = team->pass_start(team->impl, rs->selected[i], pass, err);
            if (st == THZ_OK)
                st = render_context_pass(ctx, rs->selected[i], pass, &acc[i], &ro, &rst, err);
            if (st == THZ_OK && team)
                st = team->pass_gather(team->impl, &acc[i],
                                       rs->scene->sensors[rs->selected[i]].columns, &rst, err);
            if (st != THZ_OK)
                break;
            rs->last[c * rs->n_selected + i] = rst;
            st = render_accum_write(rs->scene, c, rs->selected[i], &acc[i], &rs->images[i], err);
        }
        if (st != THZ_OK)
            break;
        rs->passes[c] = pass + 1;
        if (!(target > 0.0))
            break;
        /* one estimate a pixel (paths_per_sample or gather_rays 1, one pass) has no
         * spread yet: its standard error of 0 K is not a target met (a run of one path a
         * sample stopped there, at "0 K", after one pass) */
        if (acc[0].n >= 2 && run_channel_p95_stderr_k(rs, c) <= target)
            break;
        if (pass + 1 >= RUN_FLOOR_PASSES && run_at_map_floor(rs, c, acc, target, &st, err))
            break;
        if (rs->max_seconds > 0.0 && thz_now_s() - t0 >= rs->max_seconds) {
            st = run_add_warning(rs, err,
                                 "%s: stopped by the time limit of %g s after %u "
                                 "pass%s, at %.3g K (95th percentile of the pixels' standard "
                                 "error) above the noise target of %g K",
                                 run_channel_name(rs, c).text, rs->max_seconds, pass + 1,
                                 pass == 0 ? "" : "es", run_channel_p95_stderr_k(rs, c), target);
            break;
        }
        if (pass + 1 >= RUN_MAX_PASSES) {
            st = run_add_warning(rs, err,
                                 "%s: stopped after %u passes above the noise target "
                                 "of %g K",
                                 run_channel_name(rs, c).text, (unsigned)RUN_MAX_PASSES, target);
            break;
        }
    }
    if (st == THZ_OK && team)
        st = team->channel_end(team->impl, err);
    render_context_destroy(ctx);
    if (acc)
        for (size_t i = 0; i < rs->n_selected; i++)
            render_accum_fini(&acc[i]);
    free(acc);
    double seconds = thz_now_s() - t0;
    rs->seconds_channel[c] += seconds; /* photon-map's photon passes render again */
    rs->seconds_render += seconds;
    return st;
}

uint32_t run_photon_next_check(uint32_t n, double need)
{
    need = fmin(fmin(need, ceil(1.25 * (double)n)), (double)RUN_MAX_PASSES);
    return need > (double)n ? (uint32_t)need : n + 1;
}

double run_passes_memory_limit_bytes(void)
{
    /* the process's limit (ulimit -v, a cgroup), not only the machine's: under a limit of
     * 1 GiB the passes were let hold 11.7 GiB and ended out of memory (under a cgroup's
     * limit, the kernel's OOM killer ends them) */
    return 0.5 * (double)thz_memory_limit_bytes();
}

uint32_t run_photon_checks(uint32_t passes)
{
    uint32_t checks = 1;
    for (uint32_t n = 1; n < passes; checks++)
        n = run_photon_next_check(n, INFINITY);
    return checks;
}

double run_photon_merged_passes(uint32_t passes)
{
    double sum = 0.0;
    for (uint32_t n = 1; n < passes;) {
        n = run_photon_next_check(n, INFINITY);
        sum += n < passes ? (double)n : (double)passes;
    }
    return sum;
}

/* photon-map with a noise target (it cannot add render passes: it is deterministic given
 * its map): photon passes instead. Pass p fires photons p K .. (p + 1) K - 1 of the
 * channel, and at checks (run_photon_next_check) the channel is rendered from the merge
 * of all passes' photons (photon_map_merge: (p + 1) K photons), until the 95th percentile
 * of the channel's standard error reaches the target, the time limit passes, or the next
 * merge would not fit in half the memory.
 * *out_map is the merged map; the passes are bit-identical for any thread count. */
thz_status run_photon_passes(run_state *rs, size_t c, photon_map **out_map, thz_error *err)
{
    const thz_scene *scene = rs->scene;
    const run_options *opt = rs->opt;
    double target = rs->target_noise_k, t_start = thz_now_s();
    size_t cap = 16, n = 0, check = 1; /* passes fired; the next pass rendered */
    photon_map **maps = thz_calloc(cap, sizeof *maps);
    photon_map *merged = NULL;
    /* each merge's records and index scratch, for the next (grown in place): merging
     * into fresh memory at every check was 80 % of a 190-pass run (the page faults) */
    photon_map_pool merge_pool = {0};
    thz_status st = THZ_OK;
    if (!maps)
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon passes");
    uint64_t k = scene->photons.per_channel;
    double limit = run_passes_memory_limit_bytes();
    while (st == THZ_OK) {
        if (n == cap) {
            photon_map **m = thz_realloc_array(maps, 2 * cap, sizeof *m);
            if (!m) {
                st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory for the photon passes");
                break;
            }
            maps = m;
            cap *= 2;
        }
        photon_phase_options po = {.threads = opt->threads,
                                   .reference_temperature_k = run_photon_t0_k(scene, c),
                                   .first_photon = (uint64_t)n * k,
                                   .team = opt->team,
                                   .pool = &rs->pool,
                                   .reach = &rs->reach,
                                   .progress = opt->progress,
                                   .progress_user = opt->progress_user};
        photon_stats ps;
        double t0 = thz_now_s();
        st = photon_phase_run(scene, rs->accel, c, &po, &maps[n], &ps, err);
        if (st != THZ_OK)
            break;
        n++;
        photon_stats_merge(&rs->stats[c], &ps, (uint32_t)n);
        bool out_of_time = rs->max_seconds > 0.0 && thz_now_s() - t_start >= rs->max_seconds;
        if (n < check && !out_of_time) {
            rs->seconds_photons += thz_now_s() - t0;
            continue;
        }
        /* A check: the merge of every pass so far, rendered. */
        photon_map_recycle(merged, &merge_pool);
        merged = NULL;
        if (n > 1)
            st = photon_map_merge((const photon_map *const *)maps, n, scene->n_objects,
                                  opt->threads, &merge_pool, &merged, err);
        rs->seconds_photons += thz_now_s() - t0;
        if (st != THZ_OK)
            break;
        const photon_map *map = n > 1 ? merged : maps[0];
        rs->stats[c].stored = photon_map_count(map);
        st = run_render_channel(rs, c, map, err);
        rs->passes[c] = (uint32_t)n;
        double p95 = run_channel_p95_stderr_k(rs, c);
        /* a sample short of photons took its reflected radiance as 0 with a standard
         * error of 0: 10 photons a pass "met" a target of 0.1 K after one pass */
        uint64_t starved = run_channel_starved(rs, c);
        if (st != THZ_OK || (p95 <= target && !starved))
            break;
        run_stop_text where = run_stop_where(p95, target, starved);
        if (out_of_time) {
            st = run_add_warning(
                rs, err, "%s: stopped by the time limit of %g s after %zu photon pass%s, %s",
                run_channel_name(rs, c).text, rs->max_seconds, n, n == 1 ? "" : "es", where.text);
            break;
        }
        double per_pass = RUN_PASSES_MAP_FACTOR * (double)photon_map_bytes(map) / (double)n;
        double most = limit > 0.0 ? floor(limit / per_pass) : (double)RUN_MAX_PASSES;
        if (most <= (double)n) { /* limit 0: the machine's memory is unknown */
            st = run_add_warning(rs, err,
                                 "%s: stopped after %zu photon passes (%llu photons), %s: the "
                                 "next would need %.2f GiB of memory",
                                 run_channel_name(rs, c).text, n, (unsigned long long)(n * k),
                                 where.text, per_pass * (double)(n + 1) / 1073741824.0);
            break;
        }
        if (n >= RUN_MAX_PASSES) {
            st =
                run_add_warning(rs, err, "%s: stopped after %u passes, %s",
                                run_channel_name(rs, c).text, (unsigned)RUN_MAX_PASSES, where.text);
            break;
        }
        /* The next check where the noise, falling as 1/sqrt(photons), meets the target, at
         * most a quarter more passes than so far (so at most a quarter more photons than
         * a check after every pass would fire; the checks' merges and renders cost about
         * 5 x one of the last, not the last's times the passes): a check after every pass
         * made a run of 450 passes take 5 minutes. Between checks the passes are only
         * fired; a time limit checks at once. */
        double need = starved ? INFINITY : ceil((double)n * (p95 / target) * (p95 / target));
        check = run_photon_next_check((uint32_t)n, fmin(need, most));
    }
    if (st == THZ_OK && n > 0) {
        if (n > 1) {
            *out_map = merged;
            merged = NULL;
        } else {
            *out_map = maps[0];
            maps[0] = NULL;
        }
    }
    photon_map_destroy(merged);
    photon_map_pool_fini(&merge_pool);
    for (size_t i = 0; maps && i < n; i++)
        photon_map_destroy(maps[i]);
    free(maps);
    return st;
}
