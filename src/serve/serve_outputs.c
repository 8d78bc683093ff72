/* The post-processor's endpoints: a run's output directory, its ENVI cubes (header
 * information and float32 data), one pixel's spectrum with its truth, and the A/B
 * difference of two runs. Cubes are read through the library (thz_cube_read) once and
 * kept (SERVE_CUBE_CACHE, least recently used out), keyed by path, size and mtime. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "serve_internal.h"

struct serve_cube_entry {
    char path[PATH_MAX]; /* realpath of the .hdr; "" when free */
    struct timespec mtime_hdr, mtime_img;
    off_t size_img;
    thz_cube *cube;
    uint64_t used;
};

void serve_cubes_free(serve *s)
{
    for (size_t i = 0; s->cubes && i < SERVE_CUBE_CACHE; i++)
        thz_cube_destroy(s->cubes[i].cube);
    free(s->cubes);
    s->cubes = NULL;
}

const thz_cube *serve_cube_get(serve *s, const char *hdr, thz_error *err)
{
    char real[PATH_MAX], img[PATH_MAX + 8];
    struct stat sh, si;
    size_t n = strlen(hdr);
    if (n < 5 || strcmp(hdr + n - 4, ".hdr") != 0 || !realpath(hdr, real) || stat(real, &sh) != 0) {
        /* the request's fault, not the server's: 400 */
        snprintf(err->message, sizeof err->message, "%s: no such ENVI header (.hdr)", hdr);
        err->status = THZ_ERR_INPUT;
        return NULL;
    }
    snprintf(img, sizeof img, "%.*s.img", (int)(strlen(real) - 4), real);
    if (stat(img, &si) != 0)
        si = (struct stat){0};
    if (!s->cubes && !(s->cubes = calloc(SERVE_CUBE_CACHE, sizeof *s->cubes))) {
        snprintf(err->message, sizeof err->message, "out of memory for the cube cache");
        err->status = THZ_ERR_NOMEM;
        return NULL;
    }
    serve_cube_entry *victim = &s->cubes[0];
    for (size_t i = 0; i < SERVE_CUBE_CACHE; i++) {
        serve_cube_entry *e = &s->cubes[i];
        if (e->cube && strcmp(e->path, real) == 0 && e->size_img == si.st_size &&
            e->mtime_img.tv_sec == si.st_mtim.tv_sec &&
            e->mtime_img.tv_nsec == si.st_mtim.tv_nsec &&
            e->mtime_hdr.tv_sec == sh.st_mtim.tv_sec &&
            e->mtime_hdr.tv_nsec == sh.st_mtim.tv_nsec) {
            e->used = ++s->cube_clock;
            return e->cube;
        }
        if (!e->cube || e->used < victim->used)
            victim = e;
        if (!e->cube)
            break;
    }
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", real);
    char *slash = strrchr(dir, '/');
    *slash = '\0';
    char stem[PATH_MAX];
    snprintf(stem, sizeof stem, "%.*s", (int)(strlen(slash + 1) - 4), slash + 1);
    thz_cube *cube = NULL;
    if (thz_cube_read(dir[0] ? dir : "/", stem, &cube, err) != THZ_OK) {
        /* the library names the file by its real path: name it relative to the root, as
         * every other answer does */
        size_t rn = strlen(s->root);
        if (strncmp(err->message, s->root, rn) == 0 && err->message[rn] == '/')
            memmove(err->message, err->message + rn + 1, strlen(err->message + rn + 1) + 1);
        return NULL;
    }
    thz_cube_destroy(victim->cube);
    *victim = (serve_cube_entry){.cube = cube,
                                 .used = ++s->cube_clock,
                                 .mtime_hdr = sh.st_mtim,
                                 .mtime_img = si.st_mtim,
                                 .size_img = si.st_size};
    snprintf(victim->path, sizeof victim->path, "%s", real);
    return cube;
}

const thz_cube *serve_run_cube(serve *s, const char *dir, const char *sensor, const char *quantity,
                               char *why, size_t size)
{
    char hdr[PATH_MAX];
    struct stat st;
    why[0] = '\0';
    if (snprintf(hdr, sizeof hdr, "%s/%s.%s.hdr", dir, sensor, quantity) >= (int)sizeof hdr ||
        (lstat(hdr, &st) != 0 && errno == ENOENT))
        return NULL;
    if (!serve_path_inside(s, hdr)) {
        snprintf(why, size, "%s: outside the root", hdr);
        return NULL;
    }
    thz_error err = {0};
    const thz_cube *c = serve_cube_get(s, hdr, &err);
    if (!c)
        snprintf(why, size, "%s", err.message);
    return c;
}

