/* Fuzzes the scene loader (src/scene/load*.c and what it calls: the checks, the
 * primitives, the CSV and mesh readers, the atmosphere models): the input is the JSON
 * text of a scene whose relative file names resolve in tests/fuzz/files/ (materials
 * and atmosphere tables, small meshes); the `lines` and `itu-p676` atmospheres read the
 * small catalogues of tests/fuzz/data/ so that each input costs milliseconds.
 */
#include <jansson.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "scene/scene.h"
#include "scene/scene_hash.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_use_fixture_data();
    return 0;
}

/* Scenes whose load is slow by design, not by a defect: the work they ask for is within
 * the scene format's limits but takes more than libFuzzer's 1 s under the sanitizers.
 * They are open findings of issue 20 (docs/reliability.md, "Fuzzing"), skipped here so
 * that each run looks for new ones: spheres, cylinders and disks of more than 150 000
 * triangles in all (a sphere of 6 subdivisions has 81 920: 0.3 s), more than 64 channels
 * from a range (each tabulates the atmosphere), and an atmosphere below 300 hPa (narrow
 * lines: up to 4e6 grid points per channel). */
static double number_or(const json_t *object, const char *key, double dflt)
{
    const json_t *v = json_object_get(object, key);
    return json_is_number(v) ? json_number_value(v) : dflt;
}

static bool asks_for_slow_work(const json_t *v, double *triangles)
{
    if (json_is_array(v)) {
        for (size_t i = 0; i < json_array_size(v); i++)
            if (asks_for_slow_work(json_array_get(v, i), triangles))
                return true;
        return false;
    }
    if (!json_is_object(v))
        return false;
    const char *type = json_string_value(json_object_get(v, "type"));
    if (type && strcmp(type, "sphere") == 0)
        *triangles += 20.0 * pow(4.0, fmin(fmax(number_or(v, "subdivisions", 4), 0), 8));
    else if (type && (strcmp(type, "cylinder") == 0 || strcmp(type, "disk") == 0))
        *triangles += 4.0 * number_or(v, "segments", 64);
    if (*triangles > 150000 || number_or(v, "count", 0) > 64 ||
        number_or(v, "pressure_hpa", 1013) < 300)
        return true;
    for (void *it = json_object_iter((json_t *)v); it; it = json_object_iter_next((json_t *)v, it))
        if (asks_for_slow_work(json_object_iter_value(it), triangles))
            return true;
    return false;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
    json_t *doc = json_loads(text, 0, NULL);
    double triangles = 0.0;
    bool skip = doc && asks_for_slow_work(doc, &triangles);
    json_decref(doc);
    if (skip) {
        free(text);
        return 0;
    }
    thz_scene *scene = NULL;
    thz_error err = {0};
    thz_status st = scene_load_string(text, FUZZ_DIR "/files", "fuzz.json", &scene, &err);
    if (st == THZ_OK) {
        if (!scene)
            abort();
        scene_hash h;
        scene_hash_compute(scene, &h);
    } else {
        fuzz_report(err.message);
        if (!err.message[0] || scene)
            abort();
    }
    scene_destroy(scene);
    free(text);
    return 0;
}
