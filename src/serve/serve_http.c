/* The HTTP side of `thzmap serve`: the libmicrohttpd daemon, the access token, request
 * bodies and their limit, routing to the endpoints, and replies. */
#define _GNU_SOURCE /* getrandom */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include "serve_internal.h"

bool serve_available(void)
{
    return true;
}

/* ---- replies --------------------------------------------------------------------------- */

static void serve_common_headers(struct MHD_Response *resp)
{
    MHD_add_response_header(resp, "Cache-Control", "no-store");
    MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(resp, "Referrer-Policy", "no-referrer");
}

/* Answers other than the page's own files: nothing in them may run as a page. */
void serve_data_headers(struct MHD_Response *resp)
{
    serve_common_headers(resp);
    MHD_add_response_header(resp, "Content-Security-Policy", "default-src 'none'; sandbox");
}

/* A thread per connection, opened before the token is checked: bounded, so that whoever
 * can connect cannot hold every thread (an event stream sends a keep-alive every 15 s,
 * well within the idle limit). */
enum { SERVE_MAX_CONNECTIONS = 64, SERVE_MAX_PER_IP = 32, SERVE_IDLE_S = 60 };

enum MHD_Result serve_reply(serve_request *r, unsigned status, const char *type, const void *data,
                            size_t size)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(size, (void *)data, MHD_RESPMEM_MUST_COPY);
    if (!resp)
        return MHD_NO;
    if (type)
        MHD_add_response_header(resp, "Content-Type", type);
    if (strncmp(r->url, "/api/", 5) == 0)
        serve_data_headers(resp);
    else
        serve_common_headers(resp);
    enum MHD_Result ret = MHD_queue_response(r->conn, status, resp);
    MHD_destroy_response(resp);
    return ret;
}

