/* What the browser GUI (`thzmap serve`) reads through the public API alone: an object's
 * triangles in world space (transforms applied), a material's optics at a frequency (the
 * table, Kirchhoff's law, Fresnel from a complex index, a slab's transmission), a photon
 * map's stored photons, and Planck's law with its inverse; each against values worked
 * out here from the scene text, not from the library. */
#include <math.h>
#include <stdbool.h>

#include "api_test.h"

static const char scene_json[] =
    "{\"format\": \"thzmap-scene/1\", \"channels\": [{\"frequency_thz\": 0.5, "
    "\"relative_width\": 0.01}], \"materials\": {"
    "\"table\": {\"reflectivity\": [[0.2, 0.05], [1.2, 0.3]]}, "
    "\"glass\": {\"refractive_index\": [2.0, 0.01]}, "
    "\"veil\": {\"reflectivity\": 0.1, \"attenuation_per_m\": 300}}, "
    "\"objects\": ["
    "{\"name\": \"room\", \"type\": \"solid\", \"material\": \"table\", \"temperature_k\": 295, "
    "\"shape\": {\"type\": \"box\", \"size_m\": [4, 4, 4], \"inward\": true}}, "
    "{\"name\": \"cube\", \"type\": \"solid\", \"material\": \"glass\", \"temperature_k\": 310, "
    "\"shape\": {\"type\": \"box\", \"size_m\": [0.2, 0.4, 0.6]}, "
    "\"transform\": {\"translate_m\": [0.5, -0.25, 1]}}], "
    "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -1.5, 0], \"look_at_m\": [0, 0, 0], "
    "\"fov_deg\": 40, \"resolution\": [8, 8]}], "
    "\"photons\": {\"per_channel\": 3000, \"seed\": 2}, \"render\": {\"integrator\": "
    "\"photon-map\"}}";

