/* Render passes shared by processes (sensor/render_tiles.h; over MPI in src/mpi/), with
 * the processes played in one: each member renders its tiles of every pass into its own
 * pixel statistics, and the lead copies the others' tiles into its own after each pass,
 * as the MPI team does. The lead's statistics (means, squared deviations, photon batch
 * sums and disk variances) and summed counts must equal, byte for byte, one process's,
 * for photon-map, final-gather (batched deviation map) and path, 2 passes where the
 * integrator has passes, 2, 3 and 5 members and 1 and 2 threads; the tiles deal every
 * pixel to exactly one member, each member within one tile row of the others' shares.
 * Two crates inside out, left and right of the box, are seen from the back in different
 * members' tiles: the counts name both, as one process's do. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "core/alloc.h"
#include "photon/phase.h"
#include "scene/scene.h"
#include "sensor/render.h"
#include "sensor/render_tiles.h"

/* A grey box at 320 K in a black enclosure at 300 K between two crates inside out (objects
 * 2 and 3), seen by a camera of 37 x 21 pixels (3 x 2 tiles, the last ones partial). */
static const char *tiles_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"tiles-unit\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.02}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0}, \"grey\": {\"reflectivity\": 0.5}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
    "    \"temperature_k\": 300,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [2, 6, 2], \"inward\": true}},"
    "   {\"name\": \"box\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 320,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.4, 0.4, 0.4]}},"
    "   {\"name\": \"left\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 310,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.15, 0.15, 0.15], \"inward\": true},"
    "    \"transform\": {\"translate_m\": [-0.32, 0, 0]}},"
    "   {\"name\": \"right\", \"type\": \"solid\", \"material\": \"grey\", \"temperature_k\": 310,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [0.15, 0.15, 0.15], \"inward\": true},"
    "    \"transform\": {\"translate_m\": [0.32, 0, 0]}}],"
    " \"sensors\": ["
    "   {\"name\": \"cam\", \"position_m\": [0, -2.5, 0], \"direction\": [0, 1, 0],"
    "    \"fov_deg\": 20, \"resolution\": [37, 21]}],"
    " \"photons\": {\"per_channel\": 20000, \"seed\": 3},"
    " \"render\": {\"integrator\": \"photon-map\", \"gather_rays\": 2,"
    "              \"paths_per_sample\": 2}}";

/* Renders `passes` passes of sensor 0 as member m of n (n = 0: alone) into acc. */
static void render_passes(const thz_scene *s, const accel *acc, const photon_map *map,
                          uint32_t passes, int threads, size_t m, size_t n, render_accum *out,
                          render_stats *counts)
{
    render_options ro = {.threads = threads, .member = m, .members = n};
    thz_error err;
    render_context *ctx;
    assert_int_equal(render_context_create(s, acc, map, 0, &ro, &ctx, &err), THZ_OK);
    memset(counts, 0, sizeof *counts);
    for (uint32_t p = 0; p < passes; p++) {
        render_stats st;
        if (render_context_pass(ctx, 0, p, out, &ro, &st, &err) != THZ_OK)
            fail_msg("%s", err.message);
        render_stats_add_counts(counts, &st);
    }
    render_context_destroy(ctx);
}

/* The lead's statistics after every member rendered its tiles of each pass and the lead
 * copied them in (pass by pass, as the MPI team does). */
static void render_shared(const thz_scene *s, const accel *acc, const photon_map *map,
                          uint32_t passes, int threads, size_t n, render_accum *lead,
                          render_stats *counts)
{
    const thz_sensor *sn = &s->sensors[0];
    size_t pixels = (size_t)sn->columns * sn->rows;
    render_accum *member = thz_calloc(n, sizeof *member);
    render_options *ro = thz_calloc(n, sizeof *ro);
    render_context **ctx = thz_calloc(n, sizeof *ctx);
    assert_non_null(member);
    assert_non_null(ro);
    assert_non_null(ctx);
    thz_error err;
    memset(counts, 0, sizeof *counts);
    for (size_t m = 0; m < n; m++) {
        ro[m] = (render_options){.threads = threads, .member = m, .members = n};
        assert_int_equal(render_accum_init(&member[m], pixels, &err), THZ_OK);
        assert_int_equal(render_context_create(s, acc, map, 0, &ro[m], &ctx[m], &err), THZ_OK);
    }
    for (uint32_t p = 0; p < passes; p++) {
        for (size_t m = 0; m < n; m++) {
            render_stats st;
            if (render_context_pass(ctx[m], 0, p, &member[m], &ro[m], &st, &err) != THZ_OK)
                fail_msg("%s", err.message);
            render_stats_add_counts(counts, &st);
        }
        for (size_t m = 1; m < n; m++) {
            size_t k = render_tiles_count(pixels, sn->columns, m, n) *
                       render_tiles_doubles_per_pixel(&member[m]);
            double *buf = thz_malloc_array(k + 1, sizeof *buf);
            assert_non_null(buf);
            render_tiles_pack(&member[m], sn->columns, m, n, buf);
            render_tiles_unpack(&member[0], sn->columns, m, n, buf);
            free(buf);
        }
    }
    *lead = member[0];
    for (size_t m = 0; m < n; m++) {
        render_context_destroy(ctx[m]);
        if (m > 0)
            render_accum_fini(&member[m]);
    }
    free(member);
    free(ro);
    free(ctx);
}

