/* Loading a scene through the API checks what the loader alone cannot and a run would
 * refuse: a PSF too much wider than the image to fold onto it is refused at load, from
 * text and from a file, with the JSON path of the key that sets its width, as
 * thz_simulate refuses it. (thz_scene_load accepted such a scene, so `thzmap validate`,
 * Python's load_scene and serve's /api/validate called it valid; simulate then exited
 * 2.) argv: the thzmap binary (unused), the repository (unused). */
#include "api_test.h"

static void expect_psf_refused(thz_status st, thz_scene *const *scene, const thz_error *err,
                               const char *file, const char *what)
{
    char want[4400];
    snprintf(want, sizeof want, "%s: sensors[1].psf_fwhm_deg: the PSF reaches ", file);
    CHECK(st == THZ_ERR_INPUT && *scene == NULL, "%s: %s, scene %p", what, thz_status_name(st),
          (const void *)*scene);
    CHECK(strncmp(err->message, want, strlen(want)) == 0 &&
              strstr(err->message, "expected at most 4095 pixels"),
          "%s: '%s', expected it to start '%s'", what, err->message, want);
    if (st == THZ_OK)
        thz_scene_destroy(*scene);
}

int main(int argc, char **argv)
{
    (void)argc;
    char dir[4096], path[4200];
    test_temp_dir(dir, sizeof dir);
    /* sensor "side": a 120 deg Gaussian PSF on a field of 0.01 deg, 12 x 12 pixels,
     * reaches 5.8e5 pixels from the centre; the fold takes at most 4095 */
    char *wide =
        test_scene_with("\"fov_deg\": 50, \"resolution\": [12, 12], \"psf\": \"gaussian\", "
                        "\"psf_fwhm_deg\": 8",
                        "\"fov_deg\": 0.01, \"resolution\": [12, 12], \"psf\": \"gaussian\", "
                        "\"psf_fwhm_deg\": 120");
    thz_error err = {0};
    thz_scene *scene = (thz_scene *)&err; /* must be reset to NULL */
    expect_psf_refused(thz_scene_load_string(wide, NULL, "wide.json", &scene, &err), &scene, &err,
                       "wide.json", "from text");
    snprintf(path, sizeof path, "%s/wide.json", dir);
    test_write_file(path, wide);
    scene = (thz_scene *)&err;
    expect_psf_refused(thz_scene_load(path, &scene, &err), &scene, &err, path, "from a file");
    free(wide);

    /* the same sensor with its 8 deg PSF on its 50 deg field loads */
    scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "fine.json", &scene, &err), &err);
    thz_scene_destroy(scene);
    return test_finish(argv[0], dir);
}
