/* Camera model: orientation conventions, sample placement and exact pixel solid
 * angles (physics.md "Rendering phase"). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sensor/camera.h"

static thz_sensor make_sensor(double fov_deg, uint32_t columns, uint32_t rows, uint32_t n)
{
    thz_sensor s;
    memset(&s, 0, sizeof s);
    s.name = "cam";
    s.position_m[0] = 1.0;
    s.position_m[1] = 2.0;
    s.position_m[2] = 3.0;
    s.direction[1] = 1.0; /* looking along +y */
    s.up[2] = 1.0;
    s.fov_deg = fov_deg;
    s.columns = columns;
    s.rows = rows;
    s.oversampling = n;
    s.aperture_m2 = 0.01;
    s.normalize_to_k = 295.0;
    return s;
}

/* Solid angle of [0,x] x [0,y] at unit distance (corner formula), for cross-checks. */
static double corner(double x, double y)
{
    return atan(x * y / sqrt(1.0 + x * x + y * y));
}

static void test_pixel_solid_angles_sum_to_image(void **state)
{
    (void)state;
    const struct {
        double fov;
        uint32_t c, r;
    } cases[] = {{40.0, 64, 48}, {170.0, 7, 3}, {1.0, 100, 100}, {90.0, 1, 1}, {120.0, 33, 65}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        thz_sensor s = make_sensor(cases[k].fov, cases[k].c, cases[k].r, 1);
        camera cam;
        assert_int_equal(camera_init(&cam, &s, NULL), THZ_OK);
        double sum = 0.0;
        for (uint32_t row = 0; row < cam.rows; row++)
            for (uint32_t col = 0; col < cam.columns; col++)
                sum += camera_pixel_solid_angle(&cam, col, row);
        double a = 0.5 * cases[k].fov * M_PI / 180.0;
        double b = atan(tan(a) * cases[k].r / cases[k].c);
        double exact = 4.0 * asin(sin(a) * sin(b));
        assert_true(fabs(camera_image_solid_angle(&cam) - exact) <= 1e-14 * exact);
        assert_true(fabs(sum - exact) <= 1e-12 * exact);
    }
}

static void test_rectangle_solid_angle_closed_forms(void **state)
{
    (void)state;
    /* against the corner formula on a generic rectangle */
    double x0 = -0.3, x1 = 0.7, y0 = 0.2, y1 = 1.1;
    double ref = corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
    assert_true(fabs(camera_rectangle_solid_angle(x0, x1, y0, y1) - ref) < 1e-14);
    /* a hemisphere's quarter: [0, inf) x [0, inf) -> pi/2; use a huge square */
    double big = 1e8;
    assert_true(fabs(camera_rectangle_solid_angle(-big, big, -big, big) - 2.0 * M_PI) < 1e-7);
    /* a tiny pixel far off axis: dx dy cos^3 / 1 (relative accuracy kept) */
    double x = 2.0, y = -1.5, d = 1e-7;
    double tiny = camera_rectangle_solid_angle(x, x + d, y, y + d);
    double dx = (x + d) - x, dy = (y + d) - y; /* the widths actually represented */
    double xc = x + dx / 2, yc = y + dy / 2;
    double approx = dx * dy / pow(1.0 + xc * xc + yc * yc, 1.5);
    assert_true(fabs(tiny / approx - 1.0) < 1e-9);
}

static void test_orientation(void **state)
{
    (void)state;
    thz_sensor s = make_sensor(60.0, 5, 3, 1);
    s.up[1] = 0.5; /* not orthogonal to the direction: must be orthogonalised */
    camera cam;
    assert_int_equal(camera_init(&cam, &s, NULL), THZ_OK);
    /* right = direction x up = +y x +z = +x; up orthogonalised to +z */
    assert_true(fabs(cam.right.x - 1.0) < 1e-15 && fabs(cam.up.z - 1.0) < 1e-15);
    assert_true(fabs(v3_dot(cam.up, cam.forward)) < 1e-15);
    /* the centre pixel of an odd resolution looks straight ahead */
    vec3 c = camera_pixel_center_dir(&cam, 2, 1);
    assert_true(fabs(c.y - 1.0) < 1e-15);
    /* column 0 is the left (-x), row 0 the top (+z) */
    vec3 tl = camera_pixel_center_dir(&cam, 0, 0);
    assert_true(tl.x < 0.0 && tl.z > 0.0);
    vec3 br = camera_pixel_center_dir(&cam, 4, 2);
    assert_true(br.x > 0.0 && br.z < 0.0);
    /* horizontal half-angle at the left edge of column 0: fov/2 */
    vec3 edge = camera_plane_dir(&cam, -cam.half_width, 0.0);
    assert_true(fabs(acos(edge.y) - 30.0 * M_PI / 180.0) < 1e-12);
    /* square pixels: vertical field follows from rows/columns */
    assert_true(fabs(cam.half_height - tan(M_PI / 6.0) * 3.0 / 5.0) < 1e-15);
}

static void test_oversampling_grid(void **state)
{
    (void)state;
    thz_sensor s = make_sensor(50.0, 4, 4, 3);
    camera cam;
    assert_int_equal(camera_init(&cam, &s, NULL), THZ_OK);
    /* n = 3: the middle sample is the pixel centre; the outer ones sit at 1/6 and 5/6 */
    vec3 mid = camera_sample_dir(&cam, 1, 2, 1, 1);
    vec3 ctr = camera_pixel_center_dir(&cam, 1, 2);
    assert_true(v3_length(v3_sub(mid, ctr)) < 1e-15);
    vec3 s00 = camera_sample_dir(&cam, 1, 2, 0, 0);
    double x = s00.x / s00.y, z = s00.z / s00.y; /* back on the image plane */
    double ex = -cam.half_width + (1.0 + 1.0 / 6.0) * cam.pixel_pitch;
    double ez = cam.half_height - (2.0 + 1.0 / 6.0) * cam.pixel_pitch;
    assert_true(fabs(x - ex) < 1e-14 && fabs(z - ez) < 1e-14);
}

static void test_rejects_bad_sensor(void **state)
{
    (void)state;
    thz_sensor s = make_sensor(50.0, 4, 4, 1);
    s.up[1] = 1.0;
    s.up[2] = 0.0; /* parallel to the direction */
    camera cam;
    thz_error err;
    assert_int_equal(camera_init(&cam, &s, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "parallel"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pixel_solid_angles_sum_to_image),
        cmocka_unit_test(test_rectangle_solid_angle_closed_forms),
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_oversampling_grid),
        cmocka_unit_test(test_rejects_bad_sensor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
