/* What the files of src/serve/ share: the server's state, a request being answered,
 * replies, paths confined to the root, and the endpoints each file provides. */
#ifndef THZ_SERVE_SERVE_INTERNAL_H
#define THZ_SERVE_SERVE_INTERNAL_H

#include <jansson.h>
#include <limits.h>
#include <microhttpd.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>

#include "serve.h"
#include "thzmap/thzmap.h"

/* Binary answers are the host's float32 arrays as they are, documented as little-endian. */
#if __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "thzmap serve sends float32 arrays in the host's byte order, which must be little-endian"
#endif

#define SERVE_MAX_BODY_BYTES (4u << 20)  /* request bodies; larger: 413 */
#define SERVE_MAX_FILE_BYTES (64u << 20) /* the page's own files */
#define SERVE_MAX_JOBS 64                /* queued and running jobs; more: 409 */
#define SERVE_KEPT_FINISHED 256          /* finished jobs kept (the oldest go): 14 KB each */
#define SERVE_PREVIEW_TRIANGLES 300000   /* /api/validate's meshes: the rest "mesh": null */
#define SERVE_CUBE_CACHE 8               /* cubes kept open */
#define SERVE_STREAMS_END_S 2            /* at stop, the event streams' time to end */

typedef struct serve_job serve_job;
typedef struct serve_cube_entry serve_cube_entry;

struct serve {
    struct MHD_Daemon *daemon;
    unsigned port;
    char token[33];
    char root[PATH_MAX]; /* realpath of the root; the working directory */
    char web_dir[PATH_MAX];
    bool has_web;

    /* jobs (serve_runs.c): lock guards the list and every job's fields */
    pthread_mutex_t lock;
    pthread_cond_t changed; /* a job changed state or progress, or stopping */
    pthread_t worker;
    bool worker_started;
    bool stopping;
    size_t streams; /* event streams the daemon has not yet let go of */
    serve_job **jobs;
    size_t n_jobs, cap_jobs;
    int next_id;

    /* cubes (serve_outputs.c) and the last photon map (serve_photons.c) */
    pthread_mutex_t cache_lock;
    serve_cube_entry *cubes; /* SERVE_CUBE_CACHE entries */
    uint64_t cube_clock;
    pthread_mutex_t photon_lock;
    struct serve_photon_cache *photons;
};

/* A request: method, URL, the body so far, and the server. */
typedef struct serve_request {
    serve *s;
    struct MHD_Connection *conn;
    const char *method;
    const char *url;
    char *body;
    size_t body_size;
    size_t body_cap; /* bytes allocated for body (doubling) */
    bool too_large;
    bool answered; /* a response was queued before the body (401, 403, 413) */
} serve_request;

/* ---- replies (serve_http.c); each returns what the access handler returns ---------- */
/* The headers of every /api/ answer (docs/gui.md), for a response made by hand. */
void serve_data_headers(struct MHD_Response *resp);
enum MHD_Result serve_reply(serve_request *r, unsigned status, const char *type, const void *data,
                            size_t size);
/* Takes a reference to `json` (steals it). */
enum MHD_Result serve_reply_json(serve_request *r, unsigned status, json_t *json);
/* Cuts text at its end until it is valid UTF-8: a message cut to its buffer's size may end
 * inside a character, and jansson refuses such a string. */
void serve_text_fit(char *text);
/* Replaces each byte of text that starts no valid UTF-8 character with '?': a message that
 * quotes bytes of a request (a syntax error near them) is still one jansson takes. */
void serve_text_utf8(char *text);
/* The JSON string of text as serve_text_utf8 makes it (a name or unit read from a file,
 * which may be Latin-1), or JSON null for NULL. NULL only when out of memory. */
