/* Shared helpers of the physics identity tests (physics.md "Identities"): load a scene
 * from JSON text, run the photon phase (unless the integrator is `path`) and the
 * renderer with a chosen integrator, and check pixels against a closed form with
 * tolerances from the renderer's own standard errors. Every identity test loops over
 * ident_integrators: the identities hold for each integrator (physics.md "Integrators").
 *
 * Tolerances: the renderer estimates each pixel's standard error: photon-map from the
 * photons it gathered (Poisson: sqrt(sum of squared photon terms) / A_g), final-gather
 * and path from the spread of the pixel's independent estimates (gather rays, paths).
 * A pixel passes when it lies within IDENT_Z standard errors; the tests also bound that
 * standard error so that no tolerance is wide enough to hide a factor of 2 or pi.
 * THZ_TEST_SCALE (e.g. 0.25) scales the photon, path and gather-ray counts; the standard
 * errors, and so the tolerances, follow.
 */
#ifndef THZ_TESTS_PHYSICS_IDENTITY_H
#define THZ_TESTS_PHYSICS_IDENTITY_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "physics/channel.h"
#include "physics/planck.h"
#include "scene/scene.h"
#include "sensor/camera.h"
#include "sensor/images.h"
#include "sensor/render.h"
#include "sensor/truth.h"

/* Standard errors a pixel may lie from the closed form (per pixel, ~600 pixels a test:
 * P(|z| > 5) = 5.7e-7 each). */
#define IDENT_Z 5.0

static inline double ident_scale(void)
{
    const char *s = getenv("THZ_TEST_SCALE");
    double v = s ? atof(s) : 1.0;
    return v > 0.0 ? v : 1.0;
}

/* Photons for a test: base x THZ_TEST_SCALE, at least 1000. */
static inline uint64_t ident_photons(double base)
{
    double n = base * ident_scale();
    return n < 1000.0 ? 1000u : (uint64_t)n;
}

/* The integrators every identity is checked with. */
static const thz_integrator ident_integrators[] = {INTEGRATOR_PHOTON_MAP, INTEGRATOR_FINAL_GATHER,
                                                   INTEGRATOR_PATH};
#define IDENT_N_INTEGRATORS (sizeof ident_integrators / sizeof ident_integrators[0])

/* Paths per sample (path) and gather rays (final-gather) for a test: base x
 * THZ_TEST_SCALE, at least 16 (so that a pixel's standard error is itself known to
 * about 1/sqrt(2 x 16) = 18 %). */
static inline uint32_t ident_estimates(double base)
{
    double n = base * ident_scale();
    return n < 16.0 ? 16u : (uint32_t)n;
}

typedef struct ident_run {
    thz_scene *scene;
    accel *acc;
    sensor_images img; /* of sensor 0, all channels */
    photon_stats stats[8];
    render_stats rstats[8];
    camera cam;
} ident_run;

/* The reference temperatures every identity runs with: NAN, as simulate and path choose
 * it (the enclosure's, where reflected and transmitted terms vanish against B(T0), so
 * their weights go unchecked), and 0 K (no control variate: those weights count in full;
 * final-gather then reads the paper's map of L). photon-map's own map has T0 = 0
 * already, so it runs once. */
#define IDENT_N_T0 2
static const double ident_t0s[IDENT_N_T0] = {NAN, 0.0};

static inline bool ident_t0_applies(thz_integrator integrator, size_t variant)
{
    return variant == 0 || integrator != INTEGRATOR_PHOTON_MAP;
}

/* The image's pooled relative standard error of channel c against expected values
 * expect(col, row) (ident_tally.pooled_rel_se): a pixel's own error, from 16 estimates at
 * THZ_TEST_SCALE = 0.25, is Student-t distributed, and among 144 pixels one then lies
 * beyond 5 of its own errors now and then (measured z = 6.1 with path at T0 = 0 K). */
static inline double ident_pooled_rel_se(const ident_run *r, size_t c, const double *expect)
{
    double sum = 0.0;
    size_t n = (size_t)r->img.rows * r->img.columns;
    for (size_t i = 0; i < n; i++) {
        double rel = r->img.radiance_stderr[c * n + i] / expect[i];
        sum += rel * rel;
    }
    return n ? sqrt(sum / (double)n) : 0.0;
}

/* The same against one expected value for every pixel of channel c. */
static inline double ident_pooled_rel_se_of(const ident_run *r, size_t c, double expect)
{
    double sum = 0.0;
    size_t n = (size_t)r->img.rows * r->img.columns;
    for (size_t i = 0; i < n; i++)
        sum += (double)r->img.radiance_stderr[c * n + i] * r->img.radiance_stderr[c * n + i];
    return n ? sqrt(sum / (double)n) / expect : 0.0;
}

