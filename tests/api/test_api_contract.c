/* The API's contracts: bad input gives THZ_ERR_INPUT with a message naming the text's
 * label and the JSON path or line:column; photons of another scene handle render when
 * the geometry is the same and are refused when not; unknown integrators and half-fired
 * photons are refused; photons fired in disjoint ranges merge, and per channel
 * count what each channel got; non-finite or reversed frequency ranges, additions to a
 * committed output and incomplete figures are refused; an image's sensor name outlives
 * the scene. test_api_contract_args.c has the arguments out of range or NULL. argv: the
 * thzmap binary (unused), the repo. */
#include <math.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "api_test.h"

/* Photons fired one channel per part merge into photons of every channel, and each
 * channel counts the photons of the parts that hold it (not the parts' count times the
 * parts); when the channels differ, photons_per_channel is the largest. */
static void check_merge_per_channel(thz_context *ctx, thz_scene *scene)
{
    thz_error err = {0};
    thz_run_settings settings = {.photons_per_channel = 3000};
    thz_photons *part[3] = {NULL, NULL, NULL}, *merged = NULL;
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 0, &part[0], &err), &err);
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &part[1], &err), &err);
    REQUIRE_OK(thz_photons_merge(ctx, (const thz_photons *const *)part, 2, &merged, &err), &err);
    CHECK(thz_photons_has_channel(merged, 0) && thz_photons_has_channel(merged, 1),
          "a channel is missing");
    CHECK(thz_photons_per_channel(merged) == 3000, "one channel per part: %llu per channel",
          (unsigned long long)thz_photons_per_channel(merged));
    thz_run *run = NULL;
    REQUIRE_OK(thz_render_run(ctx, scene, merged, 1, NULL, &run, &err), &err);
    const char *summary = thz_run_summary_json(run);
    CHECK(summary && strstr(summary, "\"photons_per_channel\": 3000,"), "summary: %.300s",
          summary ? strstr(summary, "photons_per_channel") : "(none)");
    /* a render fires no photons: no photon phase time, as for a map read from a file
     * (a batch's frame rendered from kept photons said its base frame's) */
    for (const char *p = summary; p && (p = strstr(p, "\"photon_phase_s\": ")); p++)
        CHECK(strtod(p + strlen("\"photon_phase_s\": "), NULL) == 0.0, "render: %.40s", p);
    thz_run_destroy(run);
    thz_photons_destroy(merged);
    /* every channel, and channel 1 once more: 3000 in channel 0, 6000 in channel 1 */
    settings.first_photon = 3000;
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &part[2], &err), &err);
    const thz_photons *mixed[2] = {part[1], part[2]};
    REQUIRE_OK(thz_photons_merge(ctx, mixed, 2, &merged, &err), &err);
    thz_photon_stats s0, s1;
    thz_photons_stats(merged, 0, &s0);
    thz_photons_stats(merged, 1, &s1);
    CHECK(s0.fired == 3000 && s1.fired == 6000, "fired %llu and %llu", (unsigned long long)s0.fired,
          (unsigned long long)s1.fired);
    CHECK(thz_photons_per_channel(merged) == 6000, "mixed parts: %llu per channel",
          (unsigned long long)thz_photons_per_channel(merged));
    /* the same photons of a channel twice, or ranges that overlap, are refused */
    const thz_photons *twice[2] = {part[2], part[2]};
    thz_photons *refused = NULL;
    expect_input_error(thz_photons_merge(ctx, twice, 2, &refused, &err), &err,
                       "parts 0 and 1 are the same photon maps", "a part merged with itself");
    CHECK(refused == NULL, "a refused merge returned photons");
    const thz_photons *merged_twice[2] = {merged, merged};
    expect_input_error(thz_photons_merge(ctx, merged_twice, 2, &refused, &err), &err,
                       "parts 0 and 1 are the same photon maps", "a merged map with itself");
    thz_photons *overlap = NULL;
    settings.first_photon = 4000; /* 4000..6999 against 3000..5999 */
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &overlap, &err), &err);
    const thz_photons *over[2] = {part[2], overlap};
    expect_input_error(thz_photons_merge(ctx, over, 2, &refused, &err), &err,
                       "channel 1 (photons 3000 to 5999, and 3000 photons from 4000)",
                       "overlapping ranges");
    thz_photons_destroy(overlap);
    /* a merged map knows its photons: channel 1's 0..5999 again is refused, 6000..11999
     * merge, and the result's ranges join (0..11999 refuses 11999..17998) */
    settings.photons_per_channel = 6000;
    settings.first_photon = 0;
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &overlap, &err), &err);
    const thz_photons *again[2] = {overlap, merged};
    expect_input_error(thz_photons_merge(ctx, again, 2, &refused, &err), &err,
                       "channel 1 (photons 0 to 5999, and 6000 photons from 0)",
                       "a fired map with a merged one of the same photons");
    thz_photons_destroy(overlap);
    settings.first_photon = 6000;
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &overlap, &err), &err);
    const thz_photons *next[2] = {overlap, merged};
    thz_photons *joined = NULL;
    REQUIRE_OK(thz_photons_merge(ctx, next, 2, &joined, &err), &err);
    thz_photons_destroy(overlap);
    settings.photons_per_channel = 12000;
    settings.first_photon = 11999;
    REQUIRE_OK(thz_photons_fire_channel(ctx, scene, &settings, 1, &overlap, &err), &err);
    const thz_photons *last[2] = {joined, overlap};
    expect_input_error(thz_photons_merge(ctx, last, 2, &refused, &err), &err,
                       "channel 1 (photons 0 to 11999, and 12000 photons from 11999)",
                       "a map overlapping a merged map's joined ranges");
    thz_photons_destroy(overlap);
    thz_photons_destroy(joined);
    thz_photons_destroy(merged);
    for (size_t i = 0; i < 3; i++)
        thz_photons_destroy(part[i]);
}

