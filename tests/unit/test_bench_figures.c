/* The benchmark's figures (bench/, compiled into this test beside the library): each
 * computed as docs/benchmark.md "What it measures" says, from numbers chosen here so
 * that the slips a figure could take (a ratio of medians for a median of ratios, the
 * fastest for the median, the smaller run for the larger, a credit below the target, a
 * wrong unit) give different numbers. test_bench_small.sh runs the harness itself; this
 * checks the rules case by case, nothing timed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bench_pairs.h"
#include "bench_render.h"
#include "bench_report.h"
#include "scene/scene.h"
#include "sensor/render.h"
#include "thzmap/thzmap.h"

static double num(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    assert_true(json_is_number(v));
    return json_number_value(v);
}

static void assert_near(double got, double want)
{
    if (!(fabs(got - want) <= 1e-12 * fabs(want) + 1e-15))
        fail_msg("%.17g, expected %.17g", got, want);
}

/* Three pairs whose median ratio (1.5), ratio of medians (1.5 / 0.8) and fastest over
 * fastest (1.0 / 0.5) all differ; in the order (4, 1.25, 1.5) so that the median is not
 * the first, the last or the middle one as added. */
static void three_pairs(bench_pairs *p)
{
    memset(p, 0, sizeof *p);
    bench_pairs_add(p, 2.0, 0.5, 2.1, 1.1);  /* 4 */
    bench_pairs_add(p, 1.0, 0.8, 1.1, 1.7);  /* 1.25 */
    bench_pairs_add(p, 1.5, 1.0, 1.6, 2.05); /* 1.5: the median */
}

static void test_median(void **state)
{
    (void)state;
    const double odd[] = {3.0, 1.0, 7.0, 2.0, 5.0};
    assert_near(bench_median(odd, 5), 3.0);
    const double even[] = {4.0, 1.0, 3.0, 10.0};
    assert_near(bench_median(even, 4), 3.5); /* the middle two's mean */
    const double one[] = {2.5};
    assert_near(bench_median(one, 1), 2.5);
    assert_near(bench_median(odd, 0), 0.0);
}

static void test_speedup_is_the_median_of_the_pairs_ratios(void **state)
{
    (void)state;
    bench_pairs p;
    three_pairs(&p);
    assert_near(bench_pairs_speedup(&p), 1.5);
    assert_near(bench_pairs_speedup_fastest(&p), 2.0);
    double lo, hi;
    bench_pairs_range(&p, &lo, &hi);
    assert_near(lo, 1.25);
    assert_near(hi, 4.0);
    double s1, sa, c1, ca;
    bench_pairs_median_pair(&p, &s1, &sa, &c1, &ca);
    assert_near(s1, 1.5);
    assert_near(sa, 1.0);
    assert_near(c1, 1.6);
    assert_near(ca, 2.05);
    /* an even count: the middle two ratios' mean, the lower middle pair's seconds */
    bench_pairs_add(&p, 3.0, 1.0, 3.0, 2.0); /* 3 */
    assert_near(bench_pairs_speedup(&p), 0.5 * (1.5 + 3.0));
    bench_pairs_median_pair(&p, &s1, &sa, &c1, &ca);
    assert_near(s1, 1.5);
    assert_near(sa, 1.0);
    /* none */
    bench_pairs empty;
    memset(&empty, 0, sizeof empty);
    assert_near(bench_pairs_speedup(&empty), 0.0);
    assert_near(bench_pairs_speedup_fastest(&empty), 0.0);
}

static void test_pairs_beyond_the_limit_are_ignored(void **state)
{
    (void)state;
    bench_pairs p;
    memset(&p, 0, sizeof p);
    for (int i = 0; i < BENCH_MAX_PAIRS; i++)
        bench_pairs_add(&p, 2.0, 1.0, 2.0, 2.0);
    bench_pairs_add(&p, 100.0, 1.0, 1.0, 1.0);
    assert_int_equal(p.n, BENCH_MAX_PAIRS);
    double lo, hi;
    bench_pairs_range(&p, &lo, &hi);
    assert_near(hi, 2.0);
}

/* The phase over the probe: round by round, a's all-thread seconds over b's (not the
 * 1-thread side, not the ratio of their medians), over the rounds both have. */
