/* The `lines` model's input files, read once per process (src/atmosphere/atm_inputs.c):
 * a second acquire of the same files shares the first's read; a file whose modification
 * time or size changed is read again; the least recently used of more than
 * ATM_INPUTS_CACHED sets is read again; a set held by a caller is never dropped. What a
 * read gave is seen through the H2O catalogue's one line, whose intensity the test
 * rewrites in place (same size): with the modification time put back, only a cached read
 * still shows the old value. The other files are the repository's. */
#define _GNU_SOURCE /* utimensat's AT_FDCWD */
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "atmosphere/atm_inputs.h"

#define DATA THZ_SOURCE_DIR "/data/atmosphere/"

typedef struct set {
    char dir[64], h2o[96];
    const char *paths[ATM_IN_FILES];
} set;

/* Writes set s's H2O catalogue: one line at 22.235 GHz of intensity `digit`e-23. */
static void write_h2o(const set *s, int digit)
{
    FILE *f = fopen(s->h2o, "w");
    assert_non_null(f);
    fprintf(f,
            "freq_GHz,S296_cm2_GHz,Elower_K,gamma_air_GHz_per_mbar,gamma_self_GHz_per_mbar,"
            "n_air,delta_air_GHz_per_mbar,hitran_iso\n"
            "22.235067,%d.303498e-23,642.425753,2.7131e-03,1.1391e-02,0.65,-2.3670e-05,1\n",
            digit);
    assert_int_equal(fclose(f), 0);
}

/* The same file rewritten with another intensity, its modification time as before. */
static void rewrite_h2o_same_time(const set *s, int digit)
{
    struct stat before;
    assert_int_equal(stat(s->h2o, &before), 0);
    write_h2o(s, digit);
    struct timespec t[2] = {before.st_atim, before.st_mtim};
    assert_int_equal(utimensat(AT_FDCWD, s->h2o, t, 0), 0);
}

/* The file's modification time one second later. */
static void touch_h2o_later(const set *s)
{
    struct stat st;
    assert_int_equal(stat(s->h2o, &st), 0);
    struct timespec t[2] = {st.st_atim, st.st_mtim};
    t[1].tv_sec += 1;
    assert_int_equal(utimensat(AT_FDCWD, s->h2o, t, 0), 0);
}

static void set_make(set *s, int digit)
{
    snprintf(s->dir, sizeof s->dir, "/tmp/thz-atm-inputs-XXXXXX");
    assert_non_null(mkdtemp(s->dir));
    snprintf(s->h2o, sizeof s->h2o, "%s/h2o.csv", s->dir);
    write_h2o(s, digit);
    s->paths[ATM_IN_H2O] = s->h2o;
    s->paths[ATM_IN_O2] = THZ_SOURCE_DIR "/tests/inputs/atm_o2_subset.csv";
    s->paths[ATM_IN_O2_COUPLED] = DATA "am14_o2_lines_coupled.csv";
    s->paths[ATM_IN_Q_H2O] = DATA "am14_h2o_partition_sums_tips2021.csv";
    s->paths[ATM_IN_Q_O2] = DATA "am14_o2_partition_sums_tips2021.csv";
    s->paths[ATM_IN_CONTINUUM] = DATA "mt_ckd_4.2_h2o_continuum_0-520cm-1.csv";
}

static void set_remove(set *s)
{
    unlink(s->h2o);
    rmdir(s->dir);
}

/* The leading digit of the intensity the read gave (S296 of the one line, x 1e23). */
static int read_digit(const atm_inputs *in)
{
    assert_int_equal(in->h2o.n, 1);
    return (int)(in->h2o.lines[0].s296_cm2_ghz * 1e23);
}

static const atm_inputs *acquire(const set *s)
{
    const atm_inputs *in = NULL;
    thz_error err = {0};
    if (atm_inputs_acquire(s->paths, &in, &err) != THZ_OK)
        fail_msg("%s", err.message);
    return in;
}

