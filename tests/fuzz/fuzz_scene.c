/* Fuzzes the scene loader (src/scene/load*.c and what it calls: the checks, the
 * primitives, the CSV and mesh readers, the atmosphere models): the input is the JSON
 * text of a scene whose relative file names resolve in tests/fuzz/files/ (materials
 * and atmosphere tables, small meshes); the `lines` and `itu-p676` atmospheres read the
 * small catalogues of tests/fuzz/data/ so that each input costs milliseconds.
 */
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
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
