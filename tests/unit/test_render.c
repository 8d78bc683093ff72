/* Renderer behaviour beyond the physics identities: back faces, truth images,
 * oversampling, thread-count independence, cancellation, the integrator table,
 * deterministic passes and the photon map's share of final-gather's standard error. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "physics/planck.h"
#include "scene/scene.h"
#include "sensor/camera.h"
#include "sensor/images.h"
#include "sensor/render.h"
#include "sensor/truth.h"

#include "../physics/identity.h"

/* A black corridor at 300 K seen along y through alpha = 0.2 /m of the paper's
 * non-emitting air (the closed forms below are Beer-Lambert's), a grey box (R = 0.5)
 * in it, a second camera outside the corridor looking at its outside (back faces of
 * the inward box), and a third beside it looking away (at nothing). */
static const char *render_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"render-unit\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.02}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0, \"color\": [0.2, 0.4, 0.8]},"
    "                 \"grey\": {\"reflectivity\": 0.5}},"
    " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.2, \"emitting\": false},"
    " \"objects\": ["
    "   {\"name\": \"corridor\", \"type\": \"solid\", \"material\": \"black\","
    "    \"temperature_k\": 300,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [1, 6, 1], \"inward\": true}},"
    "   {\"name\": \"box\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 320,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.2, 0.2, 0.2]},"
    "    \"transform\": {\"translate_m\": [0.3, 0, 0.3]}}],"
    " \"sensors\": ["
    "   {\"name\": \"inside\", \"position_m\": [0, -2.9, 0], \"direction\": [0, 1, 0],"
    "    \"fov_deg\": 6, \"resolution\": [5, 4], \"oversampling\": 3},"
    "   {\"name\": \"outside\", \"position_m\": [0, -5, 0], \"direction\": [0, 1, 0],"
    "    \"fov_deg\": 5, \"resolution\": [4, 4]},"
    "   {\"name\": \"away\", \"position_m\": [0, -5, 0], \"direction\": [0, -1, 0],"
    "    \"fov_deg\": 5, \"resolution\": [4, 4]}],"
    " \"photons\": {\"per_channel\": 20000, \"seed\": 2},"
    " \"render\": {\"integrator\": \"photon-map\"}}";

typedef struct fixture {
    thz_scene *scene;
    accel *acc;
    photon_map *map;
} fixture;

static int setup(void **state)
{
    static fixture f;
    memset(&f, 0, sizeof f);
    thz_error err;
    if (scene_load_string(render_json, ".", "render-unit", &f.scene, &err) != THZ_OK) {
        print_message("%s\n", err.message);
        return -1;
    }
    if (accel_create(f.scene, &f.acc, &err) != THZ_OK)
        return -1;
    photon_phase_options po = {.threads = 2};
    if (photon_phase_run(f.scene, f.acc, 0, &po, &f.map, NULL, &err) != THZ_OK)
        return -1;
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    photon_map_destroy(f->map);
    accel_destroy(f->acc);
    scene_destroy(f->scene);
    return 0;
}

static void render(fixture *f, size_t sensor, int threads, sensor_images *img, render_stats *st)
{
    const thz_sensor *s = &f->scene->sensors[sensor];
    assert_int_equal(sensor_images_init(img, s->columns, s->rows, 1, 1, NULL), THZ_OK);
    render_options ro = {.threads = threads};
    thz_error err;
    assert_int_equal(render_sensor_truth(f->scene, f->acc, sensor, img, &ro, &err), THZ_OK);
    assert_int_equal(render_sensor_channel(f->scene, f->acc, f->map, 0, sensor, img, &ro, st, &err),
                     THZ_OK);
}