/* An image's sensor name is its own: it outlives the scene the image was rendered in
 * (read freed memory before; the ASan build sees it). */
static void check_image_name_lifetime(thz_context *ctx)
{
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "life.json", &scene, &err), &err);
    thz_run_settings settings = {.photons_per_channel = 2000};
    thz_run *run = NULL;
    thz_photons *photons = NULL;
    thz_image *image = NULL;
    REQUIRE_OK(thz_simulate(ctx, scene, &settings, &run, &err), &err);
    REQUIRE_OK(thz_photons_fire(ctx, scene, &settings, &photons, &err), &err);
    REQUIRE_OK(thz_render_sensor(ctx, scene, photons, 1, NULL, &image, &err), &err);
    thz_photons_destroy(photons);
    thz_scene_destroy(scene);
    const char *name = thz_image_sensor_name(thz_run_image(run, 1));
    CHECK(name && strcmp(name, "side") == 0, "run image 1 is %s", name ? name : "NULL");
    name = thz_image_sensor_name(image);
    CHECK(name && strcmp(name, "side") == 0, "image is %s", name ? name : "NULL");
    thz_image_destroy(image);
    thz_run_destroy(run);
}

/* The atmosphere refuses non-finite and reversed ranges, and its attenuation at a
 * non-finite frequency is NaN (read out of bounds before). */
