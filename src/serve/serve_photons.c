/* GET /api/photons and /api/photons/info: a saved photon map (.thzpm) read through the
 * library (thz_photons_load, which needs the scene it was made from) and sent for the
 * point cloud of the paper's Fig. 3: as float32 records (format=records, the default), or
 * as the page draws them (format=points: positions, then directions in 8 bits per axis,
 * 15 bytes a photon instead of 32). The last channel read is kept (one channel of one map). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "serve_internal.h"

#define SERVE_PHOTON_FLOATS 8 /* x y z dx dy dz power object */
#define SERVE_PHOTON_CHUNK 65536

struct serve_photon_cache {
    char map_path[PATH_MAX]; /* realpath of the .thzpm */
    char scene_path[PATH_MAX];
    struct timespec mtime;
    off_t size;
    size_t channel; /* the one channel read (thz_photons_load_channel) */
    thz_scene *scene;
    thz_photons *photons;
};

void serve_photons_free(serve *s)
{
    if (!s->photons)
        return;
    thz_photons_destroy(s->photons->photons);
    thz_scene_destroy(s->photons->scene);
    free(s->photons);
    s->photons = NULL;
}

/* The scene of the map at `map` (REL path checked): the `scene` argument, else the
 * scene.path of the summary.json beside the map. Into out; false after replying. */
static bool serve_photon_scene(serve_request *r, const char *map, char *out, enum MHD_Result *ret)
{
    if (serve_arg(r, "scene"))
        return serve_path_arg(r, "scene", true, out, ret);
    char summary[PATH_MAX + 16];
    snprintf(summary, sizeof summary, "%s", map);
    char *slash = strrchr(summary, '/');
    snprintf(slash ? slash + 1 : summary,
             sizeof summary - (size_t)(slash ? slash + 1 - summary : 0), "summary.json");
    json_t *o = serve_read_json(summary);
    const char *rel = json_string_value(json_object_get(json_object_get(o, "scene"), "path"));
    serve_path_status st = rel ? serve_path(r->s, rel, true, out) : SERVE_PATH_MISSING;
    json_decref(o);
    if (st != SERVE_PATH_OK)
        *ret = serve_reply_error(r, 400,
                                 "%s: the scene it was made from is not known (no summary.json "
                                 "beside it naming a scene under the root): give scene=REL",
                                 map);
    return st == SERVE_PATH_OK;
}

/* Channel `channel` of the photon map of the request (path=, scene=), read alone
 * (thz_photons_load_channel: the view needs neither the other channels nor an index of
 * theirs) or from the cache; NULL after replying (404 for a channel the scene does not
 * have). The caller holds s->photon_lock. */
static struct serve_photon_cache *serve_photon_map(serve_request *r, size_t channel,
                                                   enum MHD_Result *ret)
{
    serve *s = r->s;
    char map[PATH_MAX], scene[PATH_MAX], map_real[PATH_MAX], scene_real[PATH_MAX];
    if (!serve_path_arg(r, "path", true, map, ret) || !serve_photon_scene(r, map, scene, ret))
        return NULL;
    struct stat st;
    if (!realpath(map, map_real) || !realpath(scene, scene_real) || stat(map_real, &st) != 0) {
        *ret = serve_reply_error(r, 404, "%s: not found", map);
        return NULL;
    }
    struct serve_photon_cache *c = s->photons;
    if (c && strcmp(c->map_path, map_real) == 0 && strcmp(c->scene_path, scene_real) == 0 &&
        c->size == st.st_size && c->mtime.tv_sec == st.st_mtim.tv_sec &&
        c->mtime.tv_nsec == st.st_mtim.tv_nsec && c->channel == channel)
        return c;
    serve_photons_free(s);
    c = calloc(1, sizeof *c);
    thz_context *ctx = thz_context_create();
    thz_error err = {0};
    thz_status status = c && ctx ? THZ_OK : THZ_ERR_NOMEM;
    if (status == THZ_OK)
        status = thz_scene_load_within(scene, s->root, &c->scene, &err);
    bool no_channel = status == THZ_OK && channel >= thz_scene_channel_count(c->scene);
    if (status == THZ_OK && !no_channel)
        status = thz_photons_load_channel(ctx, c->scene, map, channel, &c->photons, &err);
    thz_context_destroy(ctx);
    if (no_channel) {
        thz_scene_destroy(c->scene);
        free(c);
        *ret = serve_reply_error(r, 404, "no channel %zu in the scene", channel);
        return NULL;
    }
    if (status != THZ_OK) {
        if (c)
            thz_scene_destroy(c->scene);
        free(c);
        *ret = err.message[0] ? serve_reply_thz_error(r, &err)
                              : serve_reply_error(r, 500, "out of memory");
        return NULL;
    }
    snprintf(c->map_path, sizeof c->map_path, "%s", map_real);
    snprintf(c->scene_path, sizeof c->scene_path, "%s", scene_real);
    c->mtime = st.st_mtim;
    c->size = st.st_size;
    c->channel = channel;
    s->photons = c;
    return c;
}

enum MHD_Result serve_photons_info(serve_request *r)
{
    enum MHD_Result ret = MHD_NO;
    pthread_mutex_lock(&r->s->photon_lock);
    struct serve_photon_cache *c = serve_photon_map(r, 0, &ret);
    if (c) {
        json_t *channels = json_array(), *objects = json_array();
        for (size_t i = 0; i < thz_scene_channel_count(c->scene); i++) {
            thz_channel_info ch;
            thz_scene_channel(c->scene, i, &ch);
            thz_photon_stats ps; /* read for every channel; only channel 0's map is built */
            thz_photons_stats(c->photons, i, &ps);
            json_array_append_new(channels,
                                  json_pack("{s:s, s:f, s:I}", "name", ch.name, "centre_thz",
                                            ch.frequency_thz, "photons", (json_int_t)ps.stored));
        }
        for (size_t i = 0; i < thz_scene_object_count(c->scene); i++) {
            thz_object_info o;
            thz_scene_object(c->scene, i, &o);
            json_array_append_new(objects, json_string(o.name));
        }
        ret = serve_reply_json(r, 200,
                               json_pack("{s:o, s:o}", "channels", channels, "objects", objects));
    }
    pthread_mutex_unlock(&r->s->photon_lock);
    return ret;
}