static void test_oversampled_attenuation_and_truth(void **state)
{
    fixture *f = *state;
    sensor_images img;
    render_stats st;
    render(f, 0, 2, &img, &st);
    camera cam;
    assert_int_equal(camera_init(&cam, &f->scene->sensors[0], NULL), THZ_OK);
    double b = ident_band_planck(&f->scene->channels[0], 300.0); /* independent trapezoid */
    assert_int_equal(st.samples, 5 * 4 * 9);
    assert_int_equal(st.back_face_samples, 0);
    for (uint32_t row = 0; row < 4; row++)
        for (uint32_t col = 0; col < 5; col++) {
            /* the pixel value is the mean of its 9 samples, each B exp(-alpha d_s) */
            double expect = 0.0;
            for (uint32_t j = 0; j < 3; j++)
                for (uint32_t i = 0; i < 3; i++) {
                    vec3 d = camera_sample_dir(&cam, col, row, i, j);
                    expect += b * exp(-0.2 * (3.0 + 2.9) / d.y) / 9.0;
                }
            size_t p = row * 5 + col;
            assert_true(fabs(img.radiance[p] - expect) <= 1e-5 * expect);
            vec3 c = camera_pixel_center_dir(&cam, col, row);
            assert_true(fabs(img.distance_m[p] - 5.9 / c.y) <= 1e-5);
            assert_int_equal(img.object_id[p], 0);
            assert_true(img.temperature_k[p] == 300.0f);
            double shade = 0.25 + 0.75 * c.y; /* |cos theta| against the far wall */
            assert_true(fabs(img.visual_rgb[3 * p + 2] - 0.8 * shade) < 1e-6);
            assert_true(fabs(img.visual_rgb[3 * p + 0] - 0.2 * shade) < 1e-6);
        }
    sensor_images_fini(&img);
}

static void test_back_faces_are_black_and_counted(void **state)
{
    fixture *f = *state;
    sensor_images img;
    render_stats st;
    render(f, 1, 1, &img, &st);
    assert_int_equal(st.samples, 16);
    assert_int_equal(st.back_face_samples, 16);
    for (size_t p = 0; p < 16; p++) {
        assert_true(img.radiance[p] == 0.0f);
        assert_true(img.brightness_temperature[p] == 0.0f);
        assert_int_equal(img.object_id[p], 0); /* the truth still names what is there */
    }
    sensor_images_fini(&img);
}

/* The same for every integrator, from a map of L (T0 = 0) and of the deviation L - B0
 * (T0 = 290 K; path's T0 likewise): a sample that sees a back face first, or nothing
 * (the air does not emit), is 0 whatever the reference, the deviation's -B0 there and
 * the air's (tau - 1) B0 on the way cancelling B0 (to rounding: 1e-9 of B0, where a
 * sign error or the corridor's emission leaking in would be about B0 itself).
 * Final-gather's direct back face and path's escape with a reference were run by no
 * test. */
static void test_back_faces_every_integrator(void **state)
{
    fixture *f = *state;
    const thz_integrator kinds[] = {INTEGRATOR_PHOTON_MAP, INTEGRATOR_FINAL_GATHER,
                                    INTEGRATOR_PATH};
    const double t0s[] = {0.0, 290.0};
    double b0 = ident_band_planck(&f->scene->channels[0], 290.0);
    for (size_t t = 0; t < 2; t++) {
        photon_map *map = NULL;
        photon_phase_options po = {.threads = 2, .reference_temperature_k = t0s[t]};
        thz_error err;
        assert_int_equal(photon_phase_run(f->scene, f->acc, 0, &po, &map, NULL, &err), THZ_OK);
        for (size_t k = 0; k < 6; k++) {
            size_t sensor = 1 + k / 3; /* outside, then away */
            f->scene->render.integrator = kinds[k % 3];
            const thz_sensor *s = &f->scene->sensors[sensor];
            sensor_images img;
            render_stats st;
            assert_int_equal(sensor_images_init(&img, s->columns, s->rows, 1, 1, NULL), THZ_OK);
            render_options ro = {.threads = 2, .path_t0_set = true, .path_t0_k = t0s[t]};
            assert_int_equal(
                render_sensor_channel(f->scene, f->acc, map, 0, sensor, &img, &ro, &st, &err),
                THZ_OK);
            assert_int_equal(sensor == 1 ? st.back_face_samples : st.escaped_samples, st.samples);
            for (size_t p = 0; p < 16; p++)
                if (!(fabs(img.radiance[p]) <= 1e-9 * b0))
                    fail_msg("%s, %s, T0 = %g K, pixel %zu: %g W/(m^2 sr Hz), not 0",
                             render_integrator_name(kinds[k % 3]), s->name, t0s[t], p,
                             img.radiance[p]);
            sensor_images_fini(&img);
        }
        photon_map_destroy(map);
    }
    f->scene->render.integrator = INTEGRATOR_PHOTON_MAP;
}

