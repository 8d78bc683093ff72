/* A batch's movies read each frame's brightness-temperature cube back
 * (src/batch/batch_movie.c): a finished frame whose cube is gone or cut short is named
 * with the system's reason and how to have the frame computed again (the error said
 * "cannot open (a frame's cube)" alone). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "batch/batch_internal.h"

static void test_missing_cube(void **state)
{
    (void)state;
    char dir[] = "/tmp/thz-read-band-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/cam.brightness_temperature.img", dir);
    float band[4];
    thz_error err = {0};
    assert_int_equal(batch_read_band(path, 2, 2, 1, 0, band, &err), THZ_ERR_IO);
    assert_non_null(strstr(err.message, "No such file or directory"));
    assert_non_null(strstr(err.message, "remove the frame's directory and run the batch again"));
    /* cut short: 3 floats of 4 */
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    const float three[3] = {300.0f, 301.0f, 302.0f};
    assert_int_equal(fwrite(three, sizeof(float), 3, f), 3);
    assert_int_equal(fclose(f), 0);
    thz_error err2 = {0};
    assert_int_equal(batch_read_band(path, 2, 2, 1, 0, band, &err2), THZ_ERR_IO);
    assert_non_null(strstr(err2.message, "shorter than 2 x 2 x 1 floats"));
    assert_non_null(strstr(err2.message, "remove the frame's directory and run the batch again"));
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_missing_cube)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