static void check_atmosphere_frequencies(void)
{
    thz_error err = {0};
    thz_atm_options opt;
    thz_atm_options_init(&opt);
    thz_atm *atm = NULL;
    REQUIRE_OK(thz_atm_create(&opt, NULL, &atm, &err), &err);
    expect_input_error(thz_atm_check_range(atm, NAN, NAN, "f", &err), &err, "finite",
                       "check_range NaN");
    expect_input_error(thz_atm_check_range(atm, 0.3e12, INFINITY, "f", &err), &err, "finite",
                       "check_range infinity");
    expect_input_error(thz_atm_check_range(atm, 0.9e12, 0.3e12, "f", &err), &err, "f: 0.9 to 0.3",
                       "check_range reversed");
    CHECK(thz_atm_check_range(atm, 0.3e12, 0.9e12, "f", &err) == THZ_OK, "%s", err.message);
    CHECK(isnan(thz_atm_attenuation_per_m(atm, NAN)), "alpha(NaN) %g",
          thz_atm_attenuation_per_m(atm, NAN));
    CHECK(isnan(thz_atm_attenuation_per_m(atm, INFINITY)), "alpha(inf) %g",
          thz_atm_attenuation_per_m(atm, INFINITY));
    thz_atm_attenuation parts;
    thz_atm_attenuation_parts(atm, NAN, &parts);
    CHECK(isnan(parts.total_per_m) && isnan(parts.h2o_continuum_per_m), "parts(NaN) %g",
          parts.total_per_m);
    double alpha = thz_atm_attenuation_per_m(atm, 0.35e12);
    CHECK(alpha > 0 && isfinite(alpha), "alpha(0.35 THz) %g", alpha);
    thz_atm_destroy(atm);

    /* the humidity as a volume mixing ratio of the total air: 1 % of 1000 hPa is 10 hPa of
     * water vapour, 7.52 g/m^3 at 288.15 K (ideal gas, 18.015 g/mol), and the same air as
     * a density gives the same attenuation */
    opt.pressure_hpa = 1000.0;
    opt.humidity_kind = THZ_HUMIDITY_VMR;
    opt.humidity = 0.01;
    REQUIRE_OK(thz_atm_create(&opt, NULL, &atm, &err), &err);
    thz_atm_info info;
    thz_atm_get_info(atm, &info);
    CHECK(info.has_air && !info.emitting && info.emission_temperature_k == 0.0,
          "a model made from options has air and emits nothing: %d, %d", info.has_air,
          info.emitting);
    double rho = 1000.0 * 18.015 / (8.314462618 * 288.15);
    CHECK(fabs(info.h2o_pressure_hpa - 10.0) < 1e-9 && fabs(info.h2o_vmr - 0.01) < 1e-12 &&
              fabs(info.h2o_density_g_m3 - rho) < 1e-3 * rho,
          "VMR 0.01 of 1000 hPa: %g hPa of water vapour, VMR %g, %g g/m^3 (expected %g)",
          info.h2o_pressure_hpa, info.h2o_vmr, info.h2o_density_g_m3, rho);
    double alpha_vmr = thz_atm_attenuation_per_m(atm, 0.35e12);
    thz_atm_destroy(atm);
    opt.humidity_kind = THZ_HUMIDITY_DENSITY_G_M3;
    opt.humidity = info.h2o_density_g_m3;
    REQUIRE_OK(thz_atm_create(&opt, NULL, &atm, &err), &err);
    double alpha_rho = thz_atm_attenuation_per_m(atm, 0.35e12);
    CHECK(fabs(alpha_vmr - alpha_rho) <= 1e-9 * alpha_rho,
          "VMR 0.01: alpha %g /m, as %g g/m^3 %g /m", alpha_vmr, info.h2o_density_g_m3, alpha_rho);
    thz_atm_destroy(atm);
}

/* A sensor's optics and noise per channel (thz_scene_sensor_channel): cam has an Airy
 * PSF of D = 1 cm and a Dicke radiometer, side a Gaussian PSF of FWHM 8 degrees and
 * NETDs of 0.3 and 0.5 K with noise seed 3. */
