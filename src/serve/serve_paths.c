/* Paths confined to the root, the file endpoints (list, read, atomic write) and the
 * front end's static files. */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "serve_internal.h"

/* Whether the absolute, resolved path `real` is `base` or lies below it. */
static bool serve_below(const char *base, const char *real)
{
    size_t n = strlen(base);
    if (strncmp(real, base, n) != 0)
        return false;
    return real[n] == '\0' || real[n] == '/' || (n == 1 && base[0] == '/');
}

bool serve_path_inside(const serve *s, const char *path)
{
    char real[PATH_MAX];
    return realpath(path, real) && serve_below(s->root, real);
}

/* Whether REL is relative and has no ".." component ("." and empty components, as in
 * "a/./b", "a//b" or a trailing '/', are allowed: they name the same file). */
static bool serve_rel_clean(const char *rel)
{
    if (rel[0] == '/')
        return false;
    for (const char *p = rel; *p;) {
        const char *end = strchr(p, '/');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (n == 2 && p[0] == '.' && p[1] == '.')
            return false;
        p += n + (end != NULL);
    }
    return true;
}

serve_path_status serve_path(const serve *s, const char *rel, bool must_exist, char *out)
{
    if (rel && strlen(rel) >= SERVE_MAX_REL_BYTES)
        return SERVE_PATH_TOO_LONG;
    if (!rel || !serve_rel_clean(rel))
        return SERVE_PATH_FORBIDDEN;
    if (rel[0] == '\0' || strcmp(rel, ".") == 0 || strcmp(rel, "./") == 0) {
        strcpy(out, ".");
        return SERVE_PATH_OK;
    }
    snprintf(out, PATH_MAX, "%s", rel);
    /* the path itself, or its deepest existing (or enterable) ancestor, must resolve
     * inside the root; a directory the server may not enter is told as such only when
     * what leads to it lies inside the root (else it says nothing of what is outside) */
    char probe[PATH_MAX], real[PATH_MAX];
    snprintf(probe, sizeof probe, "%s", rel);
    bool denied = false, whole = true; /* whole: probe is still the path itself */
    for (;;) {
        if (realpath(probe, real))
            break;
        whole = false;
        if (errno == EACCES) {
            denied = true;
        } else if (errno == ENAMETOOLONG) { /* a name longer than the file system's */
            return SERVE_PATH_TOO_LONG;
        } else if (errno != ENOENT && errno != ENOTDIR) {
            return SERVE_PATH_FORBIDDEN;
        } else if (!denied) {
            struct stat lst;
            if (lstat(probe, &lst) == 0) /* a dangling symlink: where it points is unknown */
                return SERVE_PATH_FORBIDDEN;
            if (must_exist)
                return SERVE_PATH_MISSING;
        }
        char *slash = strrchr(probe, '/');
        while (slash && slash > probe && slash[-1] == '/')
            slash--;
        if (!slash || slash == probe) {
            strcpy(probe, ".");
            continue;
        }
        *slash = '\0';
    }
    if (!serve_below(s->root, real))
        return SERVE_PATH_FORBIDDEN;
    /* inside the root, but a file the server may not read or a directory it may not list:
     * told as such (a listing said "not a directory", a pixel "no cube") */
    struct stat st;
    if (whole && !denied && stat(real, &st) == 0 &&
        access(real, S_ISDIR(st.st_mode) ? R_OK | X_OK : R_OK) != 0 && errno == EACCES)
        denied = true;
    return denied ? SERVE_PATH_DENIED : SERVE_PATH_OK;
}

enum MHD_Result serve_reply_path(serve_request *r, serve_path_status st, const char *label,
                                 const char *sep, const char *rel)
{
    switch (st) {
    case SERVE_PATH_FORBIDDEN:
        return serve_reply_error(r, 403, "%s%s%s: outside the root, absolute, or with '..'", label,
                                 sep, rel);
    case SERVE_PATH_DENIED:
        return serve_reply_error(r, 403, "%s%s%s: permission denied", label, sep, rel);
    case SERVE_PATH_MISSING:
        return serve_reply_error(r, 404, "%s%s%s: no such file or directory", label, sep, rel);
    case SERVE_PATH_TOO_LONG:
        if (strlen(rel) < SERVE_MAX_REL_BYTES) /* one name too long for the file system */
            return serve_reply_error(r, 400,
                                     "%s: a name in the path is longer than the file "
                                     "system allows",
                                     label);
        return serve_reply_error(r, 400, "%s: a path of %zu bytes, longer than the %d allowed",
                                 label, strlen(rel), SERVE_MAX_REL_BYTES - 1);
    default:
        return serve_reply_error(r, 500, "%s%s%s: unexpected path status", label, sep, rel);
    }
}