static json_t *serve_num(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

/* The value of a `key = value` or `key = {a, b}` line of an ENVI header. */
static char *serve_hdr_value(const char *text, const char *key)
{
    size_t n = strlen(key);
    for (const char *line = text; line && *line; line = strchr(line, '\n'), line += !!line) {
        if (strncmp(line, key, n) != 0)
            continue;
        const char *p = line + n;
        while (*p == ' ')
            p++;
        if (*p++ != '=')
            continue;
        while (*p == ' ')
            p++;
        const char *end = *p == '{' ? strchr(p, '}') : strchr(p, '\n');
        if (*p == '{')
            p++;
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char *v = malloc(len + 1);
        if (v) {
            memcpy(v, p, len);
            v[len] = '\0';
        }
        return v;
    }
    return NULL;
}

/* "cam.brightness_temperature.hdr" -> its quantity (a plane name), NULL if none. */
static const char *serve_quantity(const char *name)
{
    const char *best = NULL;
    for (int p = 0; p < THZ_PLANE_COUNT; p++) {
        const char *q = thz_plane_name((thz_plane)p);
        size_t n = strlen(name), m = strlen(q);
        if (n > m + 5 && strcmp(name + n - 4, ".hdr") == 0 && name[n - 5 - m] == '.' &&
            strncmp(name + n - 4 - m, q, m) == 0 && (!best || strlen(q) > strlen(best)))
            best = q;
    }
    return best;
}

enum MHD_Result serve_cube(serve_request *r)
{
    char path[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    if (!serve_path_arg(r, "path", true, path, &ret))
        return ret;
    char *hdr = serve_read_file(path, 1u << 20, NULL);
    char *units = hdr ? serve_hdr_value(hdr, "data units") : NULL;
    char *names = hdr ? serve_hdr_value(hdr, "band names") : NULL;
    free(hdr);
    thz_error err = {0};
    pthread_mutex_lock(&r->s->cache_lock);
    const thz_cube *c = serve_cube_get(r->s, path, &err);
    json_t *o = NULL;
    if (c) {
        size_t rows = thz_cube_rows(c), cols = thz_cube_columns(c), bands = thz_cube_bands(c);
        const float *d = thz_cube_data(c);
        const double *ghz = thz_cube_wavelength_ghz(c);
        json_t *mins = json_array(), *maxs = json_array(), *centres = json_array();
        for (size_t b = 0; b < bands; b++) {
            float lo = INFINITY, hi = -INFINITY;
            for (size_t i = b * rows * cols; i < (b + 1) * rows * cols; i++)
                if (isfinite(d[i])) {
                    lo = fminf(lo, d[i]);
                    hi = fmaxf(hi, d[i]);
                }
            json_array_append_new(mins, serve_num(lo));
            json_array_append_new(maxs, serve_num(hi));
            json_array_append_new(centres, ghz ? serve_num(ghz[b] * 1e-3) : json_null());
        }
        json_t *band_names = json_array();
        for (char *p = names, *tok; p && (tok = strsep(&p, ","));) {
            while (*tok == ' ')
                tok++;
            size_t len = strlen(tok);
            while (len && (tok[len - 1] == ' ' || tok[len - 1] == '\n'))
                tok[--len] = '\0';
            json_array_append_new(band_names, serve_json_text(tok));
        }
        json_t *objects = json_null();
        if (thz_cube_object_name_count(c)) {
            objects = json_array();
            for (size_t i = 0; i < thz_cube_object_name_count(c); i++)
                json_array_append_new(objects, serve_json_text(thz_cube_object_name(c, i)));
        }
        const char *slash = strrchr(path, '/');
        const char *q = serve_quantity(slash ? slash + 1 : path);
        /* a header of another program may hold Latin-1 ("data units = \xb0C"): it made
         * the answer 500, a band name or object name was left out */
        o = json_pack("{s:s, s:I, s:I, s:I, s:o, s:o, s:o, s:s?, s:o, s:o, s:o}", "path",
                      serve_arg(r, "path"), "rows", (json_int_t)rows, "columns", (json_int_t)cols,
                      "bands", (json_int_t)bands, "centres_thz", centres, "units",
                      serve_json_text(units), "band_names", band_names, "quantity", q, "min", mins,
                      "max", maxs, "object_names", objects);
    }
    pthread_mutex_unlock(&r->s->cache_lock);
    free(units);
    free(names);
    return c ? serve_reply_json(r, 200, o) : serve_reply_thz_error(r, &err);
}

enum MHD_Result serve_cube_data(serve_request *r)
{
    char path[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    if (!serve_path_arg(r, "path", true, path, &ret))
        return ret;
    const char *band_arg = serve_arg(r, "band");
    thz_error err = {0};
    pthread_mutex_lock(&r->s->cache_lock);
    const thz_cube *c = serve_cube_get(r->s, path, &err);
    if (!c) {
        pthread_mutex_unlock(&r->s->cache_lock);
        return serve_reply_thz_error(r, &err);
    }
    size_t plane = (size_t)thz_cube_rows(c) * thz_cube_columns(c), bands = thz_cube_bands(c);
    size_t first = 0, count = bands;
    if (band_arg) {
        char *end = NULL;
        long b = strtol(band_arg, &end, 10);
        if (!*band_arg || *end || b < 0 || (size_t)b >= bands) {
            pthread_mutex_unlock(&r->s->cache_lock);
            return serve_reply_error(r, 400, "band=%s: expected 0 to %zu", band_arg, bands - 1);
        }
        first = (size_t)b;
        count = 1;
    }
    float *copy = malloc(count * plane * sizeof *copy + 1);
    if (copy)
        memcpy(copy, thz_cube_data(c) + first * plane, count * plane * sizeof *copy);
    pthread_mutex_unlock(&r->s->cache_lock);
    if (!copy)
        return serve_reply_error(r, 500, "out of memory");
    return serve_reply_binary(r, copy, count * plane * sizeof *copy, NULL);
}

/* Reads DIR/SENSOR.QUANTITY.hdr's values at one pixel (all bands, up to max) into out;
 * the number of bands, 0 when the cube is absent or the pixel outside, or when it cannot
 * be read (why says so, else it is ""). Also its centres (THz) and object names when
 * asked. The caller holds the cache lock. */
static size_t serve_pixel_values(serve *s, const char *dir, const char *sensor, const char *q,
                                 long row, long col, double *out, size_t max, double *centres_thz,
                                 json_t **object_names, char *why, size_t size)
{
    const thz_cube *c = serve_run_cube(s, dir, sensor, q, why, size);
    if (!c || row < 0 || col < 0 || row >= (long)thz_cube_rows(c) ||
        col >= (long)thz_cube_columns(c))
        return 0;
    size_t rows = thz_cube_rows(c), cols = thz_cube_columns(c), n = thz_cube_bands(c);
    n = n < max ? n : max;
    const double *ghz = thz_cube_wavelength_ghz(c);
    for (size_t b = 0; b < n; b++) {
        out[b] = thz_cube_data(c)[(b * rows + (size_t)row) * cols + (size_t)col];
        if (centres_thz)
            centres_thz[b] = ghz ? ghz[b] * 1e-3 : NAN;
    }
    if (object_names) {
        *object_names = json_array();
        for (size_t i = 0; i < thz_cube_object_name_count(c); i++)
            json_array_append_new(*object_names, json_string(thz_cube_object_name(c, i)));
    }
    return n;
}

#define SERVE_MAX_BANDS 4096

static json_t *serve_array(const double *v, size_t n)
{
    if (!n)
        return json_null();
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(a, serve_num(v[i]));
    return a;
}

double serve_tb_stderr(double centre_hz, double l, double sigma)
{
    double tb = centre_hz > 0.0 ? thz_brightness_temperature(centre_hz, l) : 0.0;
    if (!(sigma >= 0.0) || !(tb > 0.0))
        return NAN;
    return thz_brightness_temperature_stderr(centre_hz, tb, sigma);
}

static bool serve_long_arg(serve_request *r, const char *name, long *out)
{
    const char *v = serve_arg(r, name);
    char *end = NULL;
    *out = v ? strtol(v, &end, 10) : 0;
    return v && *v && !*end;
}

enum MHD_Result serve_pixel(serve_request *r)
{
    char dir[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    long row = 0, col = 0;
    const char *sensor = serve_arg(r, "sensor");
    if (!serve_path_arg(r, "dir", true, dir, &ret))
        return ret;
    if (!sensor || strchr(sensor, '/') || !serve_long_arg(r, "row", &row) ||
        !serve_long_arg(r, "col", &col))
        return serve_reply_error(r, 400, "expected sensor=NAME&row=R&col=C");
    static const char *const q[] = {"brightness_temperature",
                                    "radiance",
                                    "radiance_stderr",
                                    "measured_brightness_temperature",
                                    "temperature",
                                    "distance",
                                    "object_id"};
    enum { NQ = sizeof q / sizeof q[0] };
    double *v = calloc(NQ * SERVE_MAX_BANDS + SERVE_MAX_BANDS, sizeof *v);
    if (!v)
        return serve_reply_error(r, 500, "out of memory");
    double *centres = v + NQ * SERVE_MAX_BANDS;
    size_t n[NQ];
    json_t *names = NULL;
    /* The brightness temperature sets the image: none, a 404; a pixel outside it, the
     * request's mistake (400, with the size). One 404 said either, for both. */
    thz_error cube_err = {0};
    char hdr[PATH_MAX], why[sizeof cube_err.message + PATH_MAX] = "";
    long rows = -1, cols = -1;
    bool inside = false;
    pthread_mutex_lock(&r->s->cache_lock);
    /* The cubes are read one after the other: a run that committed into dir meanwhile
     * gave one answer of both runs (the first's Tb beside the second's truth object and
     * the first's temperature). dir, the same before and after (a commit gives it a new
     * inode, or renames files into it: a new modification time), says none did; else
     * the pixel is read again (the cache re-reads the files that changed). */
    for (int attempt = 0; attempt < 10; attempt++) {
        struct stat before, after;
        bool known = stat(dir, &before) == 0;
        json_decref(names);
        names = NULL;
        cube_err = (thz_error){0};
        rows = cols = -1;
        if (snprintf(hdr, sizeof hdr, "%s/%s.brightness_temperature.hdr", dir, sensor) <
                (int)sizeof hdr &&
            serve_path_inside(r->s, hdr)) {
            const thz_cube *c = serve_cube_get(r->s, hdr, &cube_err);
            if (c) {
                rows = (long)thz_cube_rows(c);
                cols = (long)thz_cube_columns(c);
            }
        }
        inside = row >= 0 && col >= 0 && row < rows && col < cols;
        why[0] = '\0';
        for (size_t i = 0; i < NQ && inside && !why[0]; i++)
            n[i] = serve_pixel_values(r->s, dir, sensor, q[i], row, col, v + i * SERVE_MAX_BANDS,
                                      SERVE_MAX_BANDS, i == 0 ? centres : NULL,
                                      i == 6 ? &names : NULL, why, sizeof why);
        if (!known ||
            (stat(dir, &after) == 0 && before.st_dev == after.st_dev &&
             before.st_ino == after.st_ino && before.st_mtim.tv_sec == after.st_mtim.tv_sec &&
             before.st_mtim.tv_nsec == after.st_mtim.tv_nsec &&
             before.st_ctim.tv_sec == after.st_ctim.tv_sec &&
             before.st_ctim.tv_nsec == after.st_ctim.tv_nsec))
            break;
    }
    pthread_mutex_unlock(&r->s->cache_lock);
    if (why[0]) { /* a cube beside it damaged: said, not left out of the answer */
        free(v);
        json_decref(names);
        return serve_reply_error(r, 400, "%s", why);
    }
    if (!inside || !n[0]) { /* n[0]: the cube read, but no band of it (not one of ours) */
        free(v);
        json_decref(names);
        if (rows >= 0 && !inside)
            return serve_reply_error(r, 400,
                                     "row %ld, col %ld: outside the image of %ld x %ld pixels "
                                     "(row 0 to %ld, col 0 to %ld)",
                                     row, col, cols, rows, rows - 1, cols - 1);
        return serve_reply_error(r, 404, "%s: no brightness temperature cube of sensor '%s'%s%s",
                                 dir, sensor, cube_err.message[0] ? ": " : "", cube_err.message);
    }
    double *tb = v, *l = v + SERVE_MAX_BANDS, *sl = v + 2 * SERVE_MAX_BANDS;
    double stderr_k[SERVE_MAX_BANDS];
    bool has_se = n[1] == n[0] && n[2] == n[0];
    for (size_t b = 0; has_se && b < n[0]; b++)
        stderr_k[b] = serve_tb_stderr(centres[b] * 1e12, l[b], sl[b]);
    json_t *truth = json_null();
    if (n[6]) {
        long id = (long)v[6 * SERVE_MAX_BANDS];
        const char *obj = id >= 0 && names && (size_t)id < json_array_size(names)
                              ? json_string_value(json_array_get(names, (size_t)id))
                              : NULL;
        truth = json_pack("{s:s?, s:i, s:o, s:o}", "object", obj, "object_id", (int)id,
                          "temperature_K", n[4] ? serve_num(v[4 * SERVE_MAX_BANDS]) : json_null(),
                          "distance_m", n[5] ? serve_num(v[5 * SERVE_MAX_BANDS]) : json_null());
    }
    json_decref(names);
    json_t *o = json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:o, s:o}", "channels_thz", serve_array(centres, n[0]), "tb_K",
        serve_array(tb, n[0]), "tb_stderr_K", serve_array(stderr_k, has_se ? n[0] : 0), "radiance",
        serve_array(l, n[1]), "radiance_stderr", serve_array(sl, n[2]), "measured_tb_K",
        serve_array(v + 3 * SERVE_MAX_BANDS, n[3]), "truth", truth);
    free(v);
    return serve_reply_json(r, 200, o);
}