static void check_sensor_channel(const thz_scene *scene)
{
    thz_sensor_channel_info ci;
    thz_error err = {0};
    REQUIRE_OK(thz_scene_sensor_channel(scene, 0, 0, &ci), &err);
    double airy = 1.22 * 299792458.0 / 0.35e12 / 0.01;
    CHECK(strcmp(ci.psf, "airy") == 0 && fabs(ci.spot_rad - airy) < 1e-12 * airy &&
              ci.aperture_diameter_m == 0.01,
          "cam at 0.35 THz: %s PSF, spot %g rad (expected %g)", ci.psf, ci.spot_rad, airy);
    CHECK(strcmp(ci.noise, "dicke") == 0 && ci.netd_k > 0.0 && ci.netd_at_k > 0.0 &&
              ci.noise_bandwidth_hz > 0.0 && !ci.noise_seed_given,
          "cam's noise: %s, NETD %g K at %g K, B_n %g Hz", ci.noise, ci.netd_k, ci.netd_at_k,
          ci.noise_bandwidth_hz);
    REQUIRE_OK(thz_scene_sensor_channel(scene, 1, 1, &ci), &err);
    double fwhm = 8.0 * M_PI / 180.0;
    CHECK(strcmp(ci.psf, "gaussian") == 0 && fabs(ci.spot_rad - fwhm) < 1e-15,
          "side: %s PSF, spot %g rad (expected %g)", ci.psf, ci.spot_rad, fwhm);
    CHECK(strcmp(ci.noise, "netd") == 0 && ci.netd_k == 0.5 && ci.netd_at_k == 0.0 &&
              ci.noise_seed_given && ci.noise_seed == 3,
          "side at 0.9 THz: %s, NETD %g K, seed %d %llu", ci.noise, ci.netd_k, ci.noise_seed_given,
          (unsigned long long)ci.noise_seed);
    CHECK(thz_scene_sensor_channel(scene, 1, 2, &ci) == THZ_ERR_INPUT, "channel 2 of 2");
}

/* The figure refuses what it cannot draw: no points, no path, a curve's array missing
 * (a crash in the drawing child before). */
static void check_atmosphere_plot(void)
{
    thz_error err = {0};
    thz_atm_options opt;
    thz_atm_options_init(&opt);
    opt.model = "itu-p676";
    thz_atm *atm = NULL;
    REQUIRE_OK(thz_atm_create(&opt, NULL, &atm, &err), &err);
    double f[2] = {0.3, 0.4}, db[2] = {1, 2};
    thz_atm_plot plot = {.path = "/nonexistent/never.png",
                         .atm = atm,
                         .model_name = "itu-p676",
                         .n = 2,
                         .f_thz = f,
                         .total_db = db,
                         .h2o_lines_db = db,
                         .o2_db = NULL,
                         .dry_db = db};
    expect_input_error(thz_atm_draw_plot(&plot, &err), &err, "o2_db", "plot without O2");
    plot.o2_db = db;
    plot.n = 0;
    expect_input_error(thz_atm_draw_plot(&plot, &err), &err, "n > 0", "plot of no points");
    plot.n = 2;
    plot.path = NULL;
    expect_input_error(thz_atm_draw_plot(&plot, &err), &err, "no path", "plot without path");
    plot.path = "/nonexistent/never.png";
    plot.f_thz = NULL;
    expect_input_error(thz_atm_draw_plot(&plot, &err), &err, "f_thz", "plot without f");
    expect_input_error(thz_atm_draw_plot(NULL, &err), &err, "no figure", "NULL plot");
    thz_atm_destroy(atm);
}

