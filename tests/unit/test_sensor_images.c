/* A sensor's images (sensor/images.c): each object's mean over the pixels that see it, as
 * S.spectra.png plots it (the paper's Fig. 6: the mean normalised radiance of each object
 * in view). The figure's values are never read back from the PNG, so the sum for the
 * mean (a mutant of the figure's code) passed every test. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sensor/images.h"

static void test_object_means(void **state)
{
    (void)state;
    sensor_images img;
    thz_error err = {0};
    assert_int_equal(sensor_images_init(&img, 3, 2, 2, 0, &err), THZ_OK);
    /* objects by pixel: 0, 1, nothing, 1, 7 (no such object), 0 */
    const int32_t ids[6] = {0, 1, -1, 1, 7, 0};
    const float cube[12] = {1.0f, 2.0f, 100.0f, 4.0f, 100.0f, 3.0f,   /* channel 1 */
                            0.5f, 8.0f, 100.0f, 9.0f, 100.0f, 0.25f}; /* channel 2 */
    for (int p = 0; p < 6; p++)
        img.object_id[p] = ids[p];
    uint64_t count[3];
    double mean[6];
    sensor_images_object_means(&img, cube, 3, count, mean);
    assert_int_equal(count[0], 2);
    assert_int_equal(count[1], 2);
    assert_int_equal(count[2], 0);
    assert_true(mean[0] == 2.0 && mean[1] == 0.375); /* object 0: (1 + 3)/2, (0.5 + 0.25)/2 */
    assert_true(mean[2] == 3.0 && mean[3] == 8.5);   /* object 1: (2 + 4)/2, (8 + 9)/2 */
    assert_true(mean[4] == 0.0 && mean[5] == 0.0);   /* object 2: seen by no pixel */
    sensor_images_fini(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_object_means)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