/* Renders sensor 0 as a 30 deg, 33 x 17 view that sees the grey box (photon terms,
 * widened gathers), with the given oversampling and threads; the sensor as it was after. */
static void render_wide(fixture *f, uint32_t oversampling, int threads, sensor_images *img,
                        render_stats *st)
{
    thz_sensor *s = &f->scene->sensors[0];
    thz_sensor saved = *s;
    s->fov_deg = 30.0;
    s->columns = 33;
    s->rows = 17;
    s->oversampling = oversampling;
    render(f, 0, threads, img, st);
    *s = saved;
}

static void test_thread_count_does_not_matter(void **state)
{
    fixture *f = *state;
    sensor_images a, b;
    render_stats sa, sb;
    render_wide(f, 2, 1, &a, &sa);
    render_wide(f, 2, 2, &b, &sb);
    size_t n = 33 * 17;
    assert_memory_equal(a.radiance, b.radiance, n * sizeof(float));
    assert_memory_equal(a.radiance_stderr, b.radiance_stderr, n * sizeof(float));
    assert_memory_equal(a.visual_rgb, b.visual_rgb, 3 * n * sizeof(float));
    assert_int_equal(sa.widened_gathers, sb.widened_gathers);
    bool sees_box = false;
    for (size_t p = 0; p < n; p++)
        sees_box |= a.object_id[p] == 1;
    assert_true(sees_box);
    sensor_images_fini(&a);
    sensor_images_fini(&b);
}

/* The truth maps and the radiance face the same way, the way the camera model says: at
 * fov 30 deg, 33 x 17 pixels (pitch p = 2 tan 15 deg / 33 on the unit image plane), the
 * grey box's front face (x, z in [0.2, 0.4] m at y = -0.1, 2.8 m ahead) covers pixel
 * (col 23, row 2), whose centre is (7 p, 6 p) = (0.114, 0.097); the pixel mirrored about
 * the vertical axis, (9, 2), sees the corridor's side wall x = -0.5 m, 0.5 / 7 p ahead. A
 * truth map mirrored against the render passed every test (the corridor is symmetric). */
static void test_truth_faces_the_render(void **state)
{
    fixture *f = *state;
    sensor_images img;
    render_stats st;
    render_wide(f, 1, 1, &img, &st);
    double p = 2.0 * tan(15.0 * M_PI / 180.0) / 33.0, x = 7.0 * p, z = 6.0 * p;
    assert_true(x > 0.2 / 2.8 && x < 0.4 / 2.8 && z > 0.2 / 2.8 && z < 0.4 / 2.8);
    size_t box = 2 * 33 + 23, wall = 2 * 33 + 9;
    double r = sqrt(1.0 + x * x + z * z), d_box = 2.8 * r, d_wall = 0.5 / x * r;
    assert_int_equal(img.object_id[box], 1);
    assert_int_equal(img.object_id[wall], 0);
    assert_true(fabs(img.distance_m[box] - d_box) < 1e-5);
    assert_true(fabs(img.distance_m[wall] - d_wall) < 1e-5);
    assert_true(img.temperature_k[box] == 320.0f && img.temperature_k[wall] == 300.0f);
    /* the black wall: B(300 K) exp(-alpha d); the box's own emission alone,
     * (1 - R) B(320 K) exp(-alpha d), is a lower bound of its radiance */
    const thz_channel *ch = &f->scene->channels[0];
    double wall_l = ident_band_planck(ch, 300.0) * exp(-0.2 * d_wall);
    assert_true(fabs(img.radiance[wall] - wall_l) <= 1e-5 * wall_l);
    assert_true(img.radiance[box] > 0.5 * ident_band_planck(ch, 320.0) * exp(-0.2 * d_box));
    sensor_images_fini(&img);
}