/* Band selection refuses targets that name nothing, before loading the scene. */
static void check_bands_targets(thz_context *ctx, const char *scene_path)
{
    thz_error err = {0};
    thz_bands_options o;
    thz_bands_options_init(&o);
    o.count = 1;
    o.n_targets = 1;
    thz_bands *bands = (thz_bands *)&err;
    expect_input_error(thz_bands_select(ctx, scene_path, NULL, &bands, &err), &err,
                       "thz_bands_select: no options", "options NULL");
    expect_input_error(thz_bands_select(ctx, scene_path, &o, &bands, &err), &err,
                       "targets: 1 given but no list", "targets NULL");
    CHECK(bands == NULL, "bands came back");
    const char *names[2] = {"plate", NULL};
    o.targets = names;
    o.n_targets = 2;
    expect_input_error(thz_bands_select(ctx, scene_path, &o, &bands, &err), &err,
                       "targets[1]: expected an object's name, got NULL", "target NULL");

    /* the candidate centres: both ends included (0.1 to 1.5 THz by 10 GHz: 141), a step
     * a rounding short of to_thz counted, bad ranges 0 */
    thz_bands_options_init(&o);
    CHECK(thz_bands_candidate_centres(&o) == 141.0, "default candidates");
    o.from_thz = 0.3;
    o.to_thz = 0.6;
    o.step_ghz = 100.0; /* 0.3 + 3 x 0.1 lands a hair off 0.6 in binary */
    CHECK(thz_bands_candidate_centres(&o) == 4.0, "0.3 to 0.6 by 100 GHz");
    o.step_ghz = 0.0;
    CHECK(thz_bands_candidate_centres(&o) == 0.0, "step 0");
    o.step_ghz = 10.0;
    o.to_thz = 0.2;
    CHECK(thz_bands_candidate_centres(&o) == 0.0, "to below from");
    CHECK(thz_bands_candidate_centres(NULL) == 0.0, "NULL options");
}

/* An output takes nothing after its commit, and says so (THZ_ERR_INPUT, not an I/O
 * error about its vanished staging directory); a file of 0 bytes may have no data, one
 * of more bytes must; a run kept without photons writes no photon map; a
 * file never replaces one the output holds. */
static void check_output_order(thz_context *ctx, thz_run *run, const char *dir)
{
    thz_error err = {0};
    char outdir[4200], path[4300];
    snprintf(outdir, sizeof outdir, "%s/order", dir);
    thz_output *out = NULL;
    REQUIRE_OK(thz_output_open(outdir, &out, &err), &err);
    REQUIRE_OK(thz_output_add_file(out, "empty.txt", NULL, 0, &err), &err);
    /* a name the output holds already is refused, not replaced */
    expect_input_error(thz_output_add_file(out, "empty.txt", "x", 1, &err), &err,
                       "empty.txt is in this output already", "the same file twice");
    /* bytes without data, and a photon map of a run that kept none (no keep_photons):
     * refused as input, before anything is written */
    expect_input_error(thz_output_add_file(out, "nodata.bin", NULL, 5, &err), &err,
                       "expected a plain file name and data", "5 bytes of NULL data");
    thz_write_options with_map = {.photon_map = 1};
    expect_input_error(thz_output_add_run(ctx, out, run, &with_map, &err), &err,
                       "kept no photon maps", "a photon map the run did not keep");
    REQUIRE_OK(thz_output_add_run(ctx, out, run, NULL, &err), &err);
    expect_input_error(thz_output_add_file(out, "summary.json", "{}", 2, &err), &err,
                       "summary.json is in this output already", "a file over the run's");
    REQUIRE_OK(thz_output_commit(out, &err), &err);
    struct stat info;
    snprintf(path, sizeof path, "%s/empty.txt", outdir);
    CHECK(stat(path, &info) == 0 && info.st_size == 0, "%s: not an empty file", path);
    expect_input_error(thz_output_commit(out, &err), &err, "already committed", "commit twice");
    expect_input_error(thz_output_add_file(out, "late.txt", "x", 1, &err), &err,
                       "already committed", "add_file after commit");
    expect_input_error(thz_output_add_run(ctx, out, run, NULL, &err), &err, "already committed",
                       "add_run after commit");
    expect_input_error(thz_output_add_image(out, thz_run_image(run, 0), &err), &err,
                       "already committed", "add_image after commit");
    thz_output_destroy(out);
    CHECK(stat(path, &info) == 0, "destroying a committed output removed %s", path);
}