static void test_across_rounds(void **state)
{
    (void)state;
    bench_pairs a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    bench_pairs_add(&a, 9.0, 3.0, 0, 0);
    bench_pairs_add(&a, 9.0, 2.0, 0, 0);
    bench_pairs_add(&a, 9.0, 6.0, 0, 0);
    bench_pairs_add(&a, 9.0, 100.0, 0, 0); /* no round of b beside it */
    bench_pairs_add(&b, 1.0, 1.0, 0, 0);   /* 3 */
    bench_pairs_add(&b, 1.0, 2.0, 0, 0);   /* 1 */
    bench_pairs_add(&b, 1.0, 3.0, 0, 0);   /* 2 */
    double lo, hi;
    assert_near(bench_pairs_across(&a, &b, &lo, &hi), 2.0);
    assert_near(lo, 1.0);
    assert_near(hi, 3.0);
}

/* Two runs of two channels; channel 1 the one asked about, its figures unlike
 * channel 0's and the smaller run's. */
static void converge_case(bench_converge *cv)
{
    memset(cv, 0, sizeof *cv);
    cv->channels = 2;
    cv->pt[0] = (bench_converge_point){
        .estimates = 16, .rms_k = {0.3, 0.2}, .s_photons = {0.7, 0.6}, .s_render = {0.9, 1.0}};
    cv->pt[1] = (bench_converge_point){
        .estimates = 64, .rms_k = {0.25, 0.1}, .s_photons = {0.5, 1.0}, .s_render = {3.0, 4.0}};
}

static void test_seconds_to_target_extrapolated(void **state)
{
    (void)state;
    bench_converge cv;
    converge_case(&cv);
    /* the 4 J run: photon phase + render x (0.1 / 0.05)^2 */
    assert_near(bench_converge_seconds(&cv, 1, 0.05), 1.0 + 4.0 * 4.0);
    /* a run already below the target: scaled down too (an extrapolation both ways) */
    assert_near(bench_converge_seconds(&cv, 1, 0.2), 1.0 + 4.0 * 0.25);
    /* rms 0.2 -> 0.1 as render time 1 -> 4: the 1/sqrt law's -0.5 */
    assert_near(bench_converge_exponent(&cv, 1), -0.5);
    cv.pt[1].s_render[1] = cv.pt[0].s_render[1]; /* no longer render: no exponent */
    assert_near(bench_converge_exponent(&cv, 1), 0.0);
}

static void test_seconds_at_target_no_credit_below_it(void **state)
{
    (void)state;
    bench_converge cv;
    converge_case(&cv);
    assert_true(isnan(bench_converge_confirmed_seconds(&cv, 1, 0.05))); /* not run */
    cv.confirm_estimates[1] = 256;
    cv.confirm.s_photons[1] = 1.25;
    cv.confirm.s_render[1] = 8.0;
    cv.confirm.rms_k[1] = 0.04; /* below 0.05: its own time, not 8 x 0.64 */
    assert_near(bench_converge_confirmed_seconds(&cv, 1, 0.05), 1.25 + 8.0);
    cv.confirm.rms_k[1] = 0.06; /* above: scaled up */
    assert_near(bench_converge_confirmed_seconds(&cv, 1, 0.05), 1.25 + 8.0 * 1.44);
}

/* RMS^2 = a / J + floor^2 through J = 64 and 256: a = 1.92 K^2, floor 0.03 K; 0.05 K then
 * needs a / (0.0025 - 0.0009) = 1200 estimates; a floor above the target, none. */
static void test_floor_fit(void **state)
{
    (void)state;
    bench_converge cv;
    converge_case(&cv);
    double a, f2, need;
    assert_false(bench_converge_floor(&cv, 1, 0.05, &a, &f2, &need)); /* no run at target */
    const double a_true = 1.92, f2_true = 0.0009;
    cv.pt[1].rms_k[1] = sqrt(a_true / 64 + f2_true);
    cv.confirm_estimates[1] = 256;
    cv.confirm.rms_k[1] = sqrt(a_true / 256 + f2_true);
    assert_true(bench_converge_floor(&cv, 1, 0.05, &a, &f2, &need));
    assert_true(fabs(a - a_true) < 1e-9);
    assert_true(fabs(f2 - f2_true) < 1e-12);
    assert_true(need >= 1200 && need <= 1201); /* ceil of 1200 up to rounding */
    assert_false(bench_converge_floor(&cv, 1, 0.02, &a, &f2, &need) && need != 0.0);
    cv.confirm_estimates[1] = 64; /* not more estimates than the larger run: no fit */
    assert_false(bench_converge_floor(&cv, 1, 0.05, &a, &f2, &need));
}

/* The section's JSON: every channel's extrapolation and ratio to the limit, and the worst
 * the largest of the runs at the target (not of the extrapolations, not the smallest). */