/* A unit vector's component as a signed normalised byte (-127..127 for -1..1). */
static int8_t serve_snorm8(float v)
{
    float x = v < -1.0f ? -1.0f : v > 1.0f ? 1.0f : v;
    return (int8_t)lrintf(127.0f * x);
}

/* Copies the photons of channel ch (of object `object`, or all when it is -1) into out,
 * evenly strided over the `total` selected: min(total, max) of them, which it returns.
 * Records: 8 floats each. Points: 3 floats each for the `max` positions, then 3 bytes of
 * direction each (serve_snorm8) from byte 12 * max on. */
static size_t serve_photon_copy(const thz_photons *ph, size_t ch, long object, size_t total,
                                size_t max, bool points, float *out, thz_photon_point *buf)
{
    int8_t *dirs = (int8_t *)(out + 3 * (total < max ? total : max));
    size_t count = thz_photons_count(ph, ch), k = 0, taken = 0;
    for (size_t first = 0; first < count && taken < max; first += SERVE_PHOTON_CHUNK) {
        size_t n = thz_photons_points(ph, ch, first, SERVE_PHOTON_CHUNK, buf);
        for (size_t i = 0; i < n && taken < max; i++) {
            if (object >= 0 && buf[i].object != (uint32_t)object)
                continue;
            /* floor(k max / total) rises max times over the selection: take those k */
            bool take = total <= max || (k + 1) * max / total != k * max / total;
            k++;
            if (!take)
                continue;
            if (points) {
                memcpy(out + 3 * taken, buf[i].position_m, 3 * sizeof *out);
                for (int a = 0; a < 3; a++)
                    dirs[3 * taken + (size_t)a] = serve_snorm8(buf[i].direction[a]);
                taken++;
                continue;
            }
            float *o = out + SERVE_PHOTON_FLOATS * taken++;
            memcpy(o, buf[i].position_m, 3 * sizeof *o);
            memcpy(o + 3, buf[i].direction, 3 * sizeof *o);
            o[6] = buf[i].power_w_per_hz;
            o[7] = (float)buf[i].object;
        }
    }
    return taken;
}

enum MHD_Result serve_photons(serve_request *r)
{
    enum MHD_Result ret = MHD_NO;
    const char *ch_arg = serve_arg(r, "channel"), *obj = serve_arg(r, "object");
    const char *max_arg = serve_arg(r, "max"), *format = serve_arg(r, "format");
    bool points = format && strcmp(format, "points") == 0;
    if (format && !points && strcmp(format, "records") != 0)
        return serve_reply_error(r, 400, "format=%s: expected records or points", format);
    char *end = NULL;
    long ch = ch_arg ? strtol(ch_arg, &end, 10) : -1;
    if (!ch_arg || !*ch_arg || *end || ch < 0)
        return serve_reply_error(r, 400, "expected channel=C (0-based)");
    long long max = 1000000;
    if (max_arg && ((max = strtoll(max_arg, &end, 10)) < 1 || *end || max > 20000000))
        return serve_reply_error(r, 400, "max=%s: expected 1 to 20000000", max_arg);
    pthread_mutex_lock(&r->s->photon_lock);
    struct serve_photon_cache *c = serve_photon_map(r, (size_t)ch, &ret);
    if (!c) {
        pthread_mutex_unlock(&r->s->photon_lock);
        return ret;
    }
    long object = obj ? thz_scene_object_index(c->scene, obj) : -1;
    if (obj && object < 0) {
        pthread_mutex_unlock(&r->s->photon_lock);
        return serve_reply_error(r, 404, "no object '%s' in the scene", obj);
    }
    thz_photon_point *buf = malloc(SERVE_PHOTON_CHUNK * sizeof *buf);
    size_t total = 0, count = thz_photons_count(c->photons, (size_t)ch);
    for (size_t first = 0; buf && object >= 0 && first < count; first += SERVE_PHOTON_CHUNK) {
        size_t n = thz_photons_points(c->photons, (size_t)ch, first, SERVE_PHOTON_CHUNK, buf);
        for (size_t i = 0; i < n; i++)
            total += buf[i].object == (uint32_t)object;
    }
    if (object < 0)
        total = count;
    size_t want = total < (size_t)max ? total : (size_t)max;
    size_t bytes = points ? 15 * want : SERVE_PHOTON_FLOATS * want * sizeof(float);
    float *out = malloc(bytes + 1);
    size_t taken = buf && out ? serve_photon_copy(c->photons, (size_t)ch, object, total,
                                                  (size_t)max, points, out, buf)
                              : 0;
    pthread_mutex_unlock(&r->s->photon_lock);
    free(buf);
    if (!out || taken != want) {
        free(out);
        return serve_reply_error(r, 500, "out of memory");
    }
    char sent[32], all[32];
    snprintf(sent, sizeof sent, "%zu", taken);
    snprintf(all, sizeof all, "%zu", total);
    const char *headers[] = {"X-Thzmap-Photons", sent, "X-Thzmap-Photons-Total", all, NULL};
    return serve_reply_binary(r, out, bytes, headers);
}
