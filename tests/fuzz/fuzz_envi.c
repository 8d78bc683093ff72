/* Fuzzes the ENVI cube reader (src/io/envi_read.c through thz_cube_read, as `thzmap
 * classify` and the web server's /api/cube, /api/pixel and /api/diff read cubes): the
 * input is a header's text, then (after the line "--img--") the raw image file; without
 * that line the image is empty. A cube read must keep analysis.h's promises: at least
 * one pixel and band, data of columns x rows x bands values, a `wavelength` list of one
 * value per band, every object name a string; a refusal has a message and leaves no cube.
 */
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "thzmap/thzmap.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

static volatile float sink;

static void check_cube(const thz_cube *c)
{
    size_t n = (size_t)thz_cube_columns(c) * thz_cube_rows(c) * thz_cube_bands(c);
    const float *data = thz_cube_data(c);
    if (n == 0 || !data)
        abort();
    sink = data[0] + data[n - 1]; /* every value is there (ASan checks the last) */
    const double *ghz = thz_cube_wavelength_ghz(c);
    if (ghz) /* one per band */
        sink += (float)(ghz[0] + ghz[thz_cube_bands(c) - 1]);
    size_t names = thz_cube_object_name_count(c);
    for (size_t i = 0; i < names; i++)
        if (!thz_cube_object_name(c, i))
            abort();
    if (thz_cube_object_name(c, names))
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char sep[] = "\n--img--\n";
    const uint8_t *img = NULL;
    for (size_t i = 0; i + sizeof sep - 1 <= size && !img; i++)
        if (memcmp(data + i, sep, sizeof sep - 1) == 0)
            img = data + i + sizeof sep - 1;
    size_t hdr_size = img ? (size_t)(img - data) - (sizeof sep - 2) : size; /* keeps the '\n' */
    size_t img_size = img ? size - (size_t)(img - data) : 0;
    fuzz_temp_file("cube.hdr", data, hdr_size);
    const char *path = fuzz_temp_file("cube.img", img ? img : data, img_size);
    char dir[4096];
    size_t len = strlen(path) - strlen("/cube.img");
    memcpy(dir, path, len);
    dir[len] = '\0';

    thz_cube *cube = NULL;
    thz_error err = {0};
    thz_status st = thz_cube_read(dir, "cube", &cube, &err);
    if (st == THZ_OK) {
        if (!cube)
            abort();
        check_cube(cube);
    } else {
        fuzz_report(err.message);
        if (!err.message[0] || cube)
            abort(); /* a refusal says why and leaves no cube */
    }
    thz_cube_destroy(cube);
    return 0;
}