bool serve_path_arg(serve_request *r, const char *name, bool must_exist, char *out,
                    enum MHD_Result *result)
{
    const char *rel = serve_arg(r, name);
    if (!rel) {
        *result = serve_reply_error(r, 400, "missing query parameter '%s'", name);
        return false;
    }
    serve_path_status st = serve_path(r->s, rel, must_exist, out);
    if (st != SERVE_PATH_OK) {
        *result = serve_reply_path(r, st, name, "=", rel);
    }
    return st == SERVE_PATH_OK;
}

int serve_open_regular(const char *path)
{
    /* stat first: opening a device may act on it; O_NONBLOCK: a FIFO swapped in between
     * does not wait for a writer, and fstat tells what was opened */
    struct stat st;
    if (stat(path, &st) != 0)
        return -1;
    if (!S_ISREG(st.st_mode)) {
        errno = EINVAL;
        return -1;
    }
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -1;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        errno = EINVAL;
        return -1;
    }
    return fd;
}

json_t *serve_read_json(const char *path)
{
    char why[256];
    return serve_read_json_why(path, why, sizeof why);
}

json_t *serve_read_json_why(const char *path, char *why, size_t size)
{
    size_t n = 0;
    why[0] = '\0';
    errno = 0;
    char *text = serve_read_file(path, SERVE_MAX_FILE_BYTES, &n);
    if (!text) {
        if (errno == EINVAL)
            snprintf(why, size, "%s: not a regular file", path);
        else if (errno == EFBIG)
            snprintf(why, size, "%s: larger than the %u MiB read", path,
                     SERVE_MAX_FILE_BYTES >> 20);
        else if (errno == EACCES)
            snprintf(why, size, "%s: permission denied", path);
        else if (errno != ENOENT)
            snprintf(why, size, "%s: %s", path, errno ? strerror(errno) : "cannot be read");
        return NULL;
    }
    json_error_t error;
    json_t *doc = json_loadb(text, n, 0, &error);
    free(text);
    if (!doc) { /* the parser's words may quote bytes that are not UTF-8 */
        snprintf(why, size, "%s: line %d, column %d: %s", path, error.line, error.column,
                 error.text);
        serve_text_fit(why);
        serve_text_utf8(why);
    }
    return doc;
}

char *serve_read_file(const char *path, size_t max, size_t *size)
{
    int fd = serve_open_regular(path);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    struct stat st;
    char *buf = NULL;
    if (fstat(fileno(f), &st) == 0 && (uint64_t)st.st_size > max)
        errno = EFBIG;
    else if (fstat(fileno(f), &st) == 0 && (buf = malloc((size_t)st.st_size + 1))) {
        size_t n = fread(buf, 1, (size_t)st.st_size, f);
        if (n != (size_t)st.st_size) {
            free(buf);
            buf = NULL;
            errno = EIO;
        } else {
            buf[n] = '\0';
            if (size)
                *size = n;
        }
    }
    fclose(f);
    return buf;
}

static int serve_entry_cmp(const void *a, const void *b)
{
    const char *x = json_string_value(json_object_get(*(json_t *const *)a, "name"));
    const char *y = json_string_value(json_object_get(*(json_t *const *)b, "name"));
    return strcmp(x, y);
}