static void test_report_converge(void **state)
{
    (void)state;
    bench_converge cv;
    converge_case(&cv);
    snprintf(cv.enclosure, sizeof cv.enclosure, "box");
    double worst = 0.0;
    json_t *o = bench_report_converge("path", &cv, 0.05, 2.0, 0.0, &worst);
    json_t *ch = json_object_get(o, "channels");
    assert_int_equal(json_array_size(ch), 2);
    assert_near(num(json_array_get(ch, 0), "seconds_to_target"), 0.5 + 3.0 * 25.0);
    assert_near(num(json_array_get(ch, 1), "seconds_to_target"), 1.0 + 4.0 * 4.0);
    assert_near(num(json_array_get(ch, 1), "ratio_to_limit"), 17.0 / 2.0);
    assert_near(worst, 75.5);
    assert_near(num(o, "worst_seconds_to_target"), 75.5);
    assert_near(num(o, "worst_ratio_to_limit"), 75.5 / 2.0);
    json_decref(o);

    cv.confirmed = true;
    cv.confirm_estimates[0] = 1600;
    cv.confirm_estimates[1] = 256;
    cv.confirm.rms_k[0] = 0.05;
    cv.confirm.rms_k[1] = 0.06;
    cv.confirm.s_photons[0] = 0.5;
    cv.confirm.s_photons[1] = 1.0;
    cv.confirm.s_render[0] = 2.0;
    cv.confirm.s_render[1] = 3.0;
    o = bench_report_converge("path", &cv, 0.05, 2.0, 0.0, &worst);
    json_t *runs = json_object_get(o, "runs_at_target");
    assert_int_equal(json_array_size(runs), 2);
    assert_near(num(json_array_get(runs, 0), "seconds_to_target"), 2.5);
    assert_near(num(json_array_get(runs, 1), "seconds_to_target"), 1.0 + 3.0 * 1.44);
    assert_near(worst, 1.0 + 3.0 * 1.44);
    assert_near(num(o, "worst_seconds_to_target"), worst);
    json_decref(o);
}

/* A verdict from the value, the comparison and the limit printed (a value at its limit
 * meets it); "not shown" over either when not shown. */
static void test_target_verdicts(void **state)
{
    (void)state;
    bench_targets t = {.list = json_array()};
    bench_target(&t, "a", 9.0, "<=", 10, "s", true);
    bench_target(&t, "b", 11.0, "<=", 10, "s", true);
    bench_target(&t, "c", 2.0, ">=", 1.85, "x", false);
    bench_target(&t, "d", 1.0, ">=", 1.85, "x", false);
    bench_target(&t, "e", 10.0, "<=", 10, "s", true);
    bench_target(&t, "f", 1.85, ">=", 1.85, "x", true);
    bench_target(&t, "g", 1.84, ">=", 1.85, "x", true);
    bench_target(&t, "h", 2.5, ">=", 1.85, "x", true);
    assert_int_equal(t.total, 8);
    assert_int_equal(t.met, 4);
    const char *want[] = {"met", "not met", "not shown", "not shown",
                          "met", "met",     "not met",   "met"};
    for (size_t i = 0; i < 8; i++) {
        json_t *o = json_array_get(t.list, i);
        assert_string_equal(json_string_value(json_object_get(o, "verdict")), want[i]);
        assert_true(json_is_true(json_object_get(o, "met")) == (strcmp(want[i], "met") == 0));
    }
    json_t *b = json_array_get(t.list, 1);
    assert_near(num(b, "value"), 11.0);
    assert_near(num(b, "limit"), 10.0);
    assert_string_equal(json_string_value(json_object_get(b, "comparison")), "<=");
    assert_string_equal(json_string_value(json_object_get(b, "unit")), "s");
    json_decref(t.list);
}

/* Bytes per stored photon: the map's bytes and its directory's over its records; the peak
 * memory over the map without the directory. */
static void test_report_paper_memory(void **state)
{
    (void)state;
    bench_paper paper;
    memset(&paper, 0, sizeof paper);
    paper.largest_map_bytes = 28000000;
    paper.largest_map_directory_bytes = 4000000;
    paper.largest_map_stored = 1000000;
    paper.fired = 2000000;
    paper.s_photons = 4.0;
    paper.s_total = 5.0;
    bench_usage use = {.peak_bytes = 42000000, .cpu_s = 9.0};
    double bpp = 0.0;
    json_t *o = bench_report_paper(&paper, &use, 0.0, &bpp);
    assert_near(bpp, 32.0);
    assert_near(num(o, "bytes_per_stored_photon"), 32.0);
    assert_near(num(o, "peak_memory_over_map"), 1.5);
    assert_near(num(o, "photons_per_s"), 500000.0);
    json_decref(o);
}

