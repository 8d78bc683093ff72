/* core/order.c's radix sort of 64-bit keys against qsort: random keys, keys that share
 * digits (passes skipped), duplicates, one and no key, counts either side of 2^11 (below
 * it the library's sort is used), and key counts that the threads sort together (run with
 * OMP_NUM_THREADS unset: all cores, 2 in CI). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "core/order.h"
#include "core/rng.h"

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* 64 random bits from the project's own streams */
static uint64_t next(void)
{
    static rng_stream rng;
    static bool started;
    if (!started) {
        rng_init(&rng, 1, 0, RNG_PURPOSE_TEST, 0);
        started = true;
    }
    return rng_next_u64(&rng);
}

static void check(size_t n, uint64_t mask, uint64_t base)
{
    /* zeroed: with n = 0 the comparison below reads one byte of each, written by no one */
    uint64_t *a = calloc(n ? n : 1, sizeof *a), *b = calloc(n ? n : 1, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    for (size_t i = 0; i < n; i++)
        a[i] = b[i] = base | (next() & mask);
    order_sort_u64(a, n);
    qsort(b, n, sizeof *b, cmp_u64);
    assert_memory_equal(a, b, n * sizeof *a + (n == 0));
    free(a);
    free(b);
}

static void test_sort_u64(void **state_)
{
    (void)state_;
    check(0, ~0ull, 0);
    check(1, ~0ull, 0);
    check(2, ~0ull, 0);
    check(100000, ~0ull, 0);                      /* every digit differs */
    check(100000, 0xffffull << 32, 0x1234ull);    /* only the third digit varies */
    check(100000, 0x7, 0xabcdef0123456780ull);    /* many duplicates */
    check(100000, 0xffffffffull << 32 | 0xff, 0); /* edges' keys: two indices */
    check(3, 0, 42);                              /* all equal */
    check(2047, ~0ull, 0);                        /* the last count the library sorts */
    check(2048, 0xffffffffull << 32 | 0xff, 0);   /* the first the passes sort */
    /* from 2^20 keys on, every thread sorts a part of each pass (the parts of one digit
     * in order): an odd count, so that the parts differ in size */
    check(3000001, ~0ull, 0);
    check(3000001, 0xffffffull << 32 | 0xffffff, 0); /* edges of 2^24 vertices */
    check(2000000, 0x3, 0x5555000000000000ull);      /* 4 values, passes skipped */
    check(1 << 20, 0, 7);                            /* all equal, parallel */
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_sort_u64)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