enum MHD_Result serve_files_list(serve_request *r)
{
    char dir[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    if (!serve_arg(r, "dir"))
        strcpy(dir, ".");
    else if (!serve_path_arg(r, "dir", true, dir, &ret))
        return ret;
    DIR *d = opendir(dir);
    if (!d && errno == EACCES)
        return serve_reply_error(r, 403, "%s: permission denied", dir);
    if (!d)
        return serve_reply_error(r, errno == ENOTDIR ? 400 : 404, "%s: %s", dir, strerror(errno));
    json_t *list = json_array();
    size_t n = 0, cap = 0;
    json_t **items = NULL;
    for (struct dirent *e; (e = readdir(d));) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char path[PATH_MAX];
        struct stat st;
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path ||
            stat(path, &st) != 0 || !serve_path_inside(r->s, path))
            continue;
        if (!S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            json_t **grown = realloc(items, cap * sizeof *items);
            if (!grown)
                break;
            items = grown;
        }
        /* (a name that is not UTF-8 cannot be told in JSON: left out) */
        items[n] = json_pack("{s:s, s:s, s:I, s:I}", "name", e->d_name, "type",
                             S_ISDIR(st.st_mode) ? "dir" : "file", "size", (json_int_t)st.st_size,
                             "mtime", (json_int_t)st.st_mtime);
        n += items[n] != NULL;
    }
    closedir(d);
    if (n > 1) /* (items is NULL when nothing was listed) */
        qsort(items, n, sizeof *items, serve_entry_cmp);
    for (size_t i = 0; i < n; i++)
        json_array_append_new(list, items[i]);
    free(items);
    const char *rel = serve_arg(r, "dir");
    return serve_reply_json(r, 200,
                            json_pack("{s:s, s:o}", "dir", rel ? rel : "", "entries", list));
}

static bool serve_ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* The type a file under the root is served as: images, movies and text that a page can
 * show; never HTML, SVG or scripts (a file in the root must not run in the page's
 * origin), which go as plain bytes. */
