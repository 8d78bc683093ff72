/* The material library through the public API alone: it opens, every entry has a
 * source and a model, water's index at 1 THz is the Liebe 1991 model's (computed
 * independently with complex arithmetic), the normal reflectance and attenuation follow
 * from n and k, an ITU-R P.2040 entry reports its rows, and an unknown name fails with
 * THZ_ERR_INPUT naming the known ones; a scene's materials report their reflection lobe. */
#include <complex.h>
#include <math.h>

#include "api_test.h"

/* thz_scene_material reports each material's `reflection` and Ward's slopes as given. */
static void check_scene_reflection(void)
{
    static const char *json =
        "{\"format\": \"thzmap-scene/1\", \"channels\": [{\"frequency_thz\": 0.5, "
        "\"relative_width\": 0.01}], \"materials\": {"
        "\"matte\": {\"reflectivity\": 0.1}, "
        "\"mirror\": {\"library\": \"aluminium\", \"reflection\": \"specular\"}, "
        "\"gloss\": {\"refractive_index\": [1.6, 0.02], \"reflection\": "
        "{\"model\": \"ward\", \"alpha_x\": 0.15, \"alpha_y\": 0.4}}}, "
        "\"objects\": [{\"name\": \"o\", \"type\": \"solid\", \"material\": \"gloss\", "
        "\"temperature_k\": 300, \"shape\": {\"type\": \"box\", \"size_m\": [1, 1, 1]}}], "
        "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], \"look_at_m\": [0, 0, 0], "
        "\"fov_deg\": 40, \"resolution\": [8, 8]}]}";
    thz_error err = {0};
    thz_scene *scene = NULL;
    if (thz_scene_load_string(json, NULL, "reflection.json", &scene, &err) != THZ_OK) {
        CHECK(0, "scene refused: %s", err.message);
        return;
    }
    static const struct {
        const char *name, *reflection;
        double ax, ay;
    } want[] = {
        {"matte", "diffuse", 0, 0}, {"mirror", "specular", 0, 0}, {"gloss", "ward", 0.15, 0.4}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        thz_material_info m;
        CHECK(thz_scene_material(scene, i, &m) == THZ_OK, "material %zu", i);
        CHECK(m.name && strcmp(m.name, want[i].name) == 0, "material %zu is %s", i, m.name);
        CHECK(m.reflection && strcmp(m.reflection, want[i].reflection) == 0, "%s: reflection %s",
              want[i].name, m.reflection ? m.reflection : "(null)");
        CHECK(m.ward_alpha_x == want[i].ax && m.ward_alpha_y == want[i].ay, "%s: alpha %g, %g",
              want[i].name, m.ward_alpha_x, m.ward_alpha_y);
    }
    thz_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    thz_error err = {0};
    thz_library *lib = NULL;
    REQUIRE_OK(thz_library_load(&lib, &err), &err);
    size_t n = thz_library_count(lib);
    CHECK(n >= 25, "%zu entries", n);
    for (size_t i = 0; i < n; i++) {
        thz_library_material_info info;
        thz_library_get_info(lib, i, &info);
        CHECK(info.name && info.source && strlen(info.source) > 10, "entry %zu", i);
        CHECK(info.model && info.basis && info.description && info.note, "entry %zu", i);
    }
    size_t w = 0;
    REQUIRE_OK(thz_library_find(lib, "water", &w, &err), &err);
    /* Liebe, Hufford & Manabe 1991 at 298.15 K, f in GHz */
    double th = 1.0 - 300.0 / 298.15, e0 = 77.66 - 103.3 * th, e1 = 0.0671 * e0;
    double e2 = 3.52 + 7.52 * th, f1 = 20.2 + 146.4 * th + 316.0 * th * th, f2 = 39.8 * f1;
    double complex eps =
        e2 + (e1 - e2) / (1.0 - I * 1000.0 / f2) + (e0 - e1) / (1.0 - I * 1000.0 / f1);
    double complex nk = csqrt(eps);
    thz_library_optics o;
    thz_library_optics_at(lib, w, 1e12, &o);
    CHECK(fabs(o.n - creal(nk)) < 1e-4 * creal(nk), "water n %g, Liebe %g", o.n, creal(nk));
    CHECK(fabs(o.k - cimag(nk)) < 1e-4 * cimag(nk), "water k %g, Liebe %g", o.k, cimag(nk));
    CHECK(fabs(o.eps_real - (o.n * o.n - o.k * o.k)) < 1e-9, "eps'");
    CHECK(fabs(o.eps_imag - 2 * o.n * o.k) < 1e-9, "eps''");
    double complex r = (nk - 1.0) / (nk + 1.0);
    CHECK(fabs(o.normal_reflectance - creal(r * conj(r))) < 1e-4, "R %g", o.normal_reflectance);
    CHECK(fabs(o.attenuation_per_m - 4 * M_PI * o.k * 1e12 / 299792458.0) <
              1e-6 * o.attenuation_per_m,
          "alpha %g", o.attenuation_per_m);
    size_t c = 0;
    REQUIRE_OK(thz_library_find(lib, "concrete", &c, &err), &err);
    thz_library_material_info info;
    thz_library_get_info(lib, c, &info);
    CHECK(strcmp(info.model, "itu-p2040") == 0, "%s", info.model);
    CHECK(info.n_data_ranges == 2, "%zu rows", info.n_data_ranges);
    double lo = 0, hi = 0;
    thz_library_get_range(lib, c, 1, &lo, &hi);
    CHECK(fabs(lo - 0.11) < 1e-12 && fabs(hi - 0.33) < 1e-12, "%g to %g THz", lo, hi);
    /* the data's whole range: from the first row's start to the last row's end (concrete's
     * rows: 0.001 to 0.1 and 0.11 to 0.33 THz, as thzmap materials lists them) */
    CHECK(info.has_data_range && fabs(info.data_from_thz - 0.001) < 1e-12 &&
              fabs(info.data_to_thz - 0.33) < 1e-12,
          "data range %d: %g to %g THz", info.has_data_range, info.data_from_thz, info.data_to_thz);
    CHECK(thz_library_in_range(lib, c, 0.2e12) && !thz_library_in_range(lib, c, 0.105e12) &&
              !thz_library_in_range(lib, c, 1e12),
          "P.2040 coverage");
    size_t none = 0;
    CHECK(thz_library_find(lib, "unobtainium", &none, &err) == THZ_ERR_INPUT, "unknown name");
    CHECK(strstr(err.message, "unobtainium") && strstr(err.message, "water"), "%s", err.message);
    thz_library_destroy(lib);
    check_scene_reflection();
    return test_failures ? 1 : 0;
}
