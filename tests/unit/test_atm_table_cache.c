/* The band tables atmosphere_prepare keeps for later atmospheres with the same inputs
 * (src/atmosphere/atm_table_cache.c): a second atmosphere of the same model, air, files and
 * bands gets tables equal to the bit to those tabulated with the cache emptied, and hits;
 * one differing only in humidity, temperature, pressure, a band, the continuum switch or
 * the catalogue read misses and gets other tables; the cache stays within its entry and
 * byte bounds; threads preparing at once get the same tables. */
#define _GNU_SOURCE /* utimensat's AT_FDCWD */
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atm_lines_helpers.h"
#include "atmosphere/atm_table_cache.h"

static const thz_channel channels[] = {
    {.name = "350", .center_hz = 0.35e12, .relative_width = 0.01},
    {.name = "660", .center_hz = 0.66e12, .relative_width = 0.01}};
#define N_CH 2

static void prepare(thz_atmosphere *atm, const thz_channel *ch, size_t n)
{
    thz_error err = {0};
    if (atmosphere_prepare(atm, ch, n, &err) != THZ_OK)
        fail_msg("%s", err.message);
    assert_int_equal(atm->n_tables, n);
}

static bool tables_equal(const atm_band_table *a, const atm_band_table *b)
{
    return a->n == b->n && a->lo_hz == b->lo_hz && a->step_hz == b->step_hz &&
           memcmp(a->alpha_per_m, b->alpha_per_m, a->n * sizeof *a->alpha_per_m) == 0;
}

static void assert_same_tables(const thz_atmosphere *a, const thz_atmosphere *b)
{
    assert_int_equal(a->n_tables, b->n_tables);
    for (size_t i = 0; i < a->n_tables; i++)
        assert_true(tables_equal(&a->tables[i], &b->tables[i]));
}

/* No table of a equals b's (a cache hit would have copied it). */
static void assert_other_tables(const thz_atmosphere *a, const thz_atmosphere *b)
{
    assert_int_equal(a->n_tables, b->n_tables);
    for (size_t i = 0; i < a->n_tables; i++)
        assert_false(tables_equal(&a->tables[i], &b->tables[i]));
}

static atm_air_state air_of(double t_k, double p_hpa, double rh)
{
    atm_air_state air;
    thz_error err = {0};
    assert_int_equal(atm_air_state_init(&air, t_k, p_hpa, ATM_HUMIDITY_RELATIVE, rh, &err), THZ_OK);
    return air;
}

/* lines atmosphere of air, options o (NULL: defaults), prepared over the channels */
static void lines_prepared(thz_atmosphere *atm, const atm_air_state *air,
                           const atm_lines_options *o)
{
    init_lines(atm, air, o);
    prepare(atm, channels, N_CH);
}

static void test_same_inputs_hit_and_equal_uncached(void **state)
{
    (void)state;
    atm_table_cache_clear();
    atm_air_state air = air_of(293.15, 1013.25, 0.5);
    thz_atmosphere first, second, fresh;
    lines_prepared(&first, &air, NULL);
    size_t hits = atm_table_cache_hits();
    lines_prepared(&second, &air, NULL);
    assert_int_equal(atm_table_cache_hits(), hits + N_CH);
    assert_true(second.tables[0].alpha_per_m != first.tables[0].alpha_per_m); /* a copy */
    atm_table_cache_clear();
    lines_prepared(&fresh, &air, NULL);
    assert_int_equal(atm_table_cache_hits(), hits + N_CH); /* tabulated again */
    assert_same_tables(&second, &fresh);
    assert_same_tables(&first, &fresh);
    atmosphere_fini(&first);
    atmosphere_fini(&second);
    atmosphere_fini(&fresh);
}

