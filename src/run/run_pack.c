/* A finished run as bytes and back (run_pack.h): a header, then every field run_write
 * and the totals read, in a fixed order, each number in its native representation. */
#include "run/run_pack.h"

#include <limits.h>
#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/threads.h"

#define PACK_MAGIC "THZRUN01"

/* A growing byte buffer; `failed` once an allocation failed (every later put is void). */
typedef struct pack_out {
    uint8_t *data;
    size_t size, cap;
    bool failed;
} pack_out;

static void put(pack_out *o, const void *p, size_t n)
{
    if (o->failed || n == 0)
        return;
    if (n > SIZE_MAX - o->size) {
        o->failed = true;
        return;
    }
    if (o->size + n > o->cap) {
        size_t cap = o->cap ? o->cap : 4096;
        while (cap < o->size + n)
            cap = cap <= SIZE_MAX / 2 ? 2 * cap : o->size + n;
        uint8_t *data = realloc(o->data, cap);
        if (!data) {
            o->failed = true;
            return;
        }
        o->data = data;
        o->cap = cap;
    }
    memcpy(o->data + o->size, p, n);
    o->size += n;
}

static void put_u64(pack_out *o, uint64_t v)
{
    put(o, &v, sizeof v);
}

static void put_f64(pack_out *o, double v)
{
    put(o, &v, sizeof v);
}

/* n values of `size` bytes each (a plane, an array of plain-data structs). */
static void put_array(pack_out *o, const void *p, size_t n, size_t size)
{
    if (n > 0 && size > SIZE_MAX / n)
        o->failed = true;
    else
        put(o, p, n * size);
}

/* The cursor of run_unpack; `bad` once the bytes ran out or disagreed. */
typedef struct pack_in {
    const uint8_t *p;
    size_t left;
    bool bad;
} pack_in;

static void get(pack_in *in, void *dst, size_t n)
{
    if (in->bad || n > in->left) {
        in->bad = true;
        memset(dst, 0, n);
        return;
    }
    memcpy(dst, in->p, n);
    in->p += n;
    in->left -= n;
}

static uint64_t get_u64(pack_in *in)
{
    uint64_t v;
    get(in, &v, sizeof v);
    return v;
}

static double get_f64(pack_in *in)
{
    double v;
    get(in, &v, sizeof v);
    return v;
}

/* n values of `size` bytes into a new array (NULL and in->bad when short or out of
 * memory; *nomem says which). */
static void *get_array(pack_in *in, size_t n, size_t size, bool *nomem)
{
    if (in->bad || (n > 0 && size > SIZE_MAX / n) || n * size > in->left) {
        in->bad = true;
        return NULL;
    }
    void *a = thz_malloc_array(n ? n : 1, size);
    if (!a) {
        in->bad = *nomem = true;
        return NULL;
    }
    get(in, a, n * size);
    return a;
}

/* A cube of n_channels bands, or one band, or 3 (visual): values per pixel. */
static void pack_image(pack_out *o, const sensor_images *img)
{
    size_t px = (size_t)img->columns * img->rows, cube = px * img->n_channels;
    put_u64(o, img->columns);
    put_u64(o, img->rows);
    put_u64(o, img->n_channels);
    put_u64(o, img->radiance_stderr ? 1u : 0u);
    put_u64(o, img->measured_radiance ? 1u : 0u);
    put_u64(o, img->noise_seed);
    put_array(o, img->radiance, cube, sizeof(float));
    if (img->radiance_stderr)
        put_array(o, img->radiance_stderr, cube, sizeof(float));
    put_array(o, img->power, cube, sizeof(float));
    put_array(o, img->brightness_temperature, cube, sizeof(float));
    put_array(o, img->normalized, cube, sizeof(float));
    put_array(o, img->temperature_k, px, sizeof(float));
    put_array(o, img->distance_m, px, sizeof(float));
    put_array(o, img->object_id, px, sizeof(int32_t));
    put_array(o, img->visual_rgb, px, 3 * sizeof(float));
    if (img->measured_radiance) {
        put_array(o, img->measured_radiance, cube, sizeof(float));
        put_array(o, img->measured_brightness_temperature, cube, sizeof(float));
    }
}

static void pack_result(pack_out *o, const run_result *r)
{
    put_u64(o, r->n_channels);
    put_u64(o, r->n_sensors);
    put_u64(o, r->photons_fired);
    put_u64(o, r->photons_stored);
    put_u64(o, r->back_face_samples);
    put_u64(o, r->n_warnings);
    put_f64(o, r->worst_median_stderr_k);
    put_f64(o, r->worst_p95_stderr_k);
    put_u64(o, r->worst_object);
    put_u64(o, r->worst_object_channel);
    put_f64(o, r->worst_object_p95_stderr_k);
    put_u64(o, r->max_passes);
    put_f64(o, r->seconds);
}

/* Per-object arrays hold at least one entry (run_state_init). */
static size_t pack_objects(const thz_scene *scene)
{
    return scene->n_objects ? scene->n_objects : 1;
}