/* "integrator" or "integrator, T0 = 0 K", for messages. */
static inline void ident_label(char *out, size_t size, thz_integrator integrator, double t0_k)
{
    if (isnan(t0_k))
        snprintf(out, size, "%s", render_integrator_name(integrator));
    else
        snprintf(out, size, "%s, T0 = %g K", render_integrator_name(integrator), t0_k);
}

/* The photon phase's options as `simulate` sets them: final-gather fires the deviation
 * map at the renderer's T0, photon-map the paper's map. */
static inline photon_phase_options ident_photon_options(const thz_scene *scene, size_t channel,
                                                        thz_integrator integrator)
{
    photon_phase_options po = {.threads = 2};
    if (integrator == INTEGRATOR_FINAL_GATHER)
        po.reference_temperature_k = scene_reference_temperature_k(scene, channel);
    return po;
}

/* Loads the scene (photons.per_channel replaced by `photons` when non-zero), renders
 * every channel of sensor 0 with 2 threads and `integrator` (paths_per_sample and
 * gather_rays set to `estimates` when non-zero), and fills the truth images. */
static inline void ident_run_scene_t0(ident_run *r, const char *json, uint64_t photons,
                                      thz_integrator integrator, uint32_t estimates, double t0_k);

static inline void ident_run_scene_with(ident_run *r, const char *json, uint64_t photons,
                                        thz_integrator integrator, uint32_t estimates)
{
    ident_run_scene_t0(r, json, photons, integrator, estimates, NAN);
}

/* The same with reference temperature t0_k (NAN: as simulate chooses it): the photon
 * map's (photon-map, final-gather) or path's T0. With T0 away from the enclosure's
 * temperature the reflected and transmitted terms no longer vanish against B(T0), so an
 * identity then checks their weights too. */
static inline void ident_run_scene_t0(ident_run *r, const char *json, uint64_t photons,
                                      thz_integrator integrator, uint32_t estimates, double t0_k)
{
    memset(r, 0, sizeof *r);
    thz_error err;
    thz_error_clear(&err);
    thz_status st = scene_load_string(json, ".", "identity-test", &r->scene, &err);
    if (st != THZ_OK)
        print_message("scene: %s\n", err.message);
    assert_int_equal(st, THZ_OK);
    if (photons)
        r->scene->photons.per_channel = photons;
    r->scene->render.integrator = integrator;
    if (estimates) {
        r->scene->render.paths_per_sample = estimates;
        r->scene->render.gather_rays = estimates;
    }
    assert_true(r->scene->n_channels <= 8);
    assert_int_equal(accel_create(r->scene, &r->acc, &err), THZ_OK);
    const thz_sensor *sn = &r->scene->sensors[0];
    assert_int_equal(camera_init(&r->cam, sn, &err), THZ_OK);
    assert_int_equal(
        sensor_images_init(&r->img, sn->columns, sn->rows, r->scene->n_channels, 1, &err), THZ_OK);
    render_options ro = {.threads = 2, .path_t0_set = !isnan(t0_k), .path_t0_k = t0_k};
    assert_int_equal(render_sensor_truth(r->scene, r->acc, 0, &r->img, &ro, &err), THZ_OK);
    for (size_t c = 0; c < r->scene->n_channels; c++) {
        photon_phase_options po = ident_photon_options(r->scene, c, integrator);
        if (!isnan(t0_k))
            po.reference_temperature_k = t0_k;
        photon_map *map = NULL;
        if (render_integrator_needs_photons(integrator)) {
            st = photon_phase_run(r->scene, r->acc, c, &po, &map, &r->stats[c], &err);
            if (st != THZ_OK)
                print_message("photon phase: %s\n", err.message);
            assert_int_equal(st, THZ_OK);
        }
        st = render_sensor_channel(r->scene, r->acc, map, c, 0, &r->img, &ro, &r->rstats[c], &err);
        if (st != THZ_OK)
            print_message("render: %s\n", err.message);
        assert_int_equal(st, THZ_OK);
        photon_map_destroy(map);
    }
}

/* The same with the paper's photon-map integrator. */
static inline void ident_run_scene(ident_run *r, const char *json, uint64_t photons)
{
    ident_run_scene_with(r, json, photons, INTEGRATOR_PHOTON_MAP, 0);
}

static inline void ident_run_fini(ident_run *r)
{
    sensor_images_fini(&r->img);
    accel_destroy(r->acc);
    scene_destroy(r->scene);
    memset(r, 0, sizeof *r);
}

static inline size_t ident_at(const ident_run *r, size_t channel, uint32_t col, uint32_t row)
{
    return (channel * r->img.rows + row) * r->img.columns + col;
}