enum MHD_Result serve_reply_fd(serve_request *r, const char *type, int fd, uint64_t size)
{
    struct MHD_Response *resp = MHD_create_response_from_fd64(size, fd);
    if (!resp) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(resp, "Content-Type", type);
    serve_data_headers(resp);
    enum MHD_Result ret = MHD_queue_response(r->conn, 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

enum MHD_Result serve_reply_json(serve_request *r, unsigned status, json_t *json)
{
    char *text =
        json ? json_dumps(json, JSON_COMPACT | JSON_ENSURE_ASCII | JSON_REAL_PRECISION(9)) : NULL;
    json_decref(json);
    if (!text)
        return serve_reply(r, 500, "application/json", "{\"error\":\"out of memory\"}", 25);
    enum MHD_Result ret = serve_reply(r, status, "application/json", text, strlen(text));
    free(text);
    return ret;
}

__attribute__((format(printf, 4, 0))) static enum MHD_Result
serve_reply_errorv(serve_request *r, unsigned status, const char *json_path, const char *fmt,
                   va_list ap)
{
    char message[1200];
    vsnprintf(message, sizeof message, fmt, ap);
    /* what it quotes may not be UTF-8 (jansson's syntax errors quote the bytes near the
     * error, cut inside a character: the answer was 500 "out of memory") */
    serve_text_utf8(message);
    json_t *o = json_pack("{s:s}", "error", message);
    if (o && json_path)
        json_object_set_new(o, "path", json_string(json_path));
    return serve_reply_json(r, status, o);
}

enum MHD_Result serve_reply_error(serve_request *r, unsigned status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    enum MHD_Result ret = serve_reply_errorv(r, status, NULL, fmt, ap);
    va_end(ap);
    return ret;
}

enum MHD_Result serve_reply_bad_json(serve_request *r, const char *json_path, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    enum MHD_Result ret = serve_reply_errorv(r, 400, json_path, fmt, ap);
    va_end(ap);
    return ret;
}

enum MHD_Result serve_reply_binary(serve_request *r, void *data, size_t size,
                                   const char *const *headers)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(size, data, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(data);
        return MHD_NO;
    }
    MHD_add_response_header(resp, "Content-Type", "application/octet-stream");
    serve_data_headers(resp);
    for (size_t i = 0; headers && headers[i]; i += 2)
        MHD_add_response_header(resp, headers[i], headers[i + 1]);
    enum MHD_Result ret = MHD_queue_response(r->conn, 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

enum MHD_Result serve_reply_thz_error(serve_request *r, const thz_error *err)
{
    unsigned status = err->status == THZ_ERR_INPUT || err->status == THZ_ERR_LIMIT ? 400 : 500;
    return serve_reply_error(r, status, "%s",
                             err->message[0] ? err->message : thz_status_name(err->status));
}

const char *serve_arg(serve_request *r, const char *name)
{
    return MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, name);
}

json_t *serve_body_object(serve_request *r, const char *const *keys, enum MHD_Result *result)
{
    json_error_t jerr;
    json_t *o = json_loadb(r->body ? r->body : "", r->body_size, JSON_REJECT_DUPLICATES, &jerr);
    if (!o) {
        /* an empty body: jansson's column 0 is the line's first character */
        *result = serve_reply_bad_json(r, "$", "invalid JSON at line %d, column %d: %s", jerr.line,
                                       jerr.column > 0 ? jerr.column : 1, jerr.text);
        return NULL;
    }
    if (!json_is_object(o)) {
        json_decref(o);
        *result = serve_reply_bad_json(r, "$", "expected a JSON object");
        return NULL;
    }
    const char *key;
    json_t *v;
    json_object_foreach(o, key, v)
    {
        size_t k = 0;
        while (keys[k] && strcmp(key, keys[k]) != 0)
            k++;
        if (keys[k])
            continue;
        char path[300], expected[200] = "";
        snprintf(path, sizeof path, "$.%s", key);
        serve_text_fit(path);
        for (k = 0; keys[k]; k++)
            snprintf(expected + strlen(expected), sizeof expected - strlen(expected), "%s%s",
                     k ? ", " : "", keys[k]);
        *result = serve_reply_bad_json(r, path, "unknown key (expected %s)", expected);
        json_decref(o);
        return NULL;
    }
    return o;
}

/* ---- the token ------------------------------------------------------------------------- */

/* Constant time in the length of `want`. */
static bool serve_token_equal(const char *got, const char *want)
{
    size_t n = strlen(want), m = strlen(got);
    unsigned char diff = (unsigned char)(n != m);
    for (size_t i = 0; i < n; i++)
        diff |= (unsigned char)(want[i] ^ (i < m ? got[i] : 0));
    return diff == 0;
}

/* The token the request carries (cookie or bearer header), or NULL. */
static const char *serve_request_token(struct MHD_Connection *conn)
{
    const char *auth = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Authorization");
    if (auth && strncmp(auth, "Bearer ", 7) == 0)
        return auth + 7;
    return MHD_lookup_connection_value(conn, MHD_COOKIE_KIND, "thzmap_token");
}

/* GET /?token=T: sets the cookie and redirects to /. */
static enum MHD_Result serve_login(serve_request *r, const char *token)
{
    if (!serve_token_equal(token, r->s->token))
        return serve_reply_error(r, 403, "wrong access token");
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
    if (!resp)
        return MHD_NO;
    char cookie[128];
    snprintf(cookie, sizeof cookie, "thzmap_token=%s; HttpOnly; SameSite=Strict; Path=/",
             r->s->token);
    MHD_add_response_header(resp, "Set-Cookie", cookie);
    MHD_add_response_header(resp, "Location", "/");
    serve_common_headers(resp);
    enum MHD_Result ret = MHD_queue_response(r->conn, 303, resp);
    MHD_destroy_response(resp);
    return ret;
}

/* ---- routing ------------------------------------------------------------------------- */

static enum MHD_Result serve_info(serve_request *r)
{
    json_t *o =
        json_pack("{s:s, s:s, s:s, s:[s,s,s], s:[s,s,s,s]}", "version", thz_version(), "revision",
                  thz_revision(), "root", r->s->root, "integrators", "path", "final-gather",
                  "photon-map", "commands", "simulate", "render", "batch", "bands");
    if (o)
        json_object_set_new(o, "web", json_boolean(r->s->has_web));
    return serve_reply_json(r, 200, o);
}

typedef struct serve_route {
    const char *method; /* NULL: any (the handler checks) */
    const char *path;
    bool prefix; /* path is a prefix of the URL */
    serve_handler fn;
} serve_route;

static const serve_route serve_routes[] = {
    {"GET", "/api/info", false, serve_info},
    {"GET", "/api/files", false, serve_files_list},
    {"GET", "/api/file", false, serve_file_get},
    {"PUT", "/api/file", false, serve_file_put},
    {"POST", "/api/validate", false, serve_validate},
    {"GET", "/api/materials", true, serve_materials},
    {NULL, "/api/runs", true, serve_runs},
    {"GET", "/api/outputs", false, serve_outputs},
    {"GET", "/api/cube/data", false, serve_cube_data},
    {"GET", "/api/cube", false, serve_cube},
    {"GET", "/api/pixel", false, serve_pixel},
    {"GET", "/api/photons/info", false, serve_photons_info},
    {"GET", "/api/photons", false, serve_photons},
    {"GET", "/api/diff", false, serve_diff},
};

static enum MHD_Result serve_route_request(serve_request *r)
{
    bool path_known = false;
    for (size_t i = 0; i < sizeof serve_routes / sizeof serve_routes[0]; i++) {
        const serve_route *rt = &serve_routes[i];
        size_t n = strlen(rt->path);
        bool match = rt->prefix ? strncmp(r->url, rt->path, n) == 0 &&
                                      (r->url[n] == '\0' || r->url[n] == '/')
                                : strcmp(r->url, rt->path) == 0;
        if (!match)
            continue;
        path_known = true;
        if (!rt->method || strcmp(rt->method, r->method) == 0)
            return rt->fn(r);
    }
    if (path_known)
        return serve_reply_error(r, 405, "%s is not allowed on %s", r->method, r->url);
    if (strncmp(r->url, "/api/", 5) == 0 || strcmp(r->url, "/api") == 0)
        return serve_reply_error(r, 404, "no such endpoint: %s", r->url);
    if (strcmp(r->method, "GET") != 0 && strcmp(r->method, "HEAD") != 0)
        return serve_reply_error(r, 405, "%s is not allowed on %s", r->method, r->url);
    return serve_static(r);
}

/* Whether text is valid UTF-8 (jansson's own test: it refuses other strings). */
static bool serve_is_utf8(const char *text)
{
    json_t *t = json_string(text);
    json_decref(t);
    return t != NULL;
}

void serve_text_utf8(char *text)
{
    if (serve_is_utf8(text))
        return;
    for (char *p = text; *p;) {
        size_t len = 1; /* the character at p: the shortest prefix jansson takes */
        json_t *c = NULL;
        while (len <= 4 && p[len - 1] && !(c = json_stringn(p, len)))
            len++;
        json_decref(c);
        if (c)
            p += len;
        else
            *p++ = '?';
    }
}

json_t *serve_json_text(const char *text)
{
    if (!text)
        return json_null();
    char *copy = strdup(text);
    if (!copy)
        return NULL;
    serve_text_utf8(copy);
    json_t *s = json_string(copy);
    free(copy);
    return s;
}

void serve_text_fit(char *text)
{
    size_t n = strlen(text);
    json_t *t = NULL;
    while (n > 0 && !(t = json_stringn(text, n)))
        n--;
    json_decref(t);
    text[n] = '\0';
}

/* MHD's iterator over the query: counts the arguments that are not UTF-8 text, or hold
 * a NUL (%00), which would end the C string early: "a.json%00.txt" named a.json. */
static enum MHD_Result serve_count_bad_arg(void *cls, enum MHD_ValueKind kind, const char *key,
                                           size_t key_size, const char *value, size_t value_size)
{
    (void)kind;
    if (!serve_is_utf8(key) || strlen(key) != key_size ||
        (value && (!serve_is_utf8(value) || strlen(value) != value_size)))
        ++*(int *)cls;
    return MHD_YES;
}

/* MHD's access handler: called first with the headers (check the token and the size),
 * then with each piece of the body, then once more to answer. */
static enum MHD_Result serve_access(void *cls, struct MHD_Connection *conn, const char *url,
                                    const char *method, const char *version,
                                    const char *upload_data, size_t *upload_data_size,
                                    void **con_cls)
{
    (void)version;
    serve_request *r = *con_cls;
    if (!r) {
        r = calloc(1, sizeof *r);
        if (!r)
            return MHD_NO;
        *con_cls = r;
        *r = (serve_request){.s = cls, .conn = conn, .method = method, .url = url};
        const char *login = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "token");
        if (strcmp(method, "GET") == 0 && strcmp(url, "/") == 0 && login) {
            r->answered = true;
            return serve_login(r, login);
        }
        const char *token = serve_request_token(conn);
        if (!token) {
            r->answered = true;
            return serve_reply_error(r, 401,
                                     "no access token: open the URL thzmap serve "
                                     "printed, or send 'Authorization: Bearer TOKEN'");
        }
        if (!serve_token_equal(token, r->s->token)) {
            r->answered = true;
            return serve_reply_error(r, 403, "wrong access token");
        }
        const char *length =
            MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
        if (length && strtoull(length, NULL, 10) > SERVE_MAX_BODY_BYTES) {
            r->answered = true;
            return serve_reply_error(r, 413, "request body larger than %u bytes",
                                     SERVE_MAX_BODY_BYTES);
        }
        /* the answers quote the method, the URL and the query (paths, names), as JSON:
         * jansson refuses other bytes than UTF-8, and they became 500 "out of memory" (a
         * PUT had written its file by then; a method of other bytes on a known path, the
         * 405 that names it: the fuzzer found it) */
        int bad = 0;
        MHD_get_connection_values_n(conn, MHD_GET_ARGUMENT_KIND, serve_count_bad_arg, &bad);
        if (bad || !serve_is_utf8(url) || !serve_is_utf8(method)) {
            r->answered = true;
            return serve_reply_error(r, 400,
                                     "the method, the URL or its query is not UTF-8 text (or "
                                     "holds a NUL, %%00)");
        }
        return MHD_YES;
    }
    if (r->answered) { /* discard what a client sends after the refusal */
        *upload_data_size = 0;
        return MHD_YES;
    }
    if (*upload_data_size) {
        size_t n = *upload_data_size;
        *upload_data_size = 0;
        if (r->too_large || r->body_size + n > SERVE_MAX_BODY_BYTES) {
            r->too_large = true;
            return MHD_YES;
        }
        if (r->body_size + n + 1 > r->body_cap) {
            size_t cap = r->body_cap ? 2 * r->body_cap : 65536;
            while (cap < r->body_size + n + 1)
                cap *= 2;
            char *grown = realloc(r->body, cap);
            if (!grown)
                return MHD_NO;
            r->body = grown;
            r->body_cap = cap;
        }
        memcpy(r->body + r->body_size, upload_data, n);
        r->body_size += n;
        r->body[r->body_size] = '\0';
        return MHD_YES;
    }
    if (r->too_large)
        return serve_reply_error(r, 413, "request body larger than %u bytes", SERVE_MAX_BODY_BYTES);
    return serve_route_request(r);
}

static void serve_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                            enum MHD_RequestTerminationCode code)
{
    (void)cls, (void)conn, (void)code;
    serve_request *r = *con_cls;
    if (r) {
        free(r->body);
        free(r);
    }
    *con_cls = NULL;
}

