/* GET /api/outputs (what a run's output directory holds) and GET /api/diff (two runs'
 * brightness temperatures compared in units of their combined standard error). */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "serve_internal.h"

static int serve_str_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The names in dir (not . or ..), sorted; *n of them. */
static char **serve_dir_names(const char *dir, size_t *n)
{
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    size_t cap = 0;
    char **names = NULL;
    for (struct dirent *e; (e = readdir(d));) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            char **grown = realloc(names, cap * sizeof *names);
            if (!grown)
                break;
            names = grown;
        }
        if (!(names[*n] = strdup(e->d_name)))
            break;
        (*n)++;
    }
    closedir(d);
    if (names)
        qsort(names, *n, sizeof *names, serve_str_cmp);
    return names;
}

static void serve_names_free(char **names, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

/* The sensor entry of `sensors` called name[0..len), added if missing. */
static json_t *serve_sensor_entry(json_t *sensors, const char *name, size_t len)
{
    for (size_t i = 0; i < json_array_size(sensors); i++) {
        json_t *e = json_array_get(sensors, i);
        const char *n = json_string_value(json_object_get(e, "name"));
        if (strlen(n) == len && strncmp(n, name, len) == 0)
            return e;
    }
    json_t *e = json_pack("{s:s%, s:[], s:[]}", "name", name, len, "cubes", "images");
    json_array_append_new(sensors, e);
    return e;
}

static bool serve_is_dir(const char *dir, const char *name)
{
    char path[PATH_MAX];
    struct stat st;
    return snprintf(path, sizeof path, "%s/%s", dir, name) < (int)sizeof path &&
           stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

enum MHD_Result serve_outputs(serve_request *r)
{
    char dir[PATH_MAX], path[PATH_MAX + 32];
    enum MHD_Result ret = MHD_NO;
    if (!serve_path_arg(r, "dir", true, dir, &ret))
        return ret;
    size_t n = 0;
    char **names = serve_dir_names(dir, &n);
    if (!names && n == 0 && !serve_is_dir(dir, "."))
        return serve_reply_error(r, 400, "%s: not a directory", dir);
    /* a summary.json that is there but damaged is said so, not shown as none */
    size_t dl = strlen(dir);
    while (dl > 1 && dir[dl - 1] == '/')
        dl--;
    snprintf(path, sizeof path, "%.*s%ssummary.json", strcmp(dir, ".") ? (int)dl : 0, dir,
             strcmp(dir, ".") ? "/" : "");
    char why[PATH_MAX + 256];
    json_t *summary = serve_read_json_why(path, why, sizeof why);
    if (summary && !json_is_object(summary)) {
        snprintf(why, sizeof why, "%s: expected a JSON object, got %s", path,
                 json_is_array(summary) ? "an array" : "another value");
        json_decref(summary);
        summary = NULL;
    }
    json_t *sensors = json_array(), *frames = json_array();
    bool photon_map = false;
    /* the sensors: from S.QUANTITY.hdr of a known quantity (sensor names may hold dots) */
    for (size_t i = 0; i < n; i++) {
        const char *name = names[i];
        size_t len = strlen(name);
        if (strcmp(name, "photon-map.thzpm") == 0)
            photon_map = true;
        if (strncmp(name, "frame-", 6) == 0 && serve_is_dir(dir, name))
            json_array_append_new(frames, json_string(name));
        if (strncmp(name, "sweep-", 6) == 0 && serve_is_dir(dir, name)) {
            snprintf(path, sizeof path, "%s/%s", dir, name);
            size_t m = 0;
            char **sub = serve_dir_names(path, &m);
            for (size_t k = 0; k < m; k++)
                if (strncmp(sub[k], "frame-", 6) == 0)
                    json_array_append_new(frames, json_sprintf("%s/%s", name, sub[k]));
            serve_names_free(sub, m);
        }
        for (int p = 0; p < THZ_PLANE_COUNT; p++) {
            const char *q = thz_plane_name((thz_plane)p);
            size_t m = strlen(q);
            if (len > m + 5 && strcmp(name + len - 4, ".hdr") == 0 && name[len - 5 - m] == '.' &&
                strncmp(name + len - 4 - m, q, m) == 0) {
                json_t *e = serve_sensor_entry(sensors, name, len - 5 - m);
                json_array_append_new(json_object_get(e, "cubes"), json_string(q));
                break;
            }
        }
    }
    /* their images: S.*.png */
    for (size_t i = 0; i < n; i++) {
        size_t len = strlen(names[i]);
        if (len < 5 || strcmp(names[i] + len - 4, ".png") != 0)
            continue;
        for (size_t k = 0; k < json_array_size(sensors); k++) {
            json_t *e = json_array_get(sensors, k);
            const char *s = json_string_value(json_object_get(e, "name"));
            size_t sl = strlen(s);
            if (strncmp(names[i], s, sl) == 0 && names[i][sl] == '.')
                json_array_append_new(json_object_get(e, "images"), json_string(names[i]));
        }
    }
    serve_names_free(names, n);
    /* a batch's frames are those its batch.json lists: a shorter sequence run into the
     * directory leaves the longer one's last frames standing (scene-format.md) */
    snprintf(path, sizeof path, "%s/batch.json", dir);
    json_t *batch = serve_read_json(path), *listed = json_object_get(batch, "frames");
    if (json_is_array(listed)) {
        json_array_clear(frames);
        size_t i;
        json_t *f;
        json_array_foreach(listed, i, f)
        {
            const char *d = json_string_value(json_object_get(f, "dir"));
            if (d && serve_is_dir(dir, d))
                json_array_append_new(frames, json_string(d));
        }
    }
    json_decref(batch);
    const char *rel = serve_arg(r, "dir");
    json_t *pm = json_null();
    if (photon_map)
        pm = strcmp(dir, ".") == 0 ? json_string("photon-map.thzpm")
                                   : json_sprintf("%s/photon-map.thzpm", rel);
    return serve_reply_json(r, 200,
                            json_pack("{s:s, s:o, s:o, s:o, s:o, s:o}", "dir", rel, "summary",
                                      summary ? summary : json_null(), "summary_error",
                                      why[0] ? serve_json_text(why) : json_null(), "sensors",
                                      sensors, "frames", frames, "photon_map", pm));
}

/* One run's band of sensor s: Tb and its standard error (NaN when the run has no
 * radiance_stderr cube) into tb[], se[] (rows x columns). False when there is no such
 * cube or band; *rows and *cols must agree with earlier calls (0: set them). The caller
 * holds the cache lock. */
static bool serve_diff_side(serve *s, const char *dir, const char *sensor, size_t band,
                            uint32_t *rows, uint32_t *cols, float **tb, double **se, bool *has_se,
                            char *why, size_t size)
{
    char hdr[PATH_MAX];
    thz_error err = {0};
    snprintf(hdr, sizeof hdr, "%s/%s.brightness_temperature.hdr", dir, sensor);
    const thz_cube *c = serve_path_inside(s, hdr) ? serve_cube_get(s, hdr, &err) : NULL;
    if (!c || band >= thz_cube_bands(c)) {
        snprintf(why, size, "%s: no brightness temperature of sensor '%s' with band %zu", dir,
                 sensor, band);
        return false;
    }
    if (*rows && (*rows != thz_cube_rows(c) || *cols != thz_cube_columns(c))) {
        snprintf(why, size, "the two runs' images differ in size");
        return false;
    }
    *rows = thz_cube_rows(c);
    *cols = thz_cube_columns(c);
    size_t plane = (size_t)*rows * *cols;
    const double *ghz = thz_cube_wavelength_ghz(c);
    double centre_hz = ghz ? ghz[band] * 1e9 : NAN;
    *tb = malloc(plane * sizeof **tb + 1);
    *se = malloc(plane * sizeof **se + 1);
    if (!*tb || !*se) {
        snprintf(why, size, "out of memory");
        return false;
    }
    memcpy(*tb, thz_cube_data(c) + band * plane, plane * sizeof **tb);
    float *l = malloc(plane * sizeof *l + 1);
    if (!l) {
        snprintf(why, size, "out of memory");
        return false;
    }
    /* Tb's standard error needs the radiance and its standard error: a run without them
     * gives Tb_a - Tb_b in K (docs/gui.md); one whose cubes are there but cannot be read,
     * or are not of Tb's size, is said, not taken for a run without them */
    static const char *const q[] = {"radiance", "radiance_stderr"};
    const thz_cube *cs = NULL;
    for (int k = 0; k < 2; k++) {
        cs = serve_run_cube(s, dir, sensor, q[k], why, size);
        if (cs && (thz_cube_rows(cs) != *rows || thz_cube_columns(cs) != *cols ||
                   band >= thz_cube_bands(cs)))
            snprintf(why, size,
                     "%s/%s.%s.hdr: %u x %u pixels, %zu bands: not its "
                     "brightness temperature's %u x %u with band %zu",
                     dir, sensor, q[k], thz_cube_columns(cs), thz_cube_rows(cs), thz_cube_bands(cs),
                     *cols, *rows, band);
        if (why[0] || !cs)
            break;
        if (k == 0)
            memcpy(l, thz_cube_data(cs) + band * plane, plane * sizeof *l);
    }
    *has_se = cs && !why[0];
    for (size_t i = 0; i < plane; i++)
        (*se)[i] =
            *has_se ? serve_tb_stderr(centre_hz, l[i], thz_cube_data(cs)[band * plane + i]) : NAN;
    free(l);
    return !why[0];
}

enum MHD_Result serve_diff(serve_request *r)
{
    char a[PATH_MAX], b[PATH_MAX], why[600] = "";
    enum MHD_Result ret = MHD_NO;
    const char *sensor = serve_arg(r, "sensor"), *band_arg = serve_arg(r, "band");
    if (!serve_path_arg(r, "a", true, a, &ret) || !serve_path_arg(r, "b", true, b, &ret))
        return ret;
    char *end = NULL;
    long band = band_arg ? strtol(band_arg, &end, 10) : -1;
    if (!sensor || strchr(sensor, '/') || !band_arg || !*band_arg || *end || band < 0)
        return serve_reply_error(r, 400, "expected sensor=NAME&band=K");
    uint32_t rows = 0, cols = 0;
    float *tb_a = NULL, *tb_b = NULL;
    double *se_a = NULL, *se_b = NULL;
    bool has_a = false, has_b = false;
    pthread_mutex_lock(&r->s->cache_lock);
    bool ok = serve_diff_side(r->s, a, sensor, (size_t)band, &rows, &cols, &tb_a, &se_a, &has_a,
                              why, sizeof why) &&
              serve_diff_side(r->s, b, sensor, (size_t)band, &rows, &cols, &tb_b, &se_b, &has_b,
                              why, sizeof why);
    pthread_mutex_unlock(&r->s->cache_lock);
    if (ok) {
        size_t plane = (size_t)rows * cols;
        bool sigma = has_a && has_b;
        for (size_t i = 0; i < plane; i++) {
            double d = (double)tb_a[i] - (double)tb_b[i];
            double s2 = se_a[i] * se_a[i] + se_b[i] * se_b[i];
            tb_a[i] = (float)(sigma ? (s2 > 0.0 ? d / sqrt(s2) : d == 0.0 ? 0.0 : NAN) : d);
        }
        char rows_s[16], cols_s[16];
        snprintf(rows_s, sizeof rows_s, "%u", rows);
        snprintf(cols_s, sizeof cols_s, "%u", cols);
        const char *headers[] = {"X-Thzmap-Diff-Units",
                                 sigma ? "sigma" : "K",
                                 "X-Thzmap-Rows",
                                 rows_s,
                                 "X-Thzmap-Columns",
                                 cols_s,
                                 NULL};
        ret = serve_reply_binary(r, tb_a, plane * sizeof *tb_a, headers);
        tb_a = NULL; /* the reply's now */
    } else {
        ret = serve_reply_error(r, strstr(why, "memory") ? 500 : 400, "%s", why);
    }
    free(tb_a);
    free(tb_b);
    free(se_a);
    free(se_b);
    return ret;
}