/* The scaling tables' units: ns per photon, us per pixel, gathers per second. */
static void test_report_series_units(void **state)
{
    (void)state;
    bench_series sp;
    memset(&sp, 0, sizeof sp);
    sp.n = 2;
    sp.p[0] = (bench_point){.photons = 1000000,
                            .stored = 8192,
                            .pixels = 4096,
                            .samples = 8192,
                            .s_photons = 0.5,
                            .s_render = 0.4096,
                            .cpu_photons = 0.75,
                            .cpu_photons_fastest = 0.7,
                            .runs = 3};
    sp.p[1] = sp.p[0];
    sp.p[1].photons = 3000000;
    json_t *ph = bench_report_photons(&sp, 2, 0.0);
    assert_near(num(json_array_get(ph, 0), "ns_per_photon"), 500.0);
    assert_near(num(json_array_get(ph, 1), "ns_per_photon"), 500.0 / 3.0);
    assert_near(num(json_array_get(ph, 0), "cpu_ns_per_photon"), 750.0);
    assert_near(num(json_array_get(ph, 0), "cpu_ns_per_photon_fastest"), 700.0);
    json_decref(ph);
    json_t *r = bench_report_rendering(&sp, 2);
    json_t *r0 = json_array_get(r, 0);
    assert_near(num(r0, "us_per_pixel"), 100.0);
    assert_near(num(r0, "gathers_per_s"), 20000.0);
    assert_near(num(r0, "photons_per_pixel"), 2.0);
    json_decref(r);
}

/* The noise figure of a run (bench_measure_converge, as thzbench --small runs it: path,
 * 16 columns, one sample per pixel, J = 2 and 4 paths): per channel the RMS, not the mean,
 * over the pixels whose truth object is neither nothing nor teraeye's enclosure "box", of
 * the standard error of that channel's Tb; here from the same run through the public API. */
static void test_objects_rms(void **state)
{
    (void)state;
    const char *path = THZ_SOURCE_DIR "/examples/teraeye/scene.json";
    const uint32_t est[2] = {2, 4};
    bench_converge cv;
    thz_error err;
    memset(&err, 0, sizeof err);
    if (bench_measure_converge(path, "path", 0, est, 16, 2, 0.05, 0, &cv, &err) != THZ_OK)
        fail_msg("%s", err.message);
    assert_string_equal(cv.enclosure, "box");

    thz_scene *s = NULL;
    assert_int_equal(thz_scene_load(path, &s, &err), THZ_OK);
    long box = -1;
    for (size_t i = 0; i < thz_scene_object_count(s); i++) {
        thz_object_info oi;
        thz_scene_object(s, i, &oi);
        box = strcmp(oi.name, "box") == 0 ? (long)i : box;
    }
    assert_true(box >= 0);
    for (size_t i = 0; i < s->n_sensors; i++) { /* as --small shrinks them */
        s->sensors[i].rows = (uint32_t)((uint64_t)s->sensors[i].rows * 16 / s->sensors[i].columns);
        s->sensors[i].columns = 16;
        s->sensors[i].oversampling = 1;
    }
    assert_true(render_integrator_parse("path", &s->render.integrator));
    s->render.target_noise_k = 0.0;
    s->render.max_seconds = 0.0;
    s->render.paths_per_sample_given = true;
    thz_context *ctx = thz_context_create();
    assert_non_null(ctx);
    size_t nc = thz_scene_channel_count(s);
    assert_int_equal(nc, cv.channels);
    for (int k = 0; k < 2; k++) {
        s->render.paths_per_sample = est[k];
        thz_run_settings settings;
        thz_run_settings_init(&settings);
        settings.integrator = "path";
        thz_run *run = NULL;
        assert_int_equal(thz_simulate(ctx, s, &settings, &run, &err), THZ_OK);
        double sum[BENCH_MAX_CHANNELS] = {0};
        uint64_t objects = 0, pixels = 0, on_box = 0;
        for (size_t i = 0; i < thz_run_image_count(run); i++) {
            const thz_image *im = thz_run_image(run, i);
            size_t np = (size_t)thz_image_columns(im) * thz_image_rows(im);
            const float *tb = thz_image_plane(im, THZ_PLANE_BRIGHTNESS_TEMPERATURE, NULL);
            const float *se = thz_image_plane(im, THZ_PLANE_RADIANCE_STDERR, NULL);
            const float *id = thz_image_plane(im, THZ_PLANE_OBJECT_ID, NULL);
            assert_true(tb && se && id);
            pixels += np;
            for (size_t p = 0; p < np; p++) {
                on_box += (long)id[p] == box;
                if (id[p] < 0.0f || (long)id[p] == box)
                    continue;
                objects++;
                for (size_t c = 0; c < nc; c++) {
                    thz_channel_info ci;
                    thz_scene_channel(s, c, &ci);
                    double e = thz_brightness_temperature_stderr(
                        ci.frequency_hz, (double)tb[c * np + p], (double)se[c * np + p]);
                    sum[c] += e * e;
                }
            }
        }
        assert_true(on_box > 0 && objects > 0); /* both kinds of pixel in view */
        assert_int_equal(cv.pixels, pixels);
        assert_int_equal(cv.object_pixels, objects);
        assert_int_equal(cv.pt[k].estimates, est[k]);
        for (size_t c = 0; c < nc; c++) {
            double want = sqrt(sum[c] / (double)objects);
            if (!(fabs(cv.pt[k].rms_k[c] - want) <= 1e-9 * want))
                fail_msg("run %d channel %zu: RMS %.9g K, the objects' pixels give %.9g K", k, c,
                         cv.pt[k].rms_k[c], want);
        }
        thz_run_destroy(run);
    }
    thz_context_destroy(ctx);
    thz_scene_destroy(s);
}

