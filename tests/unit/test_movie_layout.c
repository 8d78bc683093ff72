/* A movie frame's layout (scene-format.md "Outputs", the movies): the image enlarged a
 * whole number of times, the least that makes it at least 256 pixels across but at most
 * 16 times, 96 pixels of colour bar beside it and 16 of caption above, both sides even
 * (the encoders' 4:2:0 needs them so). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "batch/batch_internal.h"

static void test_enlargement(void **state)
{
    (void)state;
    const uint32_t rows[] = {1, 3, 12, 1100};
    for (uint32_t columns = 1; columns <= 600; columns++)
        for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
            movie_layout l;
            movie_layout_of(columns, rows[r], &l);
            uint32_t across = columns * l.pixel;
            if (l.pixel < 1 || l.pixel > 16 || (across < 256 && l.pixel != 16) ||
                (l.pixel > 1 && (l.pixel - 1) * columns >= 256))
                fail_msg("%u x %u pixels: enlarged %u times (%u across)", columns, rows[r], l.pixel,
                         across);
            assert_int_equal(l.image_x, 0);
            assert_int_equal(l.image_y, 16);
            assert_int_equal(l.width, across + 96 + (across % 2));
            assert_true(l.height >= 16 + rows[r] * l.pixel && l.height % 2 == 0);
        }
}

/* The caption's decimals: every frame time written exactly where a few decimals can
 * (0.125 s at 8 fps needs 3, 0.0625 s at 16 fps 4), else enough to tell frames apart
 * (30 fps: 0.03, 0.07, 0.10 s). */
static void test_time_decimals(void **state)
{
    (void)state;
    const struct {
        double dt;
        int decimals;
    } cases[] = {{1.0, 0},   {3.0, 0},    {0.5, 1},   {0.2, 1},      {0.25, 2},
                 {0.125, 3}, {0.0625, 4}, {0.001, 3}, {1.0 / 30, 2}, {1.0 / 3, 1}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (movie_time_decimals(cases[i].dt) != cases[i].decimals)
            fail_msg("a frame interval of %g s: %d decimals, expected %d", cases[i].dt,
                     movie_time_decimals(cases[i].dt), cases[i].decimals);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_enlargement),
        cmocka_unit_test(test_time_decimals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