static const char *serve_data_type(const char *path)
{
    static const char *const types[][2] = {
        {".json", "application/json"},
        {".png", "image/png"},
        {".jpg", "image/jpeg"},
        {".jpeg", "image/jpeg"},
        {".mp4", "video/mp4"},
        {".csv", "text/plain; charset=utf-8"},
        {".hdr", "text/plain; charset=utf-8"},
        {".txt", "text/plain; charset=utf-8"},
        {".md", "text/plain; charset=utf-8"},
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (serve_ends_with(path, types[i][0]))
            return types[i][1];
    return "application/octet-stream";
}

enum MHD_Result serve_file_get(serve_request *r)
{
    char path[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    if (!serve_path_arg(r, "path", true, path, &ret))
        return ret;
    /* the descriptor of the checked path: what is sent is what was opened, streamed */
    int fd = serve_open_regular(path);
    if (fd < 0) {
        int e = errno;
        if (e == EACCES)
            return serve_reply_error(r, 403, "%s: permission denied", path);
        if (e == ENOENT)
            return serve_reply_error(r, 404, "%s: no such file or directory", path);
        return serve_reply_error(r, 400, "%s: %s", path,
                                 e == EINVAL ? "not a regular file" : strerror(e));
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        close(fd);
        return serve_reply_error(r, 500, "%s: %s", path, strerror(errno));
    }
    return serve_reply_fd(r, serve_data_type(path), fd, (uint64_t)st.st_size);
}

/* The process's umask, read without changing it (umask(2) would, for an instant, for
 * every thread): /proc/self/status's "Umask:" line (Linux 4.7 on); 022 without it. */
static mode_t serve_umask(void)
{
    FILE *f = fopen("/proc/self/status", "re");
    unsigned mask = 022;
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Umask: %o", &mask) == 1)
            break;
    if (f)
        fclose(f);
    return (mode_t)(mask & 0777);
}

/* Writes data to path through a temporary file in the same directory, renamed over it.
 * The file keeps the mode (and, where this process may set them, the owner and group) of
 * the one it replaces; a new one gets 0666 less the umask, as an editor's would. */
static int serve_write_atomic(const char *path, const char *data, size_t size)
{
    /* in the same directory, with a short name of its own: "<name>.tmp-XXXXXX" passed the
     * 255 bytes a name may have for names from 245 bytes on */
    char tmp[PATH_MAX + 32];
    const char *slash = strrchr(path, '/');
    int dir_len = slash ? (int)(slash - path + 1) : 0;
    snprintf(tmp, sizeof tmp, "%.*s.thzmap-put-XXXXXX", dir_len, path);
    int fd = mkstemp(tmp);
    if (fd < 0)
        return errno;
    int e = 0;
    for (size_t done = 0; done < size && !e;) {
        ssize_t n = write(fd, data + done, size - done);
        if (n < 0 && errno != EINTR)
            e = errno;
        else if (n > 0)
            done += (size_t)n;
    }
    struct stat old;
    bool replaces = stat(path, &old) == 0;
    if (!e && fchmod(fd, replaces ? old.st_mode & 07777 : 0666 & ~serve_umask()) != 0)
        e = errno;
    if (!e && replaces && (old.st_uid != geteuid() || old.st_gid != getegid()) &&
        fchown(fd, old.st_uid, old.st_gid) != 0) {
        /* not allowed: kept as created, owned by whoever runs the server */
    }
    if (!e && fsync(fd) != 0)
        e = errno;
    if (close(fd) != 0 && !e)
        e = errno;
    if (!e && rename(tmp, path) != 0)
        e = errno;
    if (e)
        unlink(tmp);
    return e;
}

enum MHD_Result serve_file_put(serve_request *r)
{
    char path[PATH_MAX];
    enum MHD_Result ret = MHD_NO;
    if (!serve_path_arg(r, "path", false, path, &ret))
        return ret;
    if (!serve_ends_with(path, ".json"))
        return serve_reply_error(r, 403, "%s: only .json files are written", path);
    if (memchr(r->body ? r->body : "", '\0', r->body_size))
        return serve_reply_error(r, 400, "%s: the body is not text", path);
    struct stat st;
    if (lstat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return serve_reply_error(r, 403, "%s: not a regular file", path);
    int e = serve_write_atomic(path, r->body ? r->body : "", r->body_size);
    if (e == EACCES || e == EPERM || e == EROFS) /* the server may not write there */
        return serve_reply_error(r, 403, "%s: permission denied (%s)", path, strerror(e));
    if (e)
        return serve_reply_error(r, e == ENOENT ? 404 : 500, "%s: %s", path, strerror(e));
    const char *rel = serve_arg(r, "path");
    return serve_reply_json(r, 200,
                            json_pack("{s:s, s:I}", "path", rel, "size", (json_int_t)r->body_size));
}

static const char *serve_mime(const char *path)
{
    static const char *const types[][2] = {
        {".html", "text/html; charset=utf-8"},
        {".js", "text/javascript; charset=utf-8"},
        {".mjs", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},
        {".json", "application/json"},
        {".svg", "image/svg+xml"},
        {".png", "image/png"},
        {".ico", "image/x-icon"},
        {".woff2", "font/woff2"},
        {".map", "application/json"},
        {".wasm", "application/wasm"},
        {".txt", "text/plain; charset=utf-8"},
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (serve_ends_with(path, types[i][0]))
            return types[i][1];
    return "application/octet-stream";
}

static const char serve_no_web[] =
    "<!doctype html><html><head><meta charset=utf-8><title>thzmap</title></head><body>"
    "<h1>thzmap serve</h1><p>The front end was not built (no web bundle was found: build "
    "web/ with the project, or set THZMAP_WEB_DIR). The JSON API under /api/ works; "
    "docs/gui.md describes it.</p></body></html>";

enum MHD_Result serve_static(serve_request *r)
{
    const char *url = r->url;
    bool index = strcmp(url, "/") == 0 || strcmp(url, "/index.html") == 0;
    if (!index && strncmp(url, "/assets/", 8) != 0 && strncmp(url, "/favicon", 8) != 0)
        return serve_reply_error(r, 404, "not found: %s", url);
    if (!r->s->has_web)
        return index ? serve_reply(r, 200, "text/html; charset=utf-8", serve_no_web,
                                   sizeof serve_no_web - 1)
                     : serve_reply_error(r, 404, "not found (no front end built): %s", url);
    const char *rel = index ? "index.html" : url + 1;
    if (!serve_rel_clean(rel))
        return serve_reply_error(r, 403, "forbidden: %s", url);
    char path[PATH_MAX], real[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", r->s->web_dir, rel) >= (int)sizeof path ||
        !realpath(path, real) || !serve_below(r->s->web_dir, real))
        return serve_reply_error(r, 404, "not found: %s", url);
    size_t size = 0;
    char *data = serve_read_file(real, SERVE_MAX_FILE_BYTES, &size);
    if (!data)
        return serve_reply_error(r, 404, "not found: %s", url);
    enum MHD_Result ret = serve_reply(r, 200, serve_mime(real), data, size);
    free(data);
    return ret;
}