/* The hits along a ray, continued through `straight` shells as the renderer does. */
typedef struct ident_chain {
    int n;
    uint32_t object[4];
    vec3 normal[4];
} ident_chain;

static inline void ident_trace_chain(const ident_run *r, vec3 dir, ident_chain *ch)
{
    ch->n = 0;
    vec3 o = r->cam.position_m;
    uint32_t ign_o = ACCEL_NO_OBJECT, ign_t = 0;
    accel_hit h;
    while (ch->n < 4 && accel_intersect(r->acc, o, dir, INFINITY, ign_o, ign_t, &h)) {
        const thz_object *obj = &r->scene->objects[h.object];
        ch->object[ch->n] = h.object;
        ch->normal[ch->n] = v3_from_floats(&obj->mesh.normals[3 * (size_t)h.triangle]);
        ch->n++;
        if (obj->type != OBJECT_SHELL ||
            r->scene->materials[obj->material].transmission != TRANSMISSION_STRAIGHT)
            break;
        o = accel_offset_origin(r->acc, &h, dir);
        ign_o = h.object;
        ign_t = h.triangle;
    }
}

/* True when the rays through the centres of the pixel and its 8 neighbours all hit the
 * same objects (through straight shells) on nearly the same planes (normals within
 * 25 deg): the pixel's gather disks then stay clear of the edges, where the density
 * estimate is biased (physics.md). */
static inline bool ident_pixel_interior(const ident_run *r, uint32_t col, uint32_t row)
{
    const camera *cam = &r->cam;
    ident_chain c0;
    ident_trace_chain(r, camera_pixel_center_dir(cam, col, row), &c0);
    if (c0.n == 0)
        return false;
    for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) {
            double x = -cam->half_width + ((double)col + 0.5 + di) * cam->pixel_pitch;
            double y = cam->half_height - ((double)row + 0.5 + dj) * cam->pixel_pitch;
            ident_chain c;
            ident_trace_chain(r, camera_plane_dir(cam, x, y), &c);
            if (c.n != c0.n)
                return false;
            for (int k = 0; k < c.n; k++)
                if (c.object[k] != c0.object[k] ||
                    v3_dot(c.normal[k], c0.normal[k]) < cos(25.0 * M_PI / 180.0))
                    return false;
        }
    return true;
}

/* Independent band mean over channel ch of f: trapezoid rule on 200001 points over
 * +-8 sigma (not the library's quadrature). */
static inline double ident_band_mean(const thz_channel *ch, double (*f)(double freq_hz, void *ctx),
                                     void *ctx)
{
    double sigma = ch->relative_width * ch->center_hz / (2.0 * sqrt(2.0 * log(2.0)));
    const int n = 200000;
    double lo = ch->center_hz - 8.0 * sigma, h = 16.0 * sigma / n;
    double num = 0.0, den = 0.0;
    for (int i = 0; i <= n; i++) {
        double nu = lo + h * i;
        if (nu <= 0.0)
            continue;
        double x = (nu - ch->center_hz) / sigma;
        double w = exp(-0.5 * x * x) * ((i == 0 || i == n) ? 0.5 : 1.0);
        num += w * f(nu, ctx);
        den += w;
    }
    return num / den;
}

static inline double ident_planck_at(double freq_hz, void *ctx)
{
    return planck_radiance(freq_hz, *(const double *)ctx);
}

/* Band mean of B_nu(T) over ch, W m^-2 sr^-1 Hz^-1. */
static inline double ident_band_planck(const thz_channel *ch, double temp_k)
{
    return ident_band_mean(ch, ident_planck_at, &temp_k);
}

/* Tally of a pixel comparison, for the aggregate check and the failure message. */
typedef struct ident_tally {
    size_t pixels;
    size_t failed;
    size_t unknown;    /* pixels whose standard error is unknown (NaN) */
    double sum_diff;   /* sum of (L - L_exp) / L_exp */
    double sum_var;    /* sum of (stderr / L_exp)^2 */
    double max_rel_se; /* largest stderr / L_exp */
    double worst_z;
    /* when > 0: a pixel's standard error is at least this fraction of the expected value
     * (the pooled error of the image), for heavy-tailed photon terms where a pixel's own
     * error estimate fails when the rare large terms happen to be missing */
    double pooled_rel_se;
    bool exact; /* ident_check_furnace_channel: every pixel exact (a deviation map at T) */
} ident_tally;

/* Compares pixel (col,row) of channel c with expected radiance `expect`; `floor_rel` is
 * the deterministic part of the tolerance (quadrature, float storage). */