static int cancel_at_second_call(void *user, const thz_progress *p)
{
    int *calls = user;
    assert_string_equal(p->stage, "render");
    return ++*calls >= 2;
}

static void test_cancel(void **state)
{
    fixture *f = *state;
    const thz_sensor *s = &f->scene->sensors[0];
    sensor_images img;
    assert_int_equal(sensor_images_init(&img, s->columns, s->rows, 1, 0, NULL), THZ_OK);
    int calls = 0;
    render_options ro = {.threads = 1, .progress = cancel_at_second_call, .progress_user = &calls};
    thz_error err;
    assert_int_equal(render_sensor_channel(f->scene, f->acc, f->map, 0, 0, &img, &ro, NULL, &err),
                     THZ_ERR_CANCELLED);
    assert_int_equal(calls, 2);
    sensor_images_fini(&img);
}

static void test_integrator_table(void **state)
{
    fixture *f = *state;
    thz_error err;
    assert_int_equal(render_integrator_check(INTEGRATOR_PHOTON_MAP, &err), THZ_OK);
    assert_int_equal(render_integrator_check(INTEGRATOR_FINAL_GATHER, &err), THZ_OK);
    assert_int_equal(render_integrator_check(INTEGRATOR_PATH, &err), THZ_OK);
    assert_false(render_integrator_needs_photons(INTEGRATOR_PATH));
    assert_true(render_integrator_needs_photons(INTEGRATOR_FINAL_GATHER));
    assert_false(render_integrator_has_passes(INTEGRATOR_PHOTON_MAP));
    assert_true(render_integrator_has_passes(INTEGRATOR_PATH));
    /* photon-map is deterministic given its map: a second pass is refused */
    const thz_sensor *s = &f->scene->sensors[0];
    render_accum acc;
    assert_int_equal(render_accum_init(&acc, (size_t)s->columns * s->rows, &err), THZ_OK);
    assert_int_equal(
        render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, 0, &acc, NULL, NULL, &err),
        THZ_OK);
    assert_int_equal(
        render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, 1, &acc, NULL, NULL, &err),
        THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "more photons"));
    render_accum_fini(&acc);
    thz_integrator it;
    assert_true(render_integrator_parse("path", &it) && it == INTEGRATOR_PATH);
    assert_false(render_integrator_parse("photonmap", &it));
    assert_string_equal(render_integrator_name(INTEGRATOR_FINAL_GATHER), "final-gather");
}

/* Passes of the sampled integrators: deterministic for any thread count, merged in
 * order, and pass 1 differs from pass 0 (its own random numbers). */