/* A file that cannot be written whole (a full disk; here a file-size limit with SIGXFSZ
 * ignored, so that write() fails with EFBIG) is an I/O error that gives the system's
 * reason, and the uncommitted output leaves nothing at its directory. */
static void check_output_write_fails(const char *dir)
{
    thz_error err = {0};
    char outdir[4200];
    snprintf(outdir, sizeof outdir, "%s/too-large", dir);
    thz_output *out = NULL;
    REQUIRE_OK(thz_output_open(outdir, &out, &err), &err);
    static char data[65536];
    struct rlimit before;
    CHECK(getrlimit(RLIMIT_FSIZE, &before) == 0, "getrlimit");
    struct rlimit small = {.rlim_cur = 4096, .rlim_max = before.rlim_max};
    void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, "setrlimit");
    thz_status st = thz_output_add_file(out, "big.bin", data, sizeof data, &err);
    CHECK(setrlimit(RLIMIT_FSIZE, &before) == 0, "setrlimit back");
    signal(SIGXFSZ, was);
    CHECK(st == THZ_ERR_IO && strstr(err.message, "big.bin: cannot write: File too large"),
          "a write past the limit: status %d, '%s'", (int)st, err.message);
    thz_output_destroy(out);
    struct stat info;
    CHECK(stat(outdir, &info) != 0, "%s exists after a failed, uncommitted output", outdir);
}

/* thz_revision(): a git commit (40 lowercase hex digits, "-dirty" appended when the tree
 * differed from it), "unknown", or the revision the build was given (-DTHZ_REVISION), the
 * same at every call. tests/cli/test_revision.sh holds it against the checkout's commit. */
static void check_revision(void)
{
    const char *rev = thz_revision();
    CHECK(rev != NULL, "thz_revision() is NULL");
    if (!rev)
        return;
    size_t hex = strspn(rev, "0123456789abcdef");
    if (THZ_TEST_REVISION_GIVEN[0])
        CHECK(strcmp(rev, THZ_TEST_REVISION_GIVEN) == 0, "revision '%s', built with '%s'", rev,
              THZ_TEST_REVISION_GIVEN);
    else
        CHECK(strcmp(rev, "unknown") == 0 ||
                  (hex == 40 && (rev[40] == '\0' || strcmp(rev + 40, "-dirty") == 0)),
              "revision '%s': expected 40 hex digits, then nothing or -dirty, or unknown", rev);
    CHECK(thz_revision() == rev, "thz_revision() is not one static string");
}

