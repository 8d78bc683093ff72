/* Fresnel and mirror identities (scene-format.md "Materials: optics from a complex
 * index"), for every integrator:
 *  - an opaque plate of index n + ik at T1 in a black room at T2, seen at 0, 45 and 75
 *    degrees, shows L = (1 - R(theta)) B(T1) + R(theta) B(T2) per pixel, R the Fresnel
 *    reflectance (computed here independently in complex arithmetic) at the pixel's own
 *    angle; T2 = 0 K is the issue's check Tb = B^-1((1 - R) B(T1)), T2 = 350 K checks the
 *    angle-dependent diffuse BRDF's weights too; with an explicit emissivity e (which
 *    replaces 1 - R, constant over angle) L = e B(T1) + R(theta) B(T2), from the
 *    deviation maps too;
 *  - a mirror (`specular`, R = 0.9) at 0 K shows the image of a hot disk at exactly the
 *    pixels whose mirrored ray meets the disk, with 0.9 B(T_disk), and 0 elsewhere. */
#include <complex.h>

#include "identity.h"

#define PLATE_N 2.1
#define PLATE_K 0.35

/* The Fresnel reflectance of air -> n + ik, written out independently of fresnel.c. */
static double test_fresnel(double n, double k, double mu)
{
    double complex m = n + I * k, cos_i = mu;
    double complex sin2 = 1.0 - mu * mu;
    double complex cos_t = csqrt(1.0 - sin2 / (m * m));
    double complex rs = (cos_i - m * cos_t) / (cos_i + m * cos_t);
    double complex rp = (m * cos_i - cos_t) / (m * cos_i + cos_t);
    return 0.5 * (cabs(rs) * cabs(rs) + cabs(rp) * cabs(rp));
}

static void plate_case(thz_integrator integrator, double angle_deg, double room_k, double t0_k,
                       double eps)
{
    char json[3000], eps_key[64] = "", eps_text[32] = "1 - R";
    double th = angle_deg * M_PI / 180.0;
    if (!isnan(eps)) {
        snprintf(eps_key, sizeof eps_key, ", \"emissivity\": %g", eps);
        snprintf(eps_text, sizeof eps_text, "%g", eps);
    }
    snprintf(json, sizeof json,
             "{\"format\": \"thzmap-scene/1\", \"name\": \"fresnel-plate\","
             " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"
             " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
             "   \"glassy\": {\"refractive_index\": [%g, %g]%s}},"
             " \"objects\": ["
             "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\","
             "    \"temperature_k\": %g,"
             "    \"shape\": {\"type\": \"box\", \"size_m\": [6, 6, 6], \"inward\": true}},"
             "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"glassy\","
             "    \"temperature_k\": 300,"
             "    \"shape\": {\"type\": \"box\", \"size_m\": [2.4, 2.4, 0.1]}}],"
             " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, %.17g, %.17g],"
             "   \"direction\": [0, %.17g, %.17g], \"up\": [1, 0, 0], \"fov_deg\": 6,"
             "   \"resolution\": [6, 6], \"oversampling\": 1, \"normalize_to_k\": 300}],"
             " \"photons\": {\"per_channel\": 400000, \"seed\": 7, \"gather_min_photons\": 256}}",
             PLATE_N, PLATE_K, eps_key, room_k, -sin(th), 0.05 + cos(th), sin(th), -cos(th));
    ident_run r;
    ident_run_scene_t0(&r, json, ident_photons(400000), integrator, ident_estimates(32), t0_k);
    const thz_channel *ch = &r.scene->channels[0];
    double b1 = ident_band_planck(ch, 300.0), b2 = room_k > 0.0 ? ident_band_planck(ch, room_k) : 0;
    double expects[36];
    double rmin = 1.0, rmax = 0.0;
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            vec3 d = camera_pixel_center_dir(&r.cam, col, row);
            double refl = test_fresnel(PLATE_N, PLATE_K, fabs(d.z));
            rmin = fmin(rmin, refl);
            rmax = fmax(rmax, refl);
            double e = isnan(eps) ? 1.0 - refl : eps;
            expects[row * r.img.columns + col] = e * b1 + refl * b2;
        }
    ident_tally t = {.pooled_rel_se = ident_pooled_rel_se(&r, 0, expects)};
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            assert_int_equal(r.img.object_id[row * r.img.columns + col], 1);
            ident_check_pixel(&t, &r, 0, col, row, expects[row * r.img.columns + col], 1e-4);
        }
    char what[320], label[64];
    ident_label(label, sizeof label, integrator, t0_k);
    snprintf(what, sizeof what,
             "Fresnel plate %g + %gi, emissivity %s, at %g deg (R %.4f..%.4f), room %g K, %s",
             PLATE_N, PLATE_K, eps_text, angle_deg, rmin, rmax, room_k, label);
    ident_tally_assert(&t, what, 0.08 / sqrt(ident_scale()), 1e-4);
    ident_run_fini(&r);
}

