/* Photons shared between frames (the paper's point of a photon map): frames whose scene
 * differs from the previous frame's only in "sensors" render from the photons of the
 * first frame of that run of frames (its base) instead of firing again. The photon
 * phase reads no sensor, so those photons are what each frame would fire itself; the
 * base is fixed by the sequence alone, so a resumed batch that starts inside such a run
 * fires the base's scene again with the same seed and gets the same maps.
 */
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "api/api.h"
#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"

/* Frame f's scene text without its "sensors" (NULL when out of memory). */
static char *reuse_scene_without_sensors(const thz_sequence *seq, size_t f)
{
    json_t *root = json_loads(seq->frame_json[f], 0, NULL);
    json_object_del(root, "sensors");
    char *text =
        root ? json_dumps(root, JSON_COMPACT | JSON_SORT_KEYS | JSON_REAL_PRECISION(17)) : NULL;
    json_decref(root);
    return text;
}

thz_status batch_photon_bases(const thz_sequence *seq, size_t *base, thz_error *err)
{
    char *prev = NULL;
    for (size_t f = 0; f < seq->n_frames; f++) {
        char *text = reuse_scene_without_sensors(seq, f);
        if (!text) {
            free(prev);
            return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", seq->frame_dir[f]);
        }
        /* the same text names the same files only from the same directory */
        int same_dir = f > 0 && !strcmp(seq->scene_dirs[batch_frame_scene(seq, f)],
                                        seq->scene_dirs[batch_frame_scene(seq, f - 1)]);
        base[f] = prev && same_dir && !strcmp(prev, text) ? base[f - 1] : f;
        free(prev);
        prev = text;
    }
    free(prev);
    return THZ_OK;
}

void batch_photon_cache_clear(batch_photon_cache *c)
{
    thz_photons_destroy(c->fired);
    thz_run_destroy(c->run);
    thz_scene_destroy(c->scene);
    *c = (batch_photon_cache){.base = SIZE_MAX};
}

void batch_photon_cache_keep(batch_photon_cache *c, size_t base, thz_scene **scene, thz_run **run)
{
    batch_photon_cache_clear(c);
    c->base = base;
    c->scene = *scene;
    c->run = *run;
    *scene = NULL;
    *run = NULL;
}

/* Whether the cached base's photons are the ones `scene` would fire: the same fingerprint
 * of everything a photon map depends on (scene_hash.h; what render checks a map file
 * against). The two texts differ only in their sensors, but the sensors decide the air's
 * default temperature and background, the enclosure's around them (scene-format.md), so
 * a sensor moving into another enclosure changes the map. (Only the air state of the
 * itu-p676 and lines models was compared before: a constant or table model's emitting air
 * was reused at the first enclosure's temperature.) */
static bool reuse_fits(const thz_scene *scene, batch_photon_cache *c)
{
    if (!c->hashed) {
        scene_hash_compute(c->scene, &c->hash);
        c->hashed = true;
    }
    return scene_hash_fit(&c->hash, c->scene->n_objects, c->scene->n_channels, scene, "", "",
                          NULL) == THZ_OK;
}

thz_status batch_render_reused(thz_context *ctx, const thz_sequence *seq, batch_photon_cache *c,
                               size_t base, const thz_scene *scene, thz_run **run, int *reused,
                               int *fired, thz_error *err)
{
    *fired = 0;
    *reused = 0;
    if (c->base != base) {
        batch_photon_cache_clear(c);
        thz_status st = thz_sequence_frame_scene(seq, base, &c->scene, err);
        if (st == THZ_OK)
            st = thz_photons_fire(ctx, c->scene, NULL, &c->fired, err);
        if (st != THZ_OK) {
            batch_photon_cache_clear(c);
            return st;
        }
        c->base = base;
        *fired = 1;
    }
    thz_run_settings settings;
    thz_run_settings_init(&settings);
    if (!reuse_fits(scene, c)) {
        *fired = 1; /* the sensors moved into another enclosure: fire this frame's own */
        return thz_simulate(ctx, scene, &settings, run, err);
    }
    *reused = 1;
    const thz_photons *kept = c->fired ? c->fired : thz_run_photons(c->run);
    if (!kept)
        return thz_error_set(err, THZ_ERR_INPUT, "frame %zu kept no photons", base);
    /* the base's maps, for this frame's scene handle: thz_render_run takes them, as it
     * checks what reuse_fits did */
    return thz_render_run(ctx, scene, kept, -1, &settings, run, err);
}