static void test_passes_are_deterministic(void **state)
{
    fixture *f = *state;
    const thz_integrator kinds[] = {INTEGRATOR_PATH, INTEGRATOR_FINAL_GATHER};
    thz_sensor *s = &f->scene->sensors[0];
    thz_sensor saved = *s;
    s->fov_deg = 30.0;
    size_t px = (size_t)s->columns * s->rows;
    for (size_t k = 0; k < 2; k++) {
        f->scene->render.integrator = kinds[k];
        f->scene->render.paths_per_sample = 3;
        f->scene->render.gather_rays = 3;
        render_accum a, b;
        thz_error err;
        assert_int_equal(render_accum_init(&a, px, &err), THZ_OK);
        assert_int_equal(render_accum_init(&b, px, &err), THZ_OK);
        render_options one = {.threads = 1}, two = {.threads = 2};
        render_stats st;
        for (uint32_t pass = 0; pass < 2; pass++) {
            assert_int_equal(render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, pass, &a,
                                                        &one, &st, &err),
                             THZ_OK);
            assert_int_equal(render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, pass, &b,
                                                        &two, NULL, &err),
                             THZ_OK);
            if (pass == 0)
                assert_true(st.paths > 0);
        }
        assert_int_equal(a.n, 6);
        assert_memory_equal(a.mean, b.mean, px * sizeof(double));
        assert_memory_equal(a.m2, b.m2, px * sizeof(double));
        /* out-of-order passes are an internal error */
        assert_int_equal(
            render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, 5, &a, &one, NULL, &err),
            THZ_ERR_INTERNAL);
        bool spread = false;
        for (size_t p = 0; p < px; p++)
            spread |= render_accum_stderr(&a, p) > 0.0;
        assert_true(spread); /* the grey box's reflections vary between paths */
        render_accum_fini(&a);
        render_accum_fini(&b);
    }
    f->scene->render.integrator = INTEGRATOR_PHOTON_MAP;
    *s = saved;
}

/* Every sensor and pass has random numbers of its own (render.c's stream index, unique
 * over passes x sensors): sensor 1, placed as sensor 0, renders its pass 0 from other
 * numbers than sensor 0's pass 1. With streams shared between them, two cameras of a
 * scene shared their noise (an average of the two was no less noisy than either, and
 * the difference of a camera with its twin showed no noise at all). */
static void test_streams_of_sensors_and_passes(void **state)
{
    fixture *f = *state;
    thz_sensor *s0 = &f->scene->sensors[0], *s1 = &f->scene->sensors[1];
    thz_sensor saved0 = *s0, saved1 = *s1;
    s0->fov_deg = 30.0;
    *s1 = *s0; /* the same camera */
    size_t px = (size_t)s0->columns * s0->rows;
    const thz_integrator kinds[] = {INTEGRATOR_PATH, INTEGRATOR_FINAL_GATHER};
    for (size_t k = 0; k < 2; k++) {
        f->scene->render.integrator = kinds[k];
        f->scene->render.paths_per_sample = 3;
        f->scene->render.gather_rays = 3;
        render_accum a, b;
        thz_error err;
        render_options ro = {.threads = 2};
        assert_int_equal(render_accum_init(&a, px, &err), THZ_OK);
        assert_int_equal(render_accum_init(&b, px, &err), THZ_OK);
        a.passes = 1; /* sensor 0's pass 1 alone */
        assert_int_equal(
            render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 0, 1, &a, &ro, NULL, &err),
            THZ_OK);
        assert_int_equal(
            render_sensor_channel_pass(f->scene, f->acc, f->map, 0, 1, 0, &b, &ro, NULL, &err),
            THZ_OK);
        size_t varied = 0, same = 0;
        for (size_t p = 0; p < px; p++) {
            if (!(render_accum_stderr(&a, p) > 0.0))
                continue; /* no randomness in this pixel's estimates */
            varied++;
            same += a.mean[p] == b.mean[p];
        }
        print_message("%s: %zu of %zu pixels vary, %zu of them equal between the twins\n",
                      render_integrator_name(kinds[k]), varied, px, same);
        assert_true(varied > 0); /* the grey box's pixels */
        assert_int_equal(same, 0);
        render_accum_fini(&a);
        render_accum_fini(&b);
    }
    f->scene->render.integrator = INTEGRATOR_PHOTON_MAP;
    *s0 = saved0;
    *s1 = saved1;
}