/* Each air differs from the base in one quantity: a miss, and other tables. */
static void test_other_air_misses(void **state)
{
    (void)state;
    atm_table_cache_clear();
    atm_air_state base = air_of(293.15, 1013.25, 0.5);
    atm_air_state other[] = {air_of(293.15, 1013.25, 0.55), air_of(294.15, 1013.25, 0.5),
                             air_of(293.15, 1000.0, 0.5)};
    /* the humidity's alone: same temperature and total pressure */
    assert_true(other[0].temperature_k == base.temperature_k &&
                other[0].pressure_hpa == base.pressure_hpa);
    thz_atmosphere b;
    lines_prepared(&b, &base, NULL);
    for (size_t i = 0; i < sizeof other / sizeof other[0]; i++) {
        size_t hits = atm_table_cache_hits();
        thz_atmosphere o;
        lines_prepared(&o, &other[i], NULL);
        assert_int_equal(atm_table_cache_hits(), hits);
        assert_other_tables(&o, &b);
        atmosphere_fini(&o);
    }
    /* itu-p676 at the same air does not take the lines' tables, and its own humidity
     * counts too */
    size_t hits = atm_table_cache_hits();
    thz_atmosphere itu, itu_wet, itu_again;
    thz_error err = {0};
    memset(&itu, 0, sizeof itu);
    memset(&itu_wet, 0, sizeof itu_wet);
    memset(&itu_again, 0, sizeof itu_again);
    assert_int_equal(atmosphere_init_itu_p676(&itu, &base, NULL, &err), THZ_OK);
    assert_int_equal(atmosphere_init_itu_p676(&itu_wet, &other[0], NULL, &err), THZ_OK);
    assert_int_equal(atmosphere_init_itu_p676(&itu_again, &base, NULL, &err), THZ_OK);
    prepare(&itu, channels, N_CH);
    assert_int_equal(atm_table_cache_hits(), hits);
    assert_other_tables(&itu, &b);
    prepare(&itu_wet, channels, N_CH);
    assert_int_equal(atm_table_cache_hits(), hits);
    assert_other_tables(&itu_wet, &itu);
    prepare(&itu_again, channels, N_CH);
    assert_int_equal(atm_table_cache_hits(), hits + N_CH);
    assert_same_tables(&itu_again, &itu);
    atmosphere_fini(&itu);
    atmosphere_fini(&itu_wet);
    atmosphere_fini(&itu_again);
    atmosphere_fini(&b);
}

/* A band moved by 1 GHz, and the continuum off, miss; a channel set that repeats one band
 * hits for that band only. */
static void test_other_band_or_switch_misses(void **state)
{
    (void)state;
    atm_table_cache_clear();
    atm_air_state air = air_of(293.15, 1013.25, 0.5);
    thz_atmosphere b, moved, dry_shape;
    lines_prepared(&b, &air, NULL);
    thz_channel ch[] = {channels[0], channels[1]};
    ch[1].center_hz += 1e9;
    size_t hits = atm_table_cache_hits();
    init_lines(&moved, &air, NULL);
    prepare(&moved, ch, N_CH);
    assert_int_equal(atm_table_cache_hits(), hits + 1);
    assert_true(tables_equal(&moved.tables[0], &b.tables[0]));
    assert_false(tables_equal(&moved.tables[1], &b.tables[1]));
    atm_lines_options o;
    atmosphere_lines_options_default(&o);
    o.continuum = false;
    hits = atm_table_cache_hits();
    lines_prepared(&dry_shape, &air, &o);
    assert_int_equal(atm_table_cache_hits(), hits);
    assert_other_tables(&dry_shape, &b);
    atmosphere_fini(&b);
    atmosphere_fini(&moved);
    atmosphere_fini(&dry_shape);
}

/* A catalogue read again (its modification time changed) is another read: a miss, though
 * its content, and so the tables, are the same. */
static void test_catalogue_read_again_misses(void **state)
{
    (void)state;
    atm_table_cache_clear();
    char dir[] = "/tmp/thz-atm-table-cache-XXXXXX", path[96], line[512];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/h2o.csv", dir);
    FILE *in = fopen(THZ_SOURCE_DIR "/tests/inputs/atm_h2o_subset.csv", "r");
    FILE *out = fopen(path, "w");
    assert_true(in && out);
    while (fgets(line, sizeof line, in))
        fputs(line, out);
    assert_int_equal(fclose(in), 0);
    assert_int_equal(fclose(out), 0);
    atm_lines_options o;
    atmosphere_lines_options_default(&o);
    o.h2o_lines_file = path;
    atm_air_state air = air_of(293.15, 1013.25, 0.5);
    thz_atmosphere a, again, touched;
    lines_prepared(&a, &air, &o);
    size_t hits = atm_table_cache_hits();
    lines_prepared(&again, &air, &o);
    assert_int_equal(atm_table_cache_hits(), hits + N_CH);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    struct timespec t[2] = {st.st_atim, st.st_mtim};
    t[1].tv_sec += 1;
    assert_int_equal(utimensat(AT_FDCWD, path, t, 0), 0);
    lines_prepared(&touched, &air, &o);
    assert_int_equal(atm_table_cache_hits(), hits + N_CH);
    assert_same_tables(&touched, &a);
    atmosphere_fini(&a);
    atmosphere_fini(&again);
    atmosphere_fini(&touched);
    assert_int_equal(unlink(path), 0);
    assert_int_equal(rmdir(dir), 0);
}

static void key_of(atm_table_key *k, int i)
{
    *k = (atm_table_key){0};
    atm_table_key_add(k, &i, sizeof i);
}

