/* thz_photons_merge refuses what would count photons wrongly, as bad input naming the
 * parts: parts fired for different integrators in a channel, whichever part holds the
 * channel first (part 0 may hold none of it: fired for another channel alone); and a
 * simulation's kept photons merged with a set fired over the same photon numbers (the
 * kept set knows them as a fired one does). argv: the thzmap binary (unused), the repo
 * (unused). */
#include "api_test.h"

/* The kept photons of a simulation hold photons 0 .. K - 1 of each channel: a set fired
 * from 0 again is refused (it merged, every photon counted twice), one fired from K
 * merges. */
static void check_kept_photons(thz_context *ctx, const thz_scene *scene)
{
    thz_error err = {0};
    thz_run_settings settings = {.photons_per_channel = 2000, .keep_photons = 1};
    thz_run *run = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &run, &err), &err);
    const thz_photons *kept = thz_run_photons(run);
    CHECK(kept != NULL, "the run kept no photons");
    settings.keep_photons = 0;
    thz_photons *again = NULL, *next = NULL, *merged = (thz_photons *)&err;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &again, &err), &err);
    const thz_photons *same[2] = {kept, again};
    thz_status st = thz_photons_merge(ctx, same, 2, &merged, &err);
    CHECK(st == THZ_ERR_INPUT && strstr(err.message, "hold the same photons of channel 0") &&
              strstr(err.message, "photons 0 to 1999"),
          "kept and fired photons 0..1999: %s: %s", thz_status_name(st), err.message);
    CHECK(merged == NULL, "a refused merge returned photons");
    if (st == THZ_OK)
        thz_photons_destroy(merged);
    settings.first_photon = 2000;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &next, &err), &err);
    const thz_photons *disjoint[2] = {kept, next};
    merged = NULL;
    REQUIRE_OK(thz_photons_merge(ctx, disjoint, 2, &merged, &err), &err);
    CHECK(thz_photons_per_channel(merged) == 4000, "merged: %llu per channel",
          (unsigned long long)thz_photons_per_channel(merged));
    thz_photons_destroy(merged);
    thz_photons_destroy(next);
    thz_photons_destroy(again);
    thz_run_destroy(run);
}

/* Parts fired for another handle of the same scene merge as parts of one handle do
 * (they were refused: "another scene"), and the merged set renders the same bytes; a
 * handle of a scene with a plate 1 K warmer is refused naming the part and what differs. */
static void check_other_handles(thz_context *ctx, const thz_scene *scene)
{
    thz_error err = {0};
    thz_scene *twin = NULL, *warmer = NULL;
    char *warm = test_scene_with("\"temperature_k\": 310", "\"temperature_k\": 311");
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "twin.json", &twin, &err), &err);
    REQUIRE_OK(thz_scene_load_string(warm, NULL, "warmer.json", &warmer, &err), &err);
    thz_run_settings settings = {.photons_per_channel = 2000};
    thz_photons *first = NULL, *own = NULL, *other = NULL, *warm_part = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &first, &err), &err);
    settings.first_photon = 2000;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &own, &err), &err);
    REQUIRE_OK(thz_photons_fire(ctx, twin, &settings, &other, &err), &err);
    REQUIRE_OK(thz_photons_fire(ctx, warmer, &settings, &warm_part, &err), &err);
    const thz_photons *one[2] = {first, own}, *two[2] = {first, other};
    const thz_photons *bad[2] = {first, warm_part};
    thz_photons *a = NULL, *b = NULL, *refused = (thz_photons *)&err;
    REQUIRE_OK(thz_photons_merge(ctx, one, 2, &a, &err), &err);
    REQUIRE_OK(thz_photons_merge(ctx, two, 2, &b, &err), &err);
    thz_run *ra = NULL, *rb = NULL;
    thz_run_settings render = {0};
    REQUIRE_OK(thz_render_run(ctx, scene, a, -1, &render, &ra, &err), &err);
    REQUIRE_OK(thz_render_run(ctx, scene, b, -1, &render, &rb, &err), &err);
    const thz_image *ia = thz_run_image(ra, 0), *ib = thz_run_image(rb, 0);
    size_t na = 0, nb = 0;
    const float *pa = thz_image_plane(ia, THZ_PLANE_RADIANCE, &na);
    const float *pb = thz_image_plane(ib, THZ_PLANE_RADIANCE, &nb);
    size_t values = (size_t)thz_image_columns(ia) * thz_image_rows(ia) * na;
    CHECK(pa && pb && na == nb && values > 0 && !memcmp(pa, pb, values * sizeof *pa),
          "the merge of two handles' parts renders other bytes than one handle's");
    thz_status st = thz_photons_merge(ctx, bad, 2, &refused, &err);
    CHECK(st == THZ_ERR_INPUT && strstr(err.message, "part 1") &&
              strstr(err.message, "made from another scene (materials, temperatures"),
          "a warmer scene's part: %s: %s", thz_status_name(st), err.message);
    CHECK(refused == NULL, "a refused merge returned photons");
    thz_run_destroy(ra);
    thz_run_destroy(rb);
    thz_photons_destroy(a);
    thz_photons_destroy(b);
    thz_photons_destroy(first);
    thz_photons_destroy(own);
    thz_photons_destroy(other);
    thz_photons_destroy(warm_part);
    thz_scene_destroy(twin);
    thz_scene_destroy(warmer);
    free(warm);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "merge.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
    check_kept_photons(ctx, scene);
    check_other_handles(ctx, scene);
    thz_run_settings settings = {.photons_per_channel = 2000};
    thz_photons *part[3] = {NULL, NULL, NULL};
    /* channel 0 alone; channel 1 as a map of L (photon-map, T0 0) and, with other photon
     * numbers, as final-gather's deviation map (T0 the channel's reference temperature) */
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 0, &part[0], &err), &err);
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &part[1], &err), &err);
    settings.integrator = "final-gather";
    settings.first_photon = 2000;
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &part[2], &err), &err);
    thz_photon_stats s1, s2;
    thz_photons_stats(part[1], 1, &s1);
    thz_photons_stats(part[2], 1, &s2);
    CHECK(s1.reference_temperature_k == 0.0 && s2.reference_temperature_k > 0.0,
          "the parts' channel 1 maps have T0 %g and %g K", s1.reference_temperature_k,
          s2.reference_temperature_k);

    /* with part 0 holding channel 1 the refusal was there already; without, the maps
     * reached the map merge, which said "internal error" (THZ_ERR_INTERNAL, exit 1) */
    const thz_photons *order[2][3] = {{part[1], part[2], part[0]}, {part[0], part[1], part[2]}};
    for (int k = 0; k < 2; k++) {
        thz_photons *merged = (thz_photons *)&err;
        thz_error e = {0};
        thz_status st = thz_photons_merge(ctx, order[k], 3, &merged, &e);
        CHECK(st == THZ_ERR_INPUT, "order %d: %s: %s", k, thz_status_name(st), e.message);
        CHECK(strstr(e.message, "fired for another integrator") != NULL &&
                  strstr(e.message, "channel 1") != NULL,
              "order %d: %s", k, e.message);
        CHECK(merged == NULL, "order %d: a refused merge returned photons", k);
        thz_photons_destroy(merged == (thz_photons *)&err ? NULL : merged);
    }
    for (size_t i = 0; i < 3; i++)
        thz_photons_destroy(part[i]);
    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    printf("test_api_merge_refusals: %d failures\n", test_failures);
    return test_failures ? 1 : 0;
}