int main(int argc, char **argv)
{
    (void)argc;
    CHECK(strcmp(thz_version(), THZ_VERSION_STRING) == 0, "version %s", thz_version());
    check_revision();

    thz_error err = {0};
    thz_scene *scene = (thz_scene *)&err; /* must be reset to NULL */
    char *bad = test_scene_with("\"frequency_thz\": 0.9", "\"frequency_thz\": -0.9");
    expect_input_error(thz_scene_load_string(bad, NULL, "bad.json", &scene, &err), &err,
                       "channels[1].frequency_thz", "negative frequency");
    CHECK(strstr(err.message, "bad.json") != NULL, "label missing: %s", err.message);
    CHECK(scene == NULL, "a scene came back");
    free(bad);
    expect_input_error(thz_scene_load_string("{\"format\": ", NULL, "cut.json", &scene, &err), &err,
                       "cut.json:1:", "syntax");
    expect_input_error(thz_scene_load_string(NULL, NULL, NULL, &scene, &err), &err, "no JSON",
                       "NULL text");

    thz_scene *a = NULL, *b = NULL;
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "a.json", &a, &err), &err);
    REQUIRE_OK(thz_scene_load_string(test_scene_json, NULL, "b.json", &b, &err), &err);
    thz_object_info oi;
    CHECK(thz_scene_object(a, 99, &oi) == THZ_ERR_INPUT && oi.name == NULL, "object 99");
    CHECK(thz_scene_object(a, 2, &oi) == THZ_OK && strcmp(oi.type, "shell") == 0 &&
              strcmp(oi.material_name, "cloth") == 0,
          "object 2 is %s of %s", oi.type, oi.material_name);
    CHECK(thz_scene_sensor_index(a, "nobody") == -1, "unknown sensor");
    CHECK(thz_scene_warning(a, thz_scene_warning_count(a)) == NULL, "warning out of range");
    CHECK(thz_integrator_known("path") && !thz_integrator_known("magic"), "integrator names");
    CHECK(thz_integrator_needs_photons("final-gather") && !thz_integrator_needs_photons("path"),
          "needs photons");
    check_sensor_channel(a);
    { /* the scene's constant air emits at its room's 295 K (the enclosure's, by default) */
        thz_atm *sa = NULL;
        thz_atm_info ai;
        REQUIRE_OK(thz_atm_from_scene(a, &sa, &err), &err);
        thz_atm_get_info(sa, &ai);
        CHECK(strcmp(ai.model, "constant") == 0 && !ai.has_air && ai.emitting &&
                  ai.emission_temperature_k == 295.0 && ai.background_temperature_k == 295.0,
              "scene's atmosphere: %s, emitting %d at %g K, background %g K", ai.model, ai.emitting,
              ai.emission_temperature_k, ai.background_temperature_k);
        thz_atm_destroy(sa);
    }
    CHECK(thz_integrator_has_passes("final-gather") && thz_integrator_has_passes("path") &&
              !thz_integrator_has_passes("photon-map") && !thz_integrator_has_passes("magic"),
          "has passes");
    CHECK(thz_mpi_supported() == THZ_TEST_MPI_BUILT, "thz_mpi_supported() %d, the build %d",
          thz_mpi_supported(), THZ_TEST_MPI_BUILT);

    thz_context *ctx = thz_context_create();
    thz_run_settings settings = {.integrator = "magic"};
    thz_photons *ph = (thz_photons *)&err;
    expect_input_error(thz_photons_fire(ctx, a, &settings, &ph, &err), &err, "magic",
                       "unknown integrator");
    CHECK(ph == NULL, "photons came back");
    CHECK(thz_context_last_status(ctx) == THZ_ERR_INPUT &&
              strstr(thz_context_last_message(ctx), "magic"),
          "context's last error: %s", thz_context_last_message(ctx));
    thz_run_settings_init(&settings);
    settings.photons_per_channel = 4000;

    /* two disjoint halves merge into photons of both */
    thz_photons *half[2] = {NULL, NULL}, *merged = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, a, &settings, &half[0], &err), &err);
    settings.first_photon = 4000;
    REQUIRE_OK(thz_photons_fire(ctx, a, &settings, &half[1], &err), &err);
    REQUIRE_OK(thz_photons_merge(ctx, (const thz_photons *const *)half, 2, &merged, &err), &err);
    thz_photon_stats s0, s1, sm;
    thz_photons_stats(half[0], 0, &s0);
    thz_photons_stats(half[1], 0, &s1);
    thz_photons_stats(merged, 0, &sm);
    CHECK(sm.fired == 8000 && sm.stored == s0.stored + s1.stored,
          "merged: %llu fired, %llu stored of %llu + %llu", (unsigned long long)sm.fired,
          (unsigned long long)sm.stored, (unsigned long long)s0.stored,
          (unsigned long long)s1.stored);
    CHECK(thz_photons_per_channel(merged) == 8000, "merged per channel %llu",
          (unsigned long long)thz_photons_per_channel(merged));

    /* photons of another handle of the same scene render (test_api_reuse.c has more);
     * of another geometry (below), or of one channel only, they do not */
    thz_image *image = NULL;
    REQUIRE_OK(thz_render_sensor(ctx, b, merged, 0, NULL, &image, &err), &err);
    thz_image_destroy(image);
    image = (thz_image *)&err;
    thz_photons *one = NULL;
    REQUIRE_OK(thz_photons_fire_channel(ctx, a, &settings, 1, &one, &err), &err);
    CHECK(!thz_photons_has_channel(one, 0) && thz_photons_has_channel(one, 1), "one channel");
    expect_input_error(thz_render_sensor(ctx, a, one, 0, NULL, &image, &err), &err, "channel 0",
                       "half-fired photons");
    expect_input_error(thz_photons_save(one, "/nonexistent/x.thzpm", &err), &err, "channel 0",
                       "saving half-fired photons");
    expect_input_error(thz_render_sensor(ctx, a, merged, 7, NULL, &image, &err), &err, "sensor 7",
                       "sensor out of range");
    /* no scene is "no scene" (it was "the scene has no sensor 0"), for each sensor index */
    expect_input_error(thz_render_sensor(ctx, NULL, merged, 0, NULL, &image, &err), &err,
                       "render: no scene", "render_sensor without a scene");
    thz_run *unrun = NULL;
    expect_input_error(thz_render_run(ctx, NULL, merged, 0, NULL, &unrun, &err), &err,
                       "render: no scene", "render_run without a scene");
    expect_input_error(thz_render_file(ctx, NULL, "x.thzpm", 1, NULL, &unrun, &err), &err,
                       "render: no scene", "render_file without a scene");
    expect_input_error(thz_render_run(ctx, NULL, merged, -1, NULL, &unrun, &err), &err, "no scene",
                       "render_run of every sensor without a scene");
    thz_photons *none = (thz_photons *)&err;
    expect_input_error(thz_photons_fire_channel(ctx, a, &settings, 2, &none, &err), &err,
                       "channel 2", "channel out of range");
    CHECK(none == NULL, "photons came back");

    /* a photon map of another scene is refused on loading */
    char dir[4096], path[4200];
    test_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/a.thzpm", dir);
    REQUIRE_OK(thz_photons_save(merged, path, &err), &err);
    char *other_text =
        test_scene_with("\"size_m\": [0.6, 0.05, 0.5]", "\"size_m\": [0.7, 0.05, 0.5]");
    thz_scene *other = NULL;
    REQUIRE_OK(thz_scene_load_string(other_text, NULL, "other.json", &other, &err), &err);
    thz_photons *foreign = (thz_photons *)&err;
    expect_input_error(thz_photons_load(ctx, other, path, &foreign, &err), &err, "a.thzpm",
                       "map of another scene");
    CHECK(foreign == NULL, "photons came back");
    expect_input_error(thz_render_sensor(ctx, other, merged, 0, NULL, &image, &err), &err,
                       "another scene geometry", "photons of another geometry");
    CHECK(image == NULL, "an image came back");
    thz_output *output = NULL;
    expect_input_error(thz_output_open("", &output, &err), &err, "no output directory",
                       "empty OUTDIR");

    settings = (thz_run_settings){.photons_per_channel = 2000};
    thz_run *run = NULL;
    REQUIRE_OK(thz_simulate(ctx, a, &settings, &run, &err), &err);
    snprintf(path, sizeof path, "%s/a.json", dir);
    test_write_file(path, test_scene_json);
    check_bands_targets(ctx, path);
    check_merge_per_channel(ctx, a);
    check_image_name_lifetime(ctx);
    check_atmosphere_frequencies();
    check_atmosphere_plot();
    check_output_order(ctx, run, dir);
    check_output_write_fails(dir);
    thz_run_destroy(run);

    thz_photons_destroy(one);
    thz_photons_destroy(merged);
    thz_photons_destroy(half[0]);
    thz_photons_destroy(half[1]);
    thz_scene_destroy(other);
    free(other_text);
    thz_scene_destroy(a);
    thz_scene_destroy(b);
    thz_context_destroy(ctx);
    return test_finish(argv[0], dir);
}
