/* simulate.c: the thzmap C API in one page. Simulates a scene in memory and prints, for
 * each object the first sensor sees, its mean brightness temperature per channel; with
 * OUTDIR, also writes the files `thzmap simulate` would.
 *
 *   cc simulate.c $(pkg-config --cflags --libs thzmap) -o simulate
 *   ./simulate SCENE.json [PHOTONS_PER_CHANNEL [OUTDIR]]
 */
#include <stdio.h>
#include <stdlib.h>

#include <thzmap/thzmap.h>

/* Called on this thread between batches of work; returning non-zero would cancel. */
static int show_progress(void *user, const thz_progress *p)
{
    (void)user;
    if (p->total > 0 && p->done == p->total && p->stage[0] == 'p') /* "photons" */
        fprintf(stderr, "channel %zu/%zu: %llu photons fired\n", p->channel + 1, p->n_channels,
                (unsigned long long)p->done);
    return 0;
}

static void show_warning(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "warning: %s\n", message);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s SCENE.json [PHOTONS_PER_CHANNEL [OUTDIR]]\n", argv[0]);
        return 2;
    }
    thz_error err = {0};
    thz_scene *scene = NULL;
    thz_context *ctx = NULL;
    thz_run *run = NULL;
    thz_status st = thz_scene_load(argv[1], &scene, &err);
    if (st == THZ_OK && !(ctx = thz_context_create()))
        st = THZ_ERR_NOMEM;
    if (st != THZ_OK)
        goto done;
    thz_context_set_progress(ctx, show_progress, NULL);
    thz_context_set_warning(ctx, show_warning, NULL);

    thz_run_settings settings;
    thz_run_settings_init(&settings);   /* everything as the scene says, but: */
    settings.integrator = "photon-map"; /* the paper's method (path would fire no photons) */
    settings.photons_per_channel = argc > 2 ? strtoull(argv[2], NULL, 10) : 100000;
    st = thz_simulate(ctx, scene, &settings, &run, &err);
    if (st != THZ_OK)
        goto done;

    const thz_image *image = thz_run_image(run, 0); /* owned by the run */
    size_t pixels = (size_t)thz_image_columns(image) * thz_image_rows(image), n_channels = 0;
    const float *tb = thz_image_plane(image, THZ_PLANE_BRIGHTNESS_TEMPERATURE, &n_channels);
    const float *object_id = thz_image_plane(image, THZ_PLANE_OBJECT_ID, NULL);
    printf("sensor %s, mean brightness temperature (K) per channel:\n",
           thz_image_sensor_name(image));
    for (size_t o = 0; o < thz_scene_object_count(scene); o++) {
        thz_object_info object;
        thz_scene_object(scene, o, &object);
        size_t seen = 0;
        for (size_t p = 0; p < pixels; p++)
            seen += object_id[p] == (float)o;
        if (seen == 0)
            continue;
        printf("  %-14s (%5zu pixels)", object.name, seen);
        for (size_t c = 0; c < n_channels; c++) {
            double sum = 0.0;
            for (size_t p = 0; p < pixels; p++) /* cubes are band-sequential */
                if (object_id[p] == (float)o)
                    sum += tb[c * pixels + p];
            printf(" %8.2f", sum / (double)seen);
        }
        printf("\n");
    }
    if (argc > 3)
        st = thz_run_write(ctx, run, argv[3], NULL, &err); /* all or nothing */
done:
    if (st != THZ_OK)
        fprintf(stderr, "%s: %s\n", argv[0], err.message[0] ? err.message : thz_status_name(st));
    thz_run_destroy(run);
    thz_context_destroy(ctx);
    thz_scene_destroy(scene);
    return st == THZ_OK ? 0 : st == THZ_ERR_INPUT ? 2 : 1;
}
