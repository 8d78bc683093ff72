/* Overflow-checked allocation (core/alloc.h): a count whose bytes wrap size_t, or a
 * capacity whose doubling wraps, gives NULL and leaves the caller's array and capacity
 * as they were, rather than a short block the caller then writes n elements into. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/alloc.h"

/* n x 8 bytes is 2^64 + 8: 8 bytes once wrapped, which malloc would give. */
static void test_wrapping_counts(void **state)
{
    (void)state;
    const size_t n = SIZE_MAX / 8 + 2;
    assert_null(thz_malloc_array(n, 8));
    assert_null(thz_calloc(n, 8));
    char *p = malloc(16);
    assert_non_null(p);
    memcpy(p, "kept", 5);
    assert_null(thz_realloc_array(p, n, 8));
    assert_string_equal(p, "kept"); /* the old block is the caller's still */
    free(p);
}

/* first, then doubling; a doubling past SIZE_MAX refused with p and *capacity kept. */
static void test_grow(void **state)
{
    (void)state;
    size_t cap = 0;
    int *a = thz_grow_array(NULL, &cap, 5, sizeof *a);
    assert_non_null(a);
    assert_int_equal(cap, 5);
    for (int i = 0; i < 5; i++)
        a[i] = i;
    int *b = thz_grow_array(a, &cap, 5, sizeof *b);
    assert_non_null(b);
    assert_int_equal(cap, 10);
    for (int i = 0; i < 5; i++)
        assert_int_equal(b[i], i);
    free(b);

    char *p = malloc(8);
    assert_non_null(p);
    memcpy(p, "kept", 5);
    size_t huge = SIZE_MAX / 2 + 1; /* 2 huge wraps to 0 */
    assert_null(thz_grow_array(p, &huge, 4, 1));
    assert_true(huge == SIZE_MAX / 2 + 1);
    assert_string_equal(p, "kept");
    size_t big = SIZE_MAX / 16; /* doubles without wrapping, but 16 bytes each does */
    assert_null(thz_grow_array(p, &big, 4, 16));
    assert_true(big == SIZE_MAX / 16);
    assert_string_equal(p, "kept");
    free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wrapping_counts),
        cmocka_unit_test(test_grow),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