/* The cube's mesh: a box 0.2 x 0.4 x 0.6 m centred at (0.5, -0.25, 1). */
static void check_mesh(const thz_scene *scene)
{
    thz_object_mesh m;
    CHECK(thz_scene_object_mesh(scene, 1, &m) == THZ_OK, "mesh of object 1");
    CHECK(m.n_triangles == 12, "a box has 12 triangles, got %zu", m.n_triangles);
    const double centre[3] = {0.5, -0.25, 1.0}, half[3] = {0.1, 0.2, 0.3};
    for (size_t v = 0; v < m.n_vertices; v++)
        for (int a = 0; a < 3; a++)
            CHECK(fabs(fabs(m.positions[3 * v + a] - centre[a]) - half[a]) < 1e-6,
                  "vertex %zu axis %d at %g", v, a, (double)m.positions[3 * v + a]);
    double area = 0.0;
    for (size_t t = 0; t < m.n_triangles; t++) {
        const uint32_t *ix = &m.indices[3 * t];
        CHECK(ix[0] < m.n_vertices && ix[1] < m.n_vertices && ix[2] < m.n_vertices,
              "triangle %zu indices", t);
        const float *p0 = &m.positions[3 * ix[0]], *p1 = &m.positions[3 * ix[1]],
                    *p2 = &m.positions[3 * ix[2]];
        double e1[3], e2[3], c[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = p1[a] - p0[a];
            e2[a] = p2[a] - p0[a];
        }
        c[0] = e1[1] * e2[2] - e1[2] * e2[1];
        c[1] = e1[2] * e2[0] - e1[0] * e2[2];
        c[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        area += 0.5 * len;
        /* counter-clockwise from the front: the cross product is the (outward) normal */
        double dot = 0.0, out = 0.0;
        for (int a = 0; a < 3; a++) {
            dot += c[a] / len * m.normals[3 * t + a];
            out += m.normals[3 * t + a] * ((p0[a] + p1[a] + p2[a]) / 3.0 - centre[a]);
        }
        CHECK(fabs(dot - 1.0) < 1e-5 && out > 0.0, "triangle %zu: normal and winding", t);
    }
    CHECK(fabs(area - 2 * (0.2 * 0.4 + 0.4 * 0.6 + 0.2 * 0.6)) < 1e-5, "area %g m2", area);
    CHECK(thz_scene_object_mesh(scene, 2, &m) == THZ_ERR_INPUT && m.n_vertices == 0,
          "object 2 does not exist");
}

static void check_optics(const thz_scene *scene)
{
    thz_surface_optics o;
    /* table: linear between (0.2, 0.05) and (1.2, 0.3) THz; Kirchhoff: eps = 1 - R */
    CHECK(thz_scene_material_optics(scene, 0, 0.7e12, 0.0, &o) == THZ_OK, "table");
    CHECK(fabs(o.reflectance_normal - 0.175) < 1e-12 && fabs(o.emissivity_normal - 0.825) < 1e-12,
          "table R %g eps %g", o.reflectance_normal, o.emissivity_normal);
    CHECK(!o.has_index && o.transmission_mean == 0.0, "no index, a half-space transmits nothing");
    /* glass: Fresnel at normal incidence |(n + ik - 1) / (n + ik + 1)|^2 */
    double n = 2.0, k = 0.01, f = 0.5e12;
    double r = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
    CHECK(thz_scene_material_optics(scene, 1, f, 0.0, &o) == THZ_OK, "glass");
    CHECK(o.has_index && o.n == n && o.k == k, "index %g %g", o.n, o.k);
    CHECK(fabs(o.reflectance_normal - r) < 1e-9, "Fresnel R %g, expected %g", o.reflectance_normal,
          r);
    CHECK(fabs(o.attenuation_per_m - 4 * M_PI * k * f / 299792458.0) < 1e-9 * o.attenuation_per_m,
          "alpha %g", o.attenuation_per_m);
    CHECK(o.reflectance_mean > o.reflectance_normal, "Fresnel R grows towards grazing");
    /* veil as a 1 mm slab: T(mu) = min(exp(-alpha t / mu), 1 - R), mean 2 int T mu dmu */
    CHECK(thz_scene_material_optics(scene, 2, f, 0.001, &o) == THZ_OK, "veil slab");
    double t_mean = 0.0;
    for (int i = 0; i < 200000; i++) { /* midpoint rule */
        double mu = (i + 0.5) / 200000.0;
        t_mean += 2.0 * fmin(exp(-300.0 * 0.001 / mu), 0.9) * mu / 200000.0;
    }
    CHECK(fabs(o.transmission_mean - t_mean) < 1e-6, "slab T-bar %g, expected %g",
          o.transmission_mean, t_mean);
    CHECK(fabs(o.emissivity_normal - (1.0 - 0.1 - fmin(exp(-0.3), 0.9))) < 1e-9,
          "slab eps at normal incidence %g", o.emissivity_normal);
    CHECK(thz_scene_material_optics(scene, 3, f, 0.0, &o) == THZ_ERR_INPUT, "material 3");
    CHECK(thz_scene_material_optics(scene, 0, -1.0, 0.0, &o) == THZ_ERR_INPUT, "negative f");
}

static void check_photons(const thz_scene *scene)
{
    thz_error err = {0};
    thz_context *ctx = thz_context_create();
    thz_photons *ph = NULL;
    REQUIRE_OK(thz_photons_fire(ctx, scene, NULL, &ph, &err), &err);
    thz_photon_stats st;
    thz_photons_stats(ph, 0, &st);
    size_t n = thz_photons_count(ph, 0);
    CHECK(n == st.stored && n > 0, "count %zu, stored %llu", n, (unsigned long long)st.stored);
    thz_photon_point *p = calloc(n + 1, sizeof *p);
    CHECK(p && thz_photons_points(ph, 0, 0, n + 10, p) == n, "all points");
    CHECK(thz_photons_points(ph, 0, n, 5, p) == 0 && thz_photons_count(ph, 1) == 0,
          "past the end; no channel 1");
    for (size_t i = 0; p && i < n; i++) {
        double d2 = 0.0, r2 = 0.0;
        for (int a = 0; a < 3; a++) {
            d2 += (double)p[i].direction[a] * p[i].direction[a];
            r2 = fmax(r2, fabs(p[i].position_m[a]));
        }
        bool in_room = p[i].object == 0 && fabs(r2 - 2.0) < 1e-5;
        bool on_cube = p[i].object == 1 && fabs(p[i].position_m[2] - 1.0) <= 0.3 + 1e-5;
        if (fabs(d2 - 1.0) > 1e-3 || !(in_room || on_cube) || !(p[i].power_w_per_hz > 0.0f)) {
            CHECK(0, "photon %zu: object %u at (%g, %g, %g), |d|^2 %g", i, p[i].object,
                  (double)p[i].position_m[0], (double)p[i].position_m[1],
                  (double)p[i].position_m[2], d2);
            break;
        }
    }
    free(p);
    thz_photons_destroy(ph);
    thz_context_destroy(ctx);
}

int main(void)
{
    thz_error err = {0};
    thz_scene *scene = NULL;
    REQUIRE_OK(thz_scene_load_string(scene_json, NULL, "gui.json", &scene, &err), &err);
    check_mesh(scene);
    check_optics(scene);
    check_photons(scene);
    thz_scene_destroy(scene);
    /* B(T) = 2 h nu^3 / c^2 / (exp(h nu / k T) - 1) and back */
    double h = 6.62607015e-34, kb = 1.380649e-23, c = 299792458.0, f = 1e12, t = 300.0;
    double b = 2 * h * f * f * f / (c * c) / expm1(h * f / (kb * t));
    CHECK(fabs(thz_planck_radiance(f, t) / b - 1.0) < 1e-12, "Planck");
    CHECK(fabs(thz_brightness_temperature(f, b) - t) < 1e-9, "inverse Planck");
    CHECK(thz_brightness_temperature(f, 0.0) == 0.0, "Tb of no radiance");
    return test_failures ? 1 : 0;
}
