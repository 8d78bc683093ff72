/* Fuzzes the mesh reader: the checks of src/scene/mesh_check*.c and the import through
 * assimp behind them (src/scene/mesh_import*.c). The input is written to a file whose
 * extension follows its content, as a user's file would be named: "ply" first → .ply,
 * "solid" first or 84 + 50 n bytes → .stl, anything else → .obj. A mesh that is accepted
 * is finalised and its winding checked, as the scene loader does.
 */
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "scene/mesh_import.h"
#include "scene/scene.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

static const char *name_for(const uint8_t *data, size_t size)
{
    if (size >= 3 && memcmp(data, "ply", 3) == 0)
        return "input.ply";
    if ((size >= 5 && memcmp(data, "solid", 5) == 0) || (size >= 84 && (size - 84) % 50 == 0))
        return "input.stl";
    return "input.obj";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_temp_file(name_for(data, size), data, size);
    thz_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    thz_error err = {0};
    thz_status st = mesh_import(path, NULL, &mesh, &err);
    if (st == THZ_OK) {
        if (mesh.n_triangles == 0)
            abort(); /* mesh_import.h: a file without triangles is refused */
        if (!mesh_finalize(&mesh))
            abort();
        mesh_defects d;
        (void)mesh_import_defects(&mesh, &d);
    } else {
        fuzz_report(err.message);
        if (!err.message[0])
            abort();
    }
    mesh_fini(&mesh);
    return 0;
}
