/* load_scene: the smallest program on libthzmap. Loads and validates a scene file
 * through the public API alone and reports the library's verdict.
 *
 *   cc load_scene.c $(pkg-config --cflags --libs thzmap) -o load_scene
 *   ./load_scene SCENE.json
 *
 * Exit status as thzmap's: 0 the scene is valid, 2 bad usage or bad input (the message
 * names the file and the line:column or JSON path), 1 anything else. */
#include <stdio.h>

#include <thzmap/thzmap.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: load_scene SCENE.json\n");
        return 2;
    }
    printf("libthzmap %s\n", thz_version());

    thz_scene *scene = NULL;
    thz_error err = {0};
    thz_status st = thz_scene_load(argv[1], &scene, &err);
    if (st != THZ_OK) {
        fprintf(stderr, "load_scene: %s: %s\n", thz_status_name(st), err.message);
        return st == THZ_ERR_INPUT ? 2 : 1;
    }
    printf("%s: valid scene\n", argv[1]);
    thz_scene_destroy(scene);
    return 0;
}