static void test_fresnel_plate(void **state)
{
    (void)state;
    const double angles[] = {0.0, 45.0, 75.0};
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        for (size_t a = 0; a < 3; a++) {
            plate_case(ident_integrators[k], angles[a], 0.0, NAN, NAN);
            /* a warm room: the reflected part's weights (T0 = 0 K: not cancelled by the
             * control variate); and with an explicit emissivity, whose deviation map at
             * T0 = 350 K has two sources on the plate, e B(T1) and -A(theta) B0 */
            if (a == 2)
                for (size_t v = 0; v < IDENT_N_T0; v++)
                    if (ident_t0_applies(ident_integrators[k], v)) {
                        plate_case(ident_integrators[k], angles[a], 350.0, ident_t0s[v], NAN);
                        plate_case(ident_integrators[k], angles[a], 350.0, ident_t0s[v], 0.6);
                    }
        }
}

/* The mirror z = 0 (a 2 m plate, top face at z = 0), the camera at (0, -1, 1) looking
 * down at 45 degrees, a hot disk of radius 0.2 m centred at (0, 1, 1) facing -y: its
 * mirror image is seen around the direction (0, 1, -1). */
static const char *mirror_json =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"mirror\","
    " \"channels\": [{\"frequency_thz\": 0.5, \"relative_width\": 0.05}],"
    " \"materials\": {\"black\": {\"reflectivity\": 0.0},"
    "   \"mirror\": {\"reflectivity\": 0.9, \"reflection\": \"specular\"}},"
    " \"objects\": ["
    "   {\"name\": \"room\", \"type\": \"solid\", \"material\": \"black\", \"temperature_k\": 0,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [8, 8, 8], \"inward\": true}},"
    "   {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"mirror\", \"temperature_k\": 0,"
    "    \"shape\": {\"type\": \"box\", \"size_m\": [3, 3, 0.1]},"
    "    \"transform\": {\"translate_m\": [0, 0, -0.05]}},"
    "   {\"name\": \"disk\", \"type\": \"solid\", \"two_sided\": true, \"material\": \"black\","
    "    \"temperature_k\": 400, \"shape\": {\"type\": \"disk\", \"radius_m\": 0.2},"
    "    \"transform\": {\"rotate_deg\": [90, 0, 0], \"translate_m\": [0, 1, 1]}}],"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -1, 1], \"direction\": [0, 1, -1],"
    "   \"up\": [0, 0, 1], \"fov_deg\": 30, \"resolution\": [16, 16], \"oversampling\": 1,"
    "   \"normalize_to_k\": 300}],"
    " \"photons\": {\"per_channel\": 100000, \"seed\": 7}}";

static void mirror_case(thz_integrator integrator)
{
    ident_run r;
    ident_run_scene_with(&r, mirror_json, ident_photons(100000), integrator, ident_estimates(16));
    const thz_channel *ch = &r.scene->channels[0];
    double b = ident_band_planck(ch, 400.0);
    size_t inside = 0, outside = 0;
    for (uint32_t row = 0; row < r.img.rows; row++)
        for (uint32_t col = 0; col < r.img.columns; col++) {
            vec3 d = camera_pixel_center_dir(&r.cam, col, row);
            if (!(d.z < 0.0))
                continue;
            /* the mirrored ray from the plate point p, d' = (dx, dy, -dz), meets y = 1 */
            double s = 1.0 / -d.z; /* to z = 0 from height 1 */
            vec3 p = v3(d.x * s, -1.0 + d.y * s, 0.0);
            double u = (1.0 - p.y) / d.y;
            vec3 q = v3(p.x + u * d.x, 1.0, -u * d.z);
            double rho = sqrt(q.x * q.x + (q.z - 1.0) * (q.z - 1.0));
            double l = r.img.radiance[ident_at(&r, 0, col, row)];
            /* exact but for path's frequency sampling beyond the first hit; photon-map's
             * error is unknown (NaN) on the unlit disk, whose reflection 0 is exact */
            double se = r.img.radiance_stderr[ident_at(&r, 0, col, row)];
            double tol = 1e-6 * b + (isnan(se) ? 0.0 : IDENT_Z * se);
            if (rho < 0.17) {
                inside++;
                if (!(fabs(l - 0.9 * b) <= tol))
                    print_message("%s pixel (%u, %u): L = %.6e, expected %.6e\n",
                                  render_integrator_name(integrator), col, row, l, 0.9 * b);
                assert_true(fabs(l - 0.9 * b) <= tol);
            } else if (rho > 0.23) {
                outside++;
                assert_true(fabs(l) <= 1e-9 * b);
            }
        }
    print_message("mirror, %s: %zu pixels show the disk at 0.9 B(T), %zu show 0\n",
                  render_integrator_name(integrator), inside, outside);
    assert_true(inside >= 4);
    assert_true(outside >= 100);
    ident_run_fini(&r);
}

static void test_mirror(void **state)
{
    (void)state;
    for (size_t k = 0; k < IDENT_N_INTEGRATORS; k++)
        mirror_case(ident_integrators[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_mirror),
                                       cmocka_unit_test(test_fresnel_plate)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
