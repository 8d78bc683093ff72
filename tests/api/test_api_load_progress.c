/* thz_photons_load reports its reading as the "read" stage (each channel's stored photons:
 * 0 before its records, all once its map is built) and stops when the callback says so
 * (THZ_ERR_CANCELLED, no photons): it reported nothing, so a long load could be neither
 * followed nor cancelled (Python's load_photon_map(progress=...) never called back, and
 * Ctrl-C waited). argv: the thzmap binary (unused), the repo (unused). */
#include "api_test.h"

typedef struct reports {
    size_t n, stop_at;
    size_t channel[16];
    uint64_t done[16], total[16];
    int bad_stage;
} reports;

static int on_progress(void *user, const thz_progress *p)
{
    reports *r = user;
    if (strcmp(p->stage, "read") != 0 || p->n_channels != 2)
        r->bad_stage = 1;
    if (r->n < 16) {
        r->channel[r->n] = p->channel;
        r->done[r->n] = p->done;
        r->total[r->n] = p->total;
    }
    r->n++;
    return r->stop_at && r->n >= r->stop_at;
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    char tmp[4096], path[4200];
    test_temp_dir(tmp, sizeof tmp);
    snprintf(path, sizeof path, "%s/map.thzpm", tmp);
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "load.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    settings.photons_per_channel = 3000;
    thz_photons *fired = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &fired, &err), &err);
    REQUIRE_OK(thz_photons_save(fired, path, &err), &err);
    size_t stored[2] = {thz_photons_count(fired, 0), thz_photons_count(fired, 1)};

    /* every channel: 0 then all of its stored photons, in channel order */
    reports r = {0};
    thz_context_set_progress(ctx, on_progress, &r);
    thz_photons *ph = NULL;
    REQUIRE_OK(thz_photons_load(ctx, scene, path, &ph, &err), &err);
    CHECK(!r.bad_stage, "a report of another stage or channel count");
    CHECK(r.n == 4, "%zu reports, expected 4 (two a channel)", r.n);
    /* reads of channels 0 and 1 (done 0), then their builds (done = total) */
    CHECK(r.channel[0] == 0 && r.done[0] == 0 && r.total[0] == stored[0], "report 0: %zu %llu/%llu",
          r.channel[0], (unsigned long long)r.done[0], (unsigned long long)r.total[0]);
    CHECK(r.channel[1] == 1 && r.done[1] == 0 && r.total[1] == stored[1], "report 1: %zu %llu/%llu",
          r.channel[1], (unsigned long long)r.done[1], (unsigned long long)r.total[1]);
    CHECK(r.channel[2] == 0 && r.done[2] == stored[0] && r.total[2] == stored[0],
          "report 2: %zu %llu/%llu", r.channel[2], (unsigned long long)r.done[2],
          (unsigned long long)r.total[2]);
    CHECK(r.channel[3] == 1 && r.done[3] == stored[1] && r.total[3] == stored[1],
          "report 3: %zu %llu/%llu", r.channel[3], (unsigned long long)r.done[3],
          (unsigned long long)r.total[3]);
    thz_photons_destroy(ph);

    /* one channel: every channel's records are read, its map alone built */
    r = (reports){0};
    ph = NULL;
    REQUIRE_OK(thz_photons_load_channel(ctx, scene, path, 1, &ph, &err), &err);
    CHECK(r.n == 3 && r.channel[2] == 1 && r.done[2] == stored[1],
          "load_channel(1): %zu reports, the last of channel %zu", r.n, r.channel[2]);
    thz_photons_destroy(ph);

    /* the callback stops it: cancelled, no photons */
    r = (reports){.stop_at = 2};
    ph = NULL;
    thz_status st = thz_photons_load(ctx, scene, path, &ph, &err);
    CHECK(st == THZ_ERR_CANCELLED, "stopped at the 2nd report: %s: %s", thz_status_name(st),
          err.message);
    CHECK(ph == NULL, "a cancelled load handed out photons");
    CHECK(r.n == 2, "%zu reports after asking to stop at the 2nd", r.n);

    thz_photons_destroy(fired);
    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    return test_finish("test_api_load_progress", tmp);
}