thz_status run_pack(const run_state *rs, uint8_t **data, size_t *size, thz_error *err)
{
    *data = NULL;
    *size = 0;
    const thz_scene *sc = rs->scene;
    size_t nc = sc->n_channels, no = pack_objects(sc);
    pack_out o = {0};
    put(&o, PACK_MAGIC, 8);
    put_u64(&o, sizeof(photon_stats));
    put_u64(&o, sizeof(run_noise));
    put_u64(&o, nc);
    put_u64(&o, sc->n_sensors);
    put_u64(&o, sc->n_objects);
    put_u64(&o, strcmp(rs->command, "render") == 0 ? 1u : 0u);
    put_u64(&o, rs->seed);
    put_u64(&o, rs->photons_per_channel);
    /* the options summary.json reports; the threads this process ran with */
    int threads = thz_threads_or_all(rs->opt->threads);
    put_u64(&o, (uint64_t)threads);
    put_f64(&o, rs->opt->seconds_load);
    put_f64(&o, rs->opt->target_noise_k);
    put_f64(&o, rs->opt->max_seconds);
    put_f64(&o, rs->target_noise_k);
    put_f64(&o, rs->max_seconds);
    put_u64(&o, rs->memory_bytes);
    put_f64(&o, rs->seconds_accel);
    put_f64(&o, rs->seconds_photons);
    put_f64(&o, rs->seconds_render);
    put_f64(&o, rs->seconds_output);
    put_u64(&o, rs->n_selected);
    for (size_t i = 0; i < rs->n_selected; i++) {
        put_u64(&o, rs->selected[i]);
        pack_image(&o, &rs->images[i]);
    }
    put_array(&o, rs->back_face, sc->n_sensors, sizeof *rs->back_face);
    put_array(&o, rs->stats, nc, sizeof *rs->stats);
    put_array(&o, rs->noise, nc, sizeof *rs->noise);
    put_array(&o, rs->object_noise, nc * no, sizeof *rs->object_noise);
    put_array(&o, rs->passes, nc, sizeof *rs->passes);
    put_array(&o, rs->seconds_channel, nc, sizeof *rs->seconds_channel);
    put_u64(&o, rs->n_warnings);
    for (size_t i = 0; i < rs->n_warnings; i++) {
        size_t n = strlen(rs->warnings[i]);
        put_u64(&o, n);
        put(&o, rs->warnings[i], n);
    }
    pack_result(&o, &rs->result);
    if (o.failed) {
        free(o.data);
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory packing a run (%zu bytes so far)",
                             o.size);
    }
    *data = o.data;
    *size = o.size;
    return THZ_OK;
}

/* One image, checked against sensor s of the scene. */
static void unpack_image(pack_in *in, const thz_scene *scene, size_t s, sensor_images *img,
                         bool *nomem)
{
    const thz_sensor *sn = &scene->sensors[s];
    uint64_t columns = get_u64(in), rows = get_u64(in), nc = get_u64(in);
    uint64_t with_stderr = get_u64(in), measured = get_u64(in), noise_seed = get_u64(in);
    if (in->bad || columns != sn->columns || rows != sn->rows || nc != scene->n_channels ||
        with_stderr > 1 || measured > 1) {
        in->bad = true;
        return;
    }
    img->columns = sn->columns;
    img->rows = sn->rows;
    img->n_channels = scene->n_channels;
    img->noise_seed = noise_seed;
    size_t px = (size_t)img->columns * img->rows, cube = px * img->n_channels;
    img->radiance = get_array(in, cube, sizeof(float), nomem);
    if (with_stderr)
        img->radiance_stderr = get_array(in, cube, sizeof(float), nomem);
    img->power = get_array(in, cube, sizeof(float), nomem);
    img->brightness_temperature = get_array(in, cube, sizeof(float), nomem);
    img->normalized = get_array(in, cube, sizeof(float), nomem);
    img->temperature_k = get_array(in, px, sizeof(float), nomem);
    img->distance_m = get_array(in, px, sizeof(float), nomem);
    img->object_id = get_array(in, px, sizeof(int32_t), nomem);
    img->visual_rgb = get_array(in, px, 3 * sizeof(float), nomem);
    if (measured) {
        img->measured_radiance = get_array(in, cube, sizeof(float), nomem);
        img->measured_brightness_temperature = get_array(in, cube, sizeof(float), nomem);
    }
}

static void unpack_result(pack_in *in, run_result *r)
{
    r->n_channels = get_u64(in);
    r->n_sensors = get_u64(in);
    r->photons_fired = get_u64(in);
    r->photons_stored = get_u64(in);
    r->back_face_samples = get_u64(in);
    r->n_warnings = get_u64(in);
    r->worst_median_stderr_k = get_f64(in);
    r->worst_p95_stderr_k = get_f64(in);
    r->worst_object = get_u64(in);
    r->worst_object_channel = get_u64(in);
    r->worst_object_p95_stderr_k = get_f64(in);
    r->max_passes = (uint32_t)get_u64(in);
    r->seconds = get_f64(in);
}