/* render_stderr_k: a radiance error converted to K with dTb/dL at the pixel's Tb. */
static void test_stderr_in_kelvin(void **state)
{
    (void)state;
    const double nu = 0.6e12, tb = 300.0;
    double l = planck_radiance(nu, tb), dl = 1e-4 * l;
    double dt =
        planck_brightness_temperature(nu, l + dl) - planck_brightness_temperature(nu, l - dl);
    double expect = dt / 2.0; /* K per dl */
    assert_true(fabs(render_stderr_k(nu, tb, dl) - expect) <= 1e-5 * expect);
    assert_true(render_stderr_k(nu, 0.0, dl) == 0.0);
}

/* The photon map's share of a final-gather pixel's standard error, by hand: batch sums
 * alternating 1 and 3 (mean 2, squared deviations 8) over N = 4 estimates give the
 * spread of Z_b = B s_b / N, 64 / (7 N^2) = 4/7, less the disks' Poisson variance
 * 1.6 / N^2 = 0.1; the estimates' own spread adds to it in render_accum_stderr. */
static void test_map_share_of_stderr(void **state)
{
    (void)state;
    _Static_assert(PHOTON_MAP_BATCHES == 8, "the numbers below are for 8 batches");
    render_accum acc;
    thz_error err;
    assert_int_equal(render_accum_init(&acc, 1, &err), THZ_OK);
    const double est[4] = {1.0, 2.0, 4.0, 5.0}; /* mean 3, m2 10 */
    double batch[PHOTON_MAP_BATCHES], disk_var = 1.6;
    for (unsigned b = 0; b < PHOTON_MAP_BATCHES; b++)
        batch[b] = b % 2 ? 3.0 : 1.0;
    render_accum_add_pixel(&acc, 0, est, 4, NULL, NULL);
    render_accum_end_pass(&acc, 4, false);
    assert_true(render_accum_map_stderr(&acc, 0) == 0.0); /* no batches: path */
    assert_true(fabs(render_accum_stderr(&acc, 0) - sqrt(10.0 / 12.0)) < 1e-12);
    render_accum_fini(&acc);

    assert_int_equal(render_accum_init(&acc, 1, &err), THZ_OK);
    assert_int_equal(render_accum_want_batches(&acc, &err), THZ_OK);
    render_accum_add_pixel(&acc, 0, est, 4, batch, &disk_var);
    render_accum_end_pass(&acc, 4, false);
    double map_var = 4.0 / 7.0 - 0.1;
    assert_true(fabs(render_accum_map_stderr(&acc, 0) - sqrt(map_var)) < 1e-12);
    assert_true(fabs(render_accum_stderr(&acc, 0) - sqrt(10.0 / 12.0 + map_var)) < 1e-12);
    render_accum_fini(&acc);

    /* disks noisier than the batches' spread: the map adds nothing */
    assert_int_equal(render_accum_init(&acc, 1, &err), THZ_OK);
    assert_int_equal(render_accum_want_batches(&acc, &err), THZ_OK);
    disk_var = 16.0;
    render_accum_add_pixel(&acc, 0, est, 4, batch, &disk_var);
    render_accum_end_pass(&acc, 4, false);
    assert_true(render_accum_map_stderr(&acc, 0) == 0.0);
    render_accum_fini(&acc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_oversampled_attenuation_and_truth),
        cmocka_unit_test(test_back_faces_are_black_and_counted),
        cmocka_unit_test(test_thread_count_does_not_matter),
        cmocka_unit_test(test_truth_faces_the_render),
        cmocka_unit_test(test_cancel),
        cmocka_unit_test(test_back_faces_every_integrator),
        cmocka_unit_test(test_integrator_table),
        cmocka_unit_test(test_passes_are_deterministic),
        cmocka_unit_test(test_streams_of_sensors_and_passes),
        cmocka_unit_test(test_stderr_in_kelvin),
        cmocka_unit_test(test_map_share_of_stderr),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
