/* thz_photons_merge refuses parts fired for different integrators in a channel as bad
 * input naming the part, whichever part holds the channel first: part 0 may hold none of
 * that channel's photons (fired for another channel alone). argv: the thzmap binary
 * (unused), the repo (unused). */
#include "api_test.h"

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "merge.json", &scene, &err), &err);
    thz_context *ctx = thz_context_create();
    thz_context_set_threads(ctx, 1);
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
    printf("test_api_merge_integrators: %d failures\n", test_failures);
    return test_failures ? 1 : 0;
}