/* Every channel's run at the target (bench_measure_converge with max_confirm): J* =
 * 4 J (RMS / target)^2 from the larger run, rounded up, at least 2 and at most the cap; a
 * second run only where the first missed the target and the fit asks for more, within the
 * cap. Targets chosen so that J* lands between 2 and the cap (0.3 K) and below 2 (0.9 K)
 * for --small's RMS of 0.37-0.51 K at J = 4. */
static void test_runs_at_target(void **state)
{
    (void)state;
    const char *path = THZ_SOURCE_DIR "/examples/teraeye/scene.json";
    const uint32_t est[2] = {2, 4}, cap = 24;
    const double targets[2] = {0.3, 0.9};
    int inside = 0, clamped = 0;
    for (int t = 0; t < 2; t++) {
        bench_converge cv;
        thz_error err;
        memset(&err, 0, sizeof err);
        if (bench_measure_converge(path, "path", 0, est, 16, 2, targets[t], cap, &cv, &err) !=
            THZ_OK)
            fail_msg("%s", err.message);
        assert_true(cv.confirmed);
        for (size_t c = 0; c < cv.channels; c++) {
            double x = cv.pt[1].rms_k[c] / targets[t];
            double need = ceil((double)cv.pt[1].estimates * x * x);
            uint32_t want = need < 2.0 ? 2 : need > (double)cap ? cap : (uint32_t)need;
            inside += need >= 3.0 && need < (double)cap;
            clamped += need < 2.0;
            uint32_t first = cv.refined[c] ? cv.first_estimates[c] : cv.confirm_estimates[c];
            if (first != want)
                fail_msg("%g K, channel %zu: J* %u, expected %u (RMS %g K at J = %u)", targets[t],
                         c, first, want, cv.pt[1].rms_k[c], cv.pt[1].estimates);
            if (cv.refined[c]) {
                assert_true(cv.first_rms_k[c] > targets[t]);
                assert_true(cv.confirm_estimates[c] > first && cv.confirm_estimates[c] <= cap);
            } else if (cv.confirm.rms_k[c] > targets[t]) {
                double a, f2, fit;
                assert_true(bench_converge_floor(&cv, c, targets[t], &a, &f2, &fit));
                assert_true(fit <= (double)first || fit > (double)cap);
            }
        }
    }
    assert_true(inside > 0 && clamped > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_median),
        cmocka_unit_test(test_speedup_is_the_median_of_the_pairs_ratios),
        cmocka_unit_test(test_pairs_beyond_the_limit_are_ignored),
        cmocka_unit_test(test_across_rounds),
        cmocka_unit_test(test_seconds_to_target_extrapolated),
        cmocka_unit_test(test_seconds_at_target_no_credit_below_it),
        cmocka_unit_test(test_floor_fit),
        cmocka_unit_test(test_report_converge),
        cmocka_unit_test(test_target_verdicts),
        cmocka_unit_test(test_report_paper_memory),
        cmocka_unit_test(test_report_series_units),
        cmocka_unit_test(test_objects_rms),
        cmocka_unit_test(test_runs_at_target),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