static void test_shared_then_read_again(void **state)
{
    (void)state;
    set s;
    set_make(&s, 1);
    const atm_inputs *a = acquire(&s);
    assert_int_equal(read_digit(a), 1);
    assert_true(a->n_cont > 4 && a->o2_coupled.n > 0 && a->q_h2o.n_iso >= 1);
    /* the same files, as far as their identity tells: the first read, shared */
    rewrite_h2o_same_time(&s, 2);
    const atm_inputs *b = acquire(&s);
    assert_ptr_equal(a, b);
    assert_int_equal(read_digit(b), 1);
    atm_inputs_release(b);
    atm_inputs_release(a);
    /* released, still kept */
    const atm_inputs *c = acquire(&s);
    assert_int_equal(read_digit(c), 1);
    atm_inputs_release(c);
    /* a later modification time: read again */
    touch_h2o_later(&s);
    const atm_inputs *d = acquire(&s);
    assert_int_equal(read_digit(d), 2);
    atm_inputs_release(d);
    /* another size, the same modification time: read again */
    rewrite_h2o_same_time(&s, 3);
    struct stat st;
    assert_int_equal(stat(s.h2o, &st), 0);
    FILE *f = fopen(s.h2o, "a");
    assert_non_null(f);
    fputs("\n", f);
    assert_int_equal(fclose(f), 0);
    struct timespec t[2] = {st.st_atim, st.st_mtim};
    assert_int_equal(utimensat(AT_FDCWD, s.h2o, t, 0), 0);
    const atm_inputs *e = acquire(&s);
    assert_int_equal(read_digit(e), 3);
    atm_inputs_release(e);
    set_remove(&s);
}

static void test_least_recently_used_read_again(void **state)
{
    (void)state;
    set s[ATM_INPUTS_CACHED + 1];
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++) {
        set_make(&s[i], 1);
        atm_inputs_release(acquire(&s[i]));
        rewrite_h2o_same_time(&s[i], 2);
    }
    /* set 0 was dropped for the last one; the others are still as first read */
    for (int i = ATM_INPUTS_CACHED; i >= 1; i--) {
        const atm_inputs *in = acquire(&s[i]);
        assert_int_equal(read_digit(in), 1);
        atm_inputs_release(in);
    }
    const atm_inputs *in = acquire(&s[0]);
    assert_int_equal(read_digit(in), 2);
    atm_inputs_release(in);
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++)
        set_remove(&s[i]);
}

/* Sets held by callers are never dropped: one more set is read, given out and freed at
 * its release, and the held ones stay as they were read. */
static void test_held_sets_stay(void **state)
{
    (void)state;
    set s[ATM_INPUTS_CACHED + 1];
    const atm_inputs *held[ATM_INPUTS_CACHED + 1];
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++) {
        set_make(&s[i], 4);
        held[i] = acquire(&s[i]);
    }
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++) {
        assert_int_equal(read_digit(held[i]), 4);
        rewrite_h2o_same_time(&s[i], 5);
    }
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++)
        atm_inputs_release(held[i]);
    /* the last one was not kept (every slot was held): read again; the others were */
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++) {
        const atm_inputs *in = acquire(&s[i]);
        assert_int_equal(read_digit(in), i < ATM_INPUTS_CACHED ? 4 : 5);
        atm_inputs_release(in);
    }
    for (int i = 0; i <= ATM_INPUTS_CACHED; i++)
        set_remove(&s[i]);
}

/* A file that cannot be read: the reader's message, nothing kept. */
static void test_missing_file(void **state)
{
    (void)state;
    set s;
    set_make(&s, 1);
    unlink(s.h2o);
    const atm_inputs *in = NULL;
    thz_error err = {0};
    assert_int_not_equal(atm_inputs_acquire(s.paths, &in, &err), THZ_OK);
    assert_null(in);
    assert_non_null(strstr(err.message, "h2o.csv"));
    set_remove(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shared_then_read_again),
        cmocka_unit_test(test_least_recently_used_read_again),
        cmocka_unit_test(test_held_sets_stay),
        cmocka_unit_test(test_missing_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