static inline void ident_check_pixel(ident_tally *t, const ident_run *r, size_t c, uint32_t col,
                                     uint32_t row, double expect, double floor_rel)
{
    size_t i = ident_at(r, c, col, row);
    double l = r->img.radiance[i], se = r->img.radiance_stderr[i];
    /* an unknown error (NaN: a photon-map sample on an object holding fewer photons than
     * an estimate needs, its reflection taken as 0) widens nothing: such a pixel is right
     * only where that 0 is exact (nothing lights the object), to the deterministic floor */
    if (isnan(se)) {
        se = 0.0;
        t->unknown++;
    } else if (se < t->pooled_rel_se * fabs(expect))
        se = t->pooled_rel_se * fabs(expect);
    double diff = l - expect;
    double tol = IDENT_Z * se + floor_rel * fabs(expect);
    double z = se > 0.0 ? diff / se : (diff == 0.0 ? 0.0 : INFINITY);
    t->pixels++;
    t->sum_diff += diff / expect;
    t->sum_var += (se / expect) * (se / expect);
    if (se / expect > t->max_rel_se)
        t->max_rel_se = se / expect;
    if (fabs(z) > fabs(t->worst_z))
        t->worst_z = z;
    if (!(fabs(diff) <= tol)) {
        if (t->failed < 10)
            print_message("channel %zu pixel (%u, %u): L = %.6e, expected %.6e W m^-2 sr^-1 Hz^-1 "
                          "(%+.2f %%, stderr %.2f %%, z = %.2f)\n",
                          c, col, row, l, expect, 100.0 * diff / expect, 100.0 * se / expect, z);
        t->failed++;
    }
}

/* The tally's verdict: no failed pixel, relative standard errors below max_rel_se (so
 * that the tolerance stays tight), and the mean relative deviation within IDENT_Z
 * standard errors of the mean (x 1.3 for overlapping gather disks) plus floor_rel. */
static inline void ident_tally_assert(const ident_tally *t, const char *what, double max_rel_se,
                                      double floor_rel)
{
    double mean = t->sum_diff / (double)t->pixels;
    double se_mean = 1.3 * sqrt(t->sum_var) / (double)t->pixels;
    print_message("%s: %zu pixels (%zu of unknown error), mean deviation %+.3f %% (se %.3f %%), "
                  "worst z %.2f, largest pixel stderr %.2f %%\n",
                  what, t->pixels, t->unknown, 100.0 * mean, 100.0 * se_mean, t->worst_z,
                  100.0 * t->max_rel_se);
    assert_true(t->pixels > 0);
    assert_int_equal(t->failed, 0);
    assert_true(t->max_rel_se <= max_rel_se);
    assert_true(fabs(mean) <= IDENT_Z * se_mean + floor_rel);
}

/* The furnace check of channel c, whose every pixel should show b (the band mean of
 * B(T) of the enclosure): N = L / b as written; with `path` every pixel exact (N = 1 to
 * 1e-9 and zero error, edges included); otherwise interior pixels within their error
 * (floor 0.3 % for final-gather's secondary-disk edge bias) and edge pixels within 0.35
 * plus their noise (an edge loses at most half the disk, 0.5 R <= 0.3 of N; concave
 * edges gain as much; few photons at THZ_TEST_SCALE = 0.25). Fills t for
 * ident_tally_assert (t->pooled_rel_se may be set beforehand). */
static inline void ident_check_furnace_channel(ident_tally *t, const ident_run *r, size_t c,
                                               thz_integrator integrator, double b)
{
    /* path, final-gather with its deviation map, which is empty at T0, and photon-map
     * with a deviation map: t->exact, set by the caller */
    bool exact = integrator == INTEGRATOR_PATH || t->exact;
    size_t loose_fail = 0;
    for (uint32_t row = 0; row < r->img.rows; row++)
        for (uint32_t col = 0; col < r->img.columns; col++) {
            size_t i = ident_at(r, c, col, row);
            double n = r->img.normalized[i];
            assert_true(fabs(n - r->img.radiance[i] / b) <= 1e-5 * n);
            if (exact) {
                if (!(fabs(n - 1.0) <= 1e-9))
                    print_message("path: pixel (%u, %u): N - 1 = %.3e\n", col, row, n - 1.0);
                assert_true(fabs(n - 1.0) <= 1e-9);
                assert_true(r->img.radiance_stderr[i] <= 1e-12 * r->img.radiance[i]);
                t->pixels++;
            } else if (ident_pixel_interior(r, col, row)) {
                ident_check_pixel(t, r, c, col, row, b,
                                  integrator == INTEGRATOR_FINAL_GATHER ? 3e-3 : 1e-5);
            } else if (fabs(n - 1.0) >
                       0.35 + IDENT_Z * r->img.radiance_stderr[i] / r->img.radiance[i]) {
                print_message("edge pixel (%u, %u): N = %.4f\n", col, row, n);
                loose_fail++;
            }
        }
    assert_int_equal(loose_fail, 0);
}

#endif