json_t *serve_json_text(const char *text);
enum MHD_Result serve_reply_error(serve_request *r, unsigned status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* 400 with "path": the JSON path of the problem in the request body. */
enum MHD_Result serve_reply_bad_json(serve_request *r, const char *json_path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Binary data (application/octet-stream) from malloc'd data, which the reply takes (and
 * frees, also on failure): no copy; extra headers name/value pairs, NULL-ended. */
enum MHD_Result serve_reply_binary(serve_request *r, void *data, size_t size,
                                   const char *const *headers);
/* A whole file from its open descriptor fd (size bytes; the reply closes fd, also on
 * failure): streamed, not read into memory. */
enum MHD_Result serve_reply_fd(serve_request *r, const char *type, int fd, uint64_t size);
/* The 404/403/500 for a thz_error of the library (input: 400). */
enum MHD_Result serve_reply_thz_error(serve_request *r, const thz_error *err);

/* A query argument, or NULL. */
const char *serve_arg(serve_request *r, const char *name);
/* The body parsed as a JSON object whose keys are among `keys` (NULL-ended); NULL after
 * replying 400 (then return *result): malformed, not an object, or a key not in `keys`
 * (at "$.KEY": a misspelt key would otherwise be passed over in silence). */
json_t *serve_body_object(serve_request *r, const char *const *keys, enum MHD_Result *result);

/* ---- paths under the root (serve_paths.c) ------------------------------------------- */

/* Why a path was refused. */
typedef enum serve_path_status {
    SERVE_PATH_OK = 0,
    SERVE_PATH_FORBIDDEN, /* absolute, "..", outside the root through a symlink: 403 */
    SERVE_PATH_MISSING,   /* does not exist (when it must): 404 */
    SERVE_PATH_DENIED,    /* a directory under the root the server may not enter: 403 */
    SERVE_PATH_TOO_LONG,  /* SERVE_MAX_REL_BYTES or more: 400 */
} serve_path_status;

/* REL paths shorter than this (bytes) are checked; longer ones are refused as such. */
#define SERVE_MAX_REL_BYTES (PATH_MAX - 2)

/* Checks REL (relative to the root, "" or "." is the root) and writes the path to use
 * (relative to the working directory, which is the root) into out[PATH_MAX]. With
 * must_exist false the path may not exist yet, but its deepest existing ancestor must
 * lie inside the root. */
serve_path_status serve_path(const serve *s, const char *rel, bool must_exist, char *out);
/* serve_path for the query argument `name`; replies (403, 404, 400 when absent) and
 * returns false when it is refused. */
bool serve_path_arg(serve_request *r, const char *name, bool must_exist, char *out,
                    enum MHD_Result *result);
/* The answer to a path serve_path refused (st not SERVE_PATH_OK), naming it as
 * label, sep, rel ("path", "=", "a/b"), with the status of st. */
enum MHD_Result serve_reply_path(serve_request *r, serve_path_status st, const char *label,
                                 const char *sep, const char *rel);
/* Whether a path (relative to the root) resolves inside the root. */
bool serve_path_inside(const serve *s, const char *path);
/* Opens a regular file for reading without ever blocking: a FIFO or a device is not
 * opened (or only with O_NONBLOCK, and closed again). The descriptor, or -1 with errno
 * set; EINVAL: not a regular file. */
int serve_open_regular(const char *path);
/* Reads a whole regular file (at most max bytes) into a malloc'd NUL-terminated buffer;
 * NULL with errno set (EINVAL not a regular file, EFBIG larger than max, EIO cut short). */
char *serve_read_file(const char *path, size_t max, size_t *size);

/* The JSON document of a regular file (serve_read_file: a FIFO does not block), or NULL. */
json_t *serve_read_json(const char *path);
/* The same, NULL with why "" when there is no such file, NULL with why naming the file
 * and what is wrong when it is there but cannot be read or parsed (the JSON's line and
 * column): a damaged file is told apart from one that is absent. */
json_t *serve_read_json_why(const char *path, char *why, size_t size);

/* ---- endpoints ----------------------------------------------------------------------- */
typedef enum MHD_Result (*serve_handler)(serve_request *r);

enum MHD_Result serve_files_list(serve_request *r);
enum MHD_Result serve_file_get(serve_request *r);
enum MHD_Result serve_file_put(serve_request *r);
enum MHD_Result serve_static(serve_request *r);

enum MHD_Result serve_validate(serve_request *r);
enum MHD_Result serve_materials(serve_request *r);

enum MHD_Result serve_runs(serve_request *r); /* /api/runs and /api/runs/... */
/* The job worker (serve_runs.c): started by serve_start, stopped by serve_stop. */
bool serve_runs_start(serve *s);
/* Cancels the running job, drops the queued ones and joins the worker; the event
 * streams end. serve_runs_free (after the daemon stopped) frees the jobs. */
void serve_runs_stop(serve *s);
void serve_runs_free(serve *s);

enum MHD_Result serve_outputs(serve_request *r);
enum MHD_Result serve_cube(serve_request *r);
enum MHD_Result serve_cube_data(serve_request *r);
enum MHD_Result serve_pixel(serve_request *r);
enum MHD_Result serve_diff(serve_request *r);
void serve_cubes_free(serve *s);
/* The cube of header `hdr` (a path under the root ending in .hdr), from the cache or
 * read; valid while the caller holds s->cache_lock and gets no other cube. NULL with err
 * filled when it cannot be read. */
const thz_cube *serve_cube_get(serve *s, const char *hdr, thz_error *err);
/* DIR/SENSOR.QUANTITY.hdr, a cube a run may or may not have written, by serve_cube_get:
 * NULL with why "" when there is no such file (the run wrote none), NULL with why saying
 * what is wrong when it is there but cannot be read (damaged, cut short, outside the
 * root): such a cube is reported, never taken for one the run did not write. */
const thz_cube *serve_run_cube(serve *s, const char *dir, const char *sensor, const char *quantity,
                               char *why, size_t size);
/* The standard error of Tb (K) from that of the radiance L at the channel centre (where
 * the images' Tb is defined): sigma / (dB/dT at Tb), thz_brightness_temperature_stderr.
 * NaN without a positive centre, a sigma or a positive Tb (L <= 0). */
double serve_tb_stderr(double centre_hz, double l, double sigma);

enum MHD_Result serve_photons(serve_request *r);
enum MHD_Result serve_photons_info(serve_request *r);
void serve_photons_free(serve *s);

#endif