/* ---- start and stop -------------------------------------------------------------------- */

static bool serve_make_token(char out[33])
{
    unsigned char bytes[16];
    size_t got = 0;
    while (got < sizeof bytes) {
        ssize_t n = getrandom(bytes + got, sizeof bytes - got, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return false;
        got += (size_t)n;
    }
    for (size_t i = 0; i < sizeof bytes; i++)
        snprintf(out + 2 * i, 3, "%02x", bytes[i]);
    return true;
}

serve *serve_start(const serve_options *opt, char *why, size_t size, bool *usage)
{
    *usage = false;
    serve *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(why, size, "out of memory");
        return NULL;
    }
    struct stat st;
    /* the bundle first: a relative path names it from the directory serve started in */
    char index[PATH_MAX + 16];
    if (opt->web_dir && realpath(opt->web_dir, s->web_dir) && stat(s->web_dir, &st) == 0 &&
        S_ISDIR(st.st_mode) &&
        snprintf(index, sizeof index, "%s/index.html", s->web_dir) < (int)sizeof index &&
        stat(index, &st) == 0 && S_ISREG(st.st_mode)) /* a directory without the page: none */
        s->has_web = true;
    bool found = realpath(opt->root, s->root) != NULL;
    if (!found || stat(s->root, &st) != 0 || !S_ISDIR(st.st_mode) || chdir(s->root) != 0) {
        snprintf(why, size, "--root %s: %s", opt->root,
                 found && errno != EACCES ? "not a directory" : strerror(errno));
        *usage = true;
        free(s);
        return NULL;
    }
    if (!serve_make_token(s->token)) {
        snprintf(why, size, "getrandom: %s", strerror(errno));
        free(s);
        return NULL;
    }
    struct sockaddr_in v4 = {.sin_family = AF_INET, .sin_port = htons((uint16_t)opt->port)};
    struct sockaddr_in6 v6 = {.sin6_family = AF_INET6, .sin6_port = htons((uint16_t)opt->port)};
    const struct sockaddr *addr = NULL;
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION;
    if (inet_pton(AF_INET, opt->host, &v4.sin_addr) == 1) {
        addr = (const struct sockaddr *)&v4;
    } else if (inet_pton(AF_INET6, opt->host, &v6.sin6_addr) == 1) {
        addr = (const struct sockaddr *)&v6;
        flags |= MHD_USE_IPv6;
    } else {
        snprintf(why, size, "--host %s: not an IPv4 or IPv6 address", opt->host);
        *usage = true;
        free(s);
        return NULL;
    }
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->changed, NULL);
    pthread_mutex_init(&s->cache_lock, NULL);
    pthread_mutex_init(&s->photon_lock, NULL);
    s->next_id = 1;
    if (!serve_runs_start(s)) {
        snprintf(why, size, "could not start the job thread");
        serve_stop(s);
        return NULL;
    }
    s->daemon = MHD_start_daemon(
        flags, (uint16_t)opt->port, NULL, NULL, serve_access, s, MHD_OPTION_SOCK_ADDR, addr,
        MHD_OPTION_NOTIFY_COMPLETED, serve_completed, s, MHD_OPTION_CONNECTION_TIMEOUT,
        (unsigned)SERVE_IDLE_S, MHD_OPTION_CONNECTION_LIMIT, (unsigned)SERVE_MAX_CONNECTIONS,
        MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)SERVE_MAX_PER_IP, MHD_OPTION_END);
    if (!s->daemon) {
        snprintf(why, size,
                 "cannot listen on %s port %u (in use, or not an address of this "
                 "machine)",
                 opt->host, opt->port);
        *usage = true;
        serve_stop(s);
        return NULL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_BIND_PORT);
    s->port = info ? info->port : opt->port;
    return s;
}

unsigned serve_port(const serve *s)
{
    return s->port;
}

const char *serve_token(const serve *s)
{
    return s->token;
}

const char *serve_root(const serve *s)
{
    return s->root;
}

void serve_stop(serve *s)
{
    if (!s)
        return;
    serve_runs_stop(s); /* cancels the job, wakes the event streams */
    if (s->daemon)
        MHD_stop_daemon(s->daemon);
    serve_runs_free(s);
    serve_cubes_free(s);
    serve_photons_free(s);
    pthread_mutex_destroy(&s->photon_lock);
    pthread_mutex_destroy(&s->cache_lock);
    pthread_cond_destroy(&s->changed);
    pthread_mutex_destroy(&s->lock);
    free(s);
}