static void assert_same_accum(const render_accum *a, const render_accum *b)
{
    assert_int_equal(a->pixels, b->pixels);
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->passes, b->passes);
    assert_int_equal(a->poisson, b->poisson);
    assert_memory_equal(a->mean, b->mean, a->pixels * sizeof *a->mean);
    assert_memory_equal(a->m2, b->m2, a->pixels * sizeof *a->m2);
    assert_true((a->batch == NULL) == (b->batch == NULL));
    if (a->batch) {
        assert_memory_equal(a->batch, b->batch, a->pixels * PHOTON_MAP_BATCHES * sizeof *a->batch);
        assert_memory_equal(a->disk_var, b->disk_var, a->pixels * sizeof *a->disk_var);
    }
}

static void check_integrator(thz_integrator integrator)
{
    thz_scene *s;
    thz_error err;
    if (scene_load_string(tiles_json, ".", "tiles-unit", &s, &err) != THZ_OK)
        fail_msg("%s", err.message);
    s->render.integrator = integrator;
    accel *acc;
    assert_int_equal(accel_create(s, &acc, &err), THZ_OK);
    photon_map *map = NULL;
    if (render_integrator_needs_photons(integrator)) {
        photon_phase_options po = {
            .threads = 2,
            .reference_temperature_k =
                integrator == INTEGRATOR_FINAL_GATHER ? scene_reference_temperature_k(s, 0) : 0.0};
        assert_int_equal(photon_phase_run(s, acc, 0, &po, &map, NULL, &err), THZ_OK);
    }
    uint32_t passes = render_integrator_has_passes(integrator) ? 2 : 1;
    size_t pixels = (size_t)s->sensors[0].columns * s->sensors[0].rows;
    render_accum alone;
    render_stats alone_counts;
    assert_int_equal(render_accum_init(&alone, pixels, &err), THZ_OK);
    render_passes(s, acc, map, passes, 1, 0, 0, &alone, &alone_counts);
    assert_true(alone_counts.samples > 0);
    assert_true(alone_counts.back_face_samples > 0 && alone_counts.back_face_object_lo == 2 &&
                alone_counts.back_face_object_hi == 3);
    if (integrator == INTEGRATOR_FINAL_GATHER)
        assert_non_null(alone.batch); /* the batched map's statistics are shared too */
    size_t members[] = {2, 3, 5};
    for (size_t i = 0; i < 3; i++)
        for (int threads = 1; threads <= 2; threads++) {
            render_accum lead;
            render_stats counts;
            render_shared(s, acc, map, passes, threads, members[i], &lead, &counts);
            assert_same_accum(&alone, &lead);
            alone_counts.seconds = counts.seconds = 0.0; /* wall times */
            assert_memory_equal(&alone_counts, &counts, sizeof counts);
            render_accum_fini(&lead);
        }
    render_accum_fini(&alone);
    photon_map_destroy(map);
    accel_destroy(acc);
    scene_destroy(s);
}

static void test_photon_map_shared(void **state)
{
    (void)state;
    check_integrator(INTEGRATOR_PHOTON_MAP);
}

static void test_final_gather_shared(void **state)
{
    (void)state;
    check_integrator(INTEGRATOR_FINAL_GATHER);
}

static void test_path_shared(void **state)
{
    (void)state;
    check_integrator(INTEGRATOR_PATH);
}

static void test_tiles_deal_every_pixel_once(void **state)
{
    (void)state;
    uint32_t sizes[][2] = {{1, 1}, {16, 16}, {37, 21}, {640, 480}, {17, 200}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        uint32_t cols = sizes[i][0], rows = sizes[i][1];
        size_t pixels = (size_t)cols * rows;
        for (size_t n = 1; n <= 7; n++) {
            size_t total = 0, most = 0, least = SIZE_MAX;
            for (size_t m = 0; m < n; m++) {
                size_t k = render_tiles_count(pixels, cols, m, n);
                total += k;
                most = k > most ? k : most;
                least = k < least ? k : least;
            }
            assert_int_equal(total, pixels); /* every pixel to exactly one member */
            /* diagonal dealing: the shares differ by at most a tile row's worth per tile
             * row of the image */
            size_t tile_rows = (rows + RENDER_TILE_PIXELS - 1) / RENDER_TILE_PIXELS;
            assert_true(most - least <= tile_rows * RENDER_TILE_PIXELS * RENDER_TILE_PIXELS);
        }
    }
    assert_int_equal(render_tile_owner(15, 15, 2), 0);
    assert_int_equal(render_tile_owner(16, 0, 2), 1);
    assert_int_equal(render_tile_owner(16, 16, 2), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_photon_map_shared),
        cmocka_unit_test(test_final_gather_shared),
        cmocka_unit_test(test_path_shared),
        cmocka_unit_test(test_tiles_deal_every_pixel_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