/* The header: magic, the plain-data structs' sizes, the scene's counts. */
static bool unpack_header(pack_in *in, const thz_scene *sc)
{
    char magic[8];
    get(in, magic, sizeof magic);
    uint64_t v[5]; /* in the order run_pack puts them (an initialiser's order is not fixed) */
    for (size_t i = 0; i < 5; i++)
        v[i] = get_u64(in);
    return !in->bad && memcmp(magic, PACK_MAGIC, 8) == 0 && v[0] == sizeof(photon_stats) &&
           v[1] == sizeof(run_noise) && v[2] == sc->n_channels && v[3] == sc->n_sensors &&
           v[4] == sc->n_objects;
}

/* The warnings: a count, then each as its length and bytes. */
static void unpack_warnings(pack_in *in, run_state *rs, bool *nomem)
{
    uint64_t n = get_u64(in);
    if (in->bad || n > in->left / sizeof(uint64_t)) { /* each takes at least its length */
        in->bad = true;
        return;
    }
    rs->warnings = thz_calloc(n ? n : 1, sizeof *rs->warnings);
    if (!rs->warnings) {
        in->bad = *nomem = true;
        return;
    }
    for (; rs->n_warnings < n && !in->bad; rs->n_warnings++) {
        uint64_t len = get_u64(in);
        char *w = !in->bad && len < in->left ? thz_malloc_array(len + 1, 1) : NULL;
        if (!w) {
            *nomem = !in->bad && len < in->left;
            in->bad = true;
            return;
        }
        get(in, w, len);
        w[len] = '\0';
        rs->warnings[rs->n_warnings] = w;
    }
}

thz_status run_unpack(const thz_scene *scene, const void *data, size_t size, run_state *rs,
                      thz_error *err)
{
    memset(rs, 0, sizeof *rs);
    pack_in in = {.p = data, .left = size};
    bool nomem = false;
    if (!unpack_header(&in, scene))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "a packed run: not from this thzmap build or not for this scene");
    size_t nc = scene->n_channels, no = pack_objects(scene);
    rs->scene = scene;
    rs->opt = &rs->options;
    bool render = get_u64(&in) != 0;
    rs->command = render ? "render" : "simulate";
    rs->seed = get_u64(&in);
    rs->photons_per_channel = get_u64(&in);
    uint64_t threads = get_u64(&in);
    rs->options.threads = threads <= INT_MAX ? (int)threads : 0;
    rs->options.seconds_load = get_f64(&in);
    rs->options.target_noise_k = get_f64(&in);
    rs->options.max_seconds = get_f64(&in);
    rs->target_noise_k = get_f64(&in);
    rs->max_seconds = get_f64(&in);
    rs->memory_bytes = get_u64(&in);
    rs->seconds_accel = get_f64(&in);
    rs->seconds_photons = get_f64(&in);
    rs->seconds_render = get_f64(&in);
    rs->seconds_output = get_f64(&in);
    /* the source of the target is a static name: found again as the run found it */
    run_target_noise_k(scene, &rs->options, render, &rs->target_source);
    uint64_t n_selected = get_u64(&in);
    if (!in.bad && n_selected <= scene->n_sensors) {
        rs->selected = thz_calloc(scene->n_sensors ? scene->n_sensors : 1, sizeof *rs->selected);
        rs->images = thz_calloc(n_selected ? n_selected : 1, sizeof *rs->images);
        nomem = !rs->selected || !rs->images;
        in.bad |= nomem;
    } else {
        in.bad = true;
    }
    for (size_t i = 0; !in.bad && i < n_selected; i++) {
        uint64_t s = get_u64(&in);
        rs->n_selected = i + 1; /* run_state_fini frees images[0 .. i] */
        if (s >= scene->n_sensors) {
            in.bad = true;
            break;
        }
        rs->selected[i] = (size_t)s;
        unpack_image(&in, scene, rs->selected[i], &rs->images[i], &nomem);
    }
    rs->back_face = get_array(&in, scene->n_sensors, sizeof *rs->back_face, &nomem);
    rs->stats = get_array(&in, nc, sizeof *rs->stats, &nomem);
    rs->noise = get_array(&in, nc, sizeof *rs->noise, &nomem);
    rs->object_noise = get_array(&in, nc * no, sizeof *rs->object_noise, &nomem);
    rs->passes = get_array(&in, nc, sizeof *rs->passes, &nomem);
    rs->seconds_channel = get_array(&in, nc, sizeof *rs->seconds_channel, &nomem);
    unpack_warnings(&in, rs, &nomem);
    unpack_result(&in, &rs->result);
    if (in.bad || in.left != 0) {
        run_state_fini(rs);
        if (nomem)
            return thz_error_set(err, THZ_ERR_NOMEM, "out of memory unpacking a run");
        return thz_error_set(err, THZ_ERR_INPUT, "a packed run of %zu bytes is damaged", size);
    }
    return THZ_OK;
}