static void test_bounds(void **state)
{
    (void)state;
    atm_table_cache_clear();
    double alpha[4] = {1, 2, 3, 4};
    atm_band_table t = {.lo_hz = 1e11, .step_hz = 1e8, .n = 4, .alpha_per_m = alpha}, got;
    atm_table_key k;
    /* one more than the entries: the first put is dropped, the rest kept */
    for (int i = 0; i <= ATM_TABLE_CACHE_ENTRIES; i++) {
        key_of(&k, i);
        atm_table_cache_put(&k, &t);
        atm_table_key_fini(&k);
    }
    key_of(&k, 0);
    assert_false(atm_table_cache_get(&k, &got));
    atm_table_key_fini(&k);
    for (int i = 1; i <= ATM_TABLE_CACHE_ENTRIES; i++) {
        key_of(&k, i);
        assert_true(atm_table_cache_get(&k, &got));
        assert_true(tables_equal(&got, &t));
        free(got.alpha_per_m);
        atm_table_key_fini(&k);
    }
    /* bytes: a table larger than the budget is not kept; two of 5/8 of it do not fit
     * together, and the older goes */
    size_t big_n = ATM_TABLE_CACHE_BYTES / sizeof(double) + 1, part_n = big_n / 8 * 5;
    double *big = calloc(big_n, sizeof *big);
    assert_non_null(big);
    atm_band_table tb = {.lo_hz = 1e11, .step_hz = 1.0, .n = big_n, .alpha_per_m = big};
    key_of(&k, -1);
    atm_table_cache_put(&k, &tb);
    assert_false(atm_table_cache_get(&k, &got));
    atm_table_key_fini(&k);
    tb.n = part_n;
    for (int i = -2; i >= -3; i--) {
        key_of(&k, i);
        atm_table_cache_put(&k, &tb);
        atm_table_key_fini(&k);
    }
    key_of(&k, -2);
    assert_false(atm_table_cache_get(&k, &got));
    atm_table_key_fini(&k);
    key_of(&k, -3);
    assert_true(atm_table_cache_get(&k, &got));
    assert_int_equal(got.n, part_n);
    free(got.alpha_per_m);
    atm_table_key_fini(&k);
    free(big);
    /* a key that differs in its last byte only, and a longer one, are other keys */
    atm_table_cache_clear();
    key_of(&k, 7);
    atm_table_cache_put(&k, &t);
    atm_table_key_add(&k, "", 1);
    assert_false(atm_table_cache_get(&k, &got));
    atm_table_key_fini(&k);
    key_of(&k, 7 + (1 << 24));
    assert_false(atm_table_cache_get(&k, &got));
    atm_table_key_fini(&k);
    atm_table_cache_clear();
}

/* Threads preparing the same itu-p676 atmosphere at once, the cache cleared between
 * rounds so that they race to tabulate and store. */
typedef struct worker {
    const thz_atmosphere *ref;
    bool same;
} worker;

static void *prepare_worker(void *arg)
{
    worker *w = arg;
    w->same = true;
    for (int round = 0; round < 20; round++) {
        thz_atmosphere atm = {0};
        thz_error err = {0};
        if (atmosphere_init_itu_p676(&atm, &w->ref->air, NULL, &err) != THZ_OK ||
            atmosphere_prepare(&atm, channels, N_CH, &err) != THZ_OK) {
            w->same = false;
            return NULL;
        }
        for (size_t i = 0; i < N_CH; i++)
            w->same = w->same && tables_equal(&atm.tables[i], &w->ref->tables[i]);
        atmosphere_fini(&atm);
        if (round % 5 == 4)
            atm_table_cache_clear();
    }
    return NULL;
}

static void test_threads(void **state)
{
    (void)state;
    atm_table_cache_clear();
    atm_air_state air = air_of(280.0, 900.0, 0.8);
    thz_atmosphere ref = {0};
    thz_error err = {0};
    assert_int_equal(atmosphere_init_itu_p676(&ref, &air, NULL, &err), THZ_OK);
    prepare(&ref, channels, N_CH);
    atm_table_cache_clear();
    enum { THREADS = 4 };
    pthread_t th[THREADS];
    worker w[THREADS];
    for (int i = 0; i < THREADS; i++) {
        w[i].ref = &ref;
        assert_int_equal(pthread_create(&th[i], NULL, prepare_worker, &w[i]), 0);
    }
    for (int i = 0; i < THREADS; i++) {
        assert_int_equal(pthread_join(th[i], NULL), 0);
        assert_true(w[i].same);
    }
    atmosphere_fini(&ref);
    atm_table_cache_clear();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_inputs_hit_and_equal_uncached),
        cmocka_unit_test(test_other_air_misses),
        cmocka_unit_test(test_other_band_or_switch_misses),
        cmocka_unit_test(test_catalogue_read_again_misses),
        cmocka_unit_test(test_bounds),
        cmocka_unit_test(test_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
