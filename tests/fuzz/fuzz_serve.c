/* Fuzzes `thzmap serve` (src/serve/) with what a client sends: the input is the raw bytes
 * of an HTTP connection (request line, headers, body; several requests when they are
 * pipelined), in which every "TOKEN" stands for the server's access token. The harness
 * runs the server in this process (serve_start, once) over a copy of
 * tests/fuzz/files/serve/root/ (two small runs, one with a photon map, their scenes) with
 * files/serve/web/ as the page, and hands it each input through a socket pair
 * (MHD_add_connection): libmicrohttpd parses the request, serve_http.c checks the token,
 * the size and the query, and routes it to the endpoint, which parses its query and body
 * (serve_runs_post.c: POST /api/runs; serve_scene.c: /api/validate; the paths of
 * serve_paths.c; the cubes, pixels, differences and photon maps of the runs).
 * The job thread is stopped at the start: a POST /api/runs is parsed and checked as
 * ever, then refused with 409 instead of running (a run would take the fuzzer's time
 * and change the root).
 *
 * What the server promises, checked on each input: an answer is HTTP with a status; an
 * answer of the server's own (its headers, application/json) is a JSON object or array,
 * with an "error" string when the status is 400 or more; no answer is 500 (the server's
 * own failure: bad input is 4xx); nothing is written outside the root. A PUT may change
 * the root: it is then copied afresh, so that every input starts from the same files.
 * FUZZ_VERBOSE=1 prints the answers (triage with fuzz_replay_serve).
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <jansson.h>
#include <limits.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/run_command.h"
#include "fuzz.h"
#include "serve/serve_internal.h"

/* The CLI's exit guard (src/cli/run_command.c), which serve_runs.c gives a running job:
 * no job runs here (the job thread is stopped), and the CLI is not linked. */
thz_output **cli_exit_guard(void)
{
    static thz_output *slot;
    return &slot;
}

static char parent[PATH_MAX]; /* holds the root and nothing else */
static char root[PATH_MAX];
static serve *server;
static long long root_time; /* the newest change under the root when it was copied, ns */
static size_t root_entries;

/* ---- the root: copied from files/serve/root, checked after each input --------------- */

static const char *copy_from, *copy_to;

static int copy_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)ftw;
    char to[PATH_MAX];
    if (snprintf(to, sizeof to, "%s%s", copy_to, path + strlen(copy_from)) >= (int)sizeof to)
        abort();
    if (flag == FTW_D)
        return mkdir(to, 0755) != 0 && errno != EEXIST;
    if (flag != FTW_F)
        return 1;
    FILE *in = fopen(path, "rb"), *out = fopen(to, "wb");
    if (!in || !out)
        abort();
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, out) != n)
            abort();
    fclose(in);
    if (fclose(out) != 0)
        abort();
    (void)st;
    return 0;
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag;
    if (ftw->level > 0) /* the root stays: it is the server's working directory */
        remove(path);
    return 0;
}

/* The newest modification or change time under the root (ns) and its entries. */
static long long newest;
static size_t entries;
static int survey_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)path, (void)flag, (void)ftw;
    entries++;
    long long m = st->st_mtim.tv_sec * 1000000000LL + st->st_mtim.tv_nsec;
    long long c = st->st_ctim.tv_sec * 1000000000LL + st->st_ctim.tv_nsec;
    newest = m > newest ? m : newest;
    newest = c > newest ? c : newest;
    return 0;
}

static void survey(void)
{
    newest = 0;
    entries = 0;
    nftw(root, survey_entry, 16, FTW_PHYS);
}

static void fresh_root(void)
{
    nftw(root, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    copy_from = FUZZ_DIR "/files/serve/root";
    copy_to = root;
    if (nftw(copy_from, copy_entry, 16, FTW_PHYS) != 0)
        abort();
    survey();
    root_time = newest;
    root_entries = entries;
}

static void stop_server(void)
{
    serve_stop(server);
    nftw(root, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    rmdir(root);
    rmdir(parent);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_use_fixture_data();
    const char *tmp = getenv("TMPDIR");
    if (snprintf(parent, sizeof parent, "%s/thz-fuzz-serve-XXXXXX", tmp && *tmp ? tmp : "/tmp") >=
        (int)sizeof parent)
        abort();
    if (!mkdtemp(parent))
        abort();
    if (snprintf(root, sizeof root, "%s/root", parent) >= (int)sizeof root)
        abort();
    if (mkdir(root, 0755) != 0)
        abort();
    fresh_root();
    serve_options opt = {
        .host = "127.0.0.1", .port = 0, .root = root, .web_dir = FUZZ_DIR "/files/serve/web"};
    char why[512];
    bool usage;
    server = serve_start(&opt, why, sizeof why, &usage);
    if (!server) {
        fprintf(stderr, "fuzz_serve: %s\n", why);
        abort();
    }
    serve_runs_stop(server); /* POST /api/runs: checked, then 409 */
    atexit(stop_server);
    return 0;
}

/* ---- one connection ------------------------------------------------------------------ */

/* The input with every "TOKEN" replaced by the token (malloc'd, *size updated). */
static char *with_token(const uint8_t *data, size_t *size)
{
    const char *token = serve_token(server);
    size_t tlen = strlen(token), n = *size;
    char *out = malloc(n / 5 * tlen + n + 1);
    size_t o = 0;
    for (size_t i = 0; i < n;) {
        if (i + 5 <= n && memcmp(data + i, "TOKEN", 5) == 0) {
            memcpy(out + o, token, tlen);
            o += tlen;
            i += 5;
        } else {
            out[o++] = (char)data[i++];
        }
    }
    out[o] = '\0';
    *size = o;
    return out;
}

/* Sends request[0..n) on a new connection, the write side then closed, and reads the
 * answer until the server closes (malloc'd, NUL-terminated, *got bytes). */
static char *exchange(const char *request, size_t n, size_t *got)
{
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0)
        abort();
    struct sockaddr_in peer = {.sin_family = AF_INET, .sin_port = htons(40000)};
    peer.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (MHD_add_connection(server->daemon, sv[1], (const struct sockaddr *)&peer, sizeof peer) !=
        MHD_YES)
        abort();
    fcntl(sv[0], F_SETFL, O_NONBLOCK);
    size_t sent = 0, cap = 65536, len = 0;
    char *answer = malloc(cap);
    bool write_open = true;
    for (;;) {
        if (write_open && sent == n) {
            shutdown(sv[0], SHUT_WR);
            write_open = false;
        }
        struct pollfd p = {.fd = sv[0], .events = (short)(POLLIN | (write_open ? POLLOUT : 0))};
        int r = poll(&p, 1, 20000);
        if (r == 0) {
            fprintf(stderr, "fuzz_serve: no answer within 20 s\n");
            abort();
        }
        if (r < 0)
            continue;
        if (write_open && (p.revents & POLLOUT)) {
            ssize_t w = send(sv[0], request + sent, n - sent, MSG_NOSIGNAL);
            if (w > 0)
                sent += (size_t)w;
            else if (w < 0 && errno != EAGAIN && errno != EINTR)
                write_open = false; /* the server closed: its answer is read below */
        }
        if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
            if (len + 65536 + 1 > cap) {
                cap *= 2;
                answer = realloc(answer, cap);
            }
            ssize_t m = recv(sv[0], answer + len, cap - len - 1, 0);
            if (m > 0)
                len += (size_t)m;
            else if (m == 0 || (errno != EAGAIN && errno != EINTR))
                break;
        }
    }
    close(sv[0]);
    answer[len] = '\0';
    *got = len;
    return answer;
}

/* ---- the checks ---------------------------------------------------------------------- */

static void fail(const char *why, const char *answer)
{
    fprintf(stderr, "fuzz_serve: %s; the answer:\n%.2000s\n", why, answer);
    abort();
}

/* The value of header `name` in the head (up to the blank line), or NULL. */
static const char *header(const char *head, const char *head_end, const char *name, size_t *len)
{
    size_t nl = strlen(name);
    for (const char *p = strstr(head, "\r\n"); p && p < head_end; p = strstr(p + 2, "\r\n")) {
        const char *h = p + 2;
        if (strncasecmp(h, name, nl) == 0 && h[nl] == ':') {
            const char *v = h + nl + 1;
            while (*v == ' ')
                v++;
            const char *e = strstr(v, "\r\n");
            *len = e ? (size_t)(e - v) : strlen(v);
            return v;
        }
    }
    return NULL;
}

/* Checks the answer at a (n bytes); returns the length of the answer when it can tell
 * (a Content-Length, and no HEAD among the requests, whose answers have none), else 0:
 * what follows belongs to pipelined requests. */
static size_t check_answer(const char *a, size_t n, bool head_request)
{
    unsigned status = 0;
    if ((strncmp(a, "HTTP/1.1 ", 9) != 0 && strncmp(a, "HTTP/1.0 ", 9) != 0) ||
        sscanf(a + 9, "%3u", &status) != 1 || status < 100 || status > 599)
        fail("not an HTTP answer", a);
    const char *end = strstr(a, "\r\n\r\n");
    if (!end)
        fail("an answer without the blank line after its headers", a);
    if (status == 500)
        fail("500: the server failed on its own (bad input is 4xx)", a);
    size_t tlen = 0, llen = 0, olen = 0;
    const char *type = header(a, end, "Content-Type", &tlen);
    const char *length = header(a, end, "Content-Length", &llen);
    /* libmicrohttpd's own answers (a 400 page for what is no valid HTTP) lack the server's
     * headers; it may write their head twice (0.9.75, on a bad Content-Length): what
     * follows one is not checked */
    bool own = header(a, end, "X-Content-Type-Options", &olen) != NULL;
    if (head_request || !length || !own)
        return 0;
    size_t body_len = strtoul(length, NULL, 10);
    const char *body = end + 4;
    if ((size_t)(a + n - body) < body_len)
        fail("an answer shorter than its Content-Length", a);
    if (type && strncmp(type, "application/json", 16) == 0) {
        json_t *doc = json_loadb(body, body_len, 0, NULL);
        if (!json_is_object(doc) && !json_is_array(doc))
            fail("a JSON answer that is no JSON object or array", a);
        if (status >= 400 && !json_is_string(json_object_get(doc, "error")))
            fail("an error without an \"error\" string", a);
        json_decref(doc);
    }
    return (size_t)(body + body_len - a);
}

/* Nothing beside the root in its parent directory. */
static void check_outside(void)
{
    DIR *d = opendir(parent);
    if (!d)
        abort();
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strcmp(e->d_name, "root")) {
            fprintf(stderr, "fuzz_serve: %s/%s written outside the root\n", parent, e->d_name);
            abort();
        }
    closedir(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t n = size;
    char *request = with_token(data, &n);
    bool head_request = strstr(request, "HEAD") != NULL; /* (a NUL ends the search early:
                                                             MHD refuses what follows) */
    size_t got = 0;
    char *answer = exchange(request, n, &got);
    if (getenv("FUZZ_VERBOSE")) /* triage: the answers as they came */
        fwrite(answer, 1, got, stderr);
    /* closed without an answer: MHD's choice on what is no HTTP at all */
    for (size_t at = 0, len = 1; at < got && len > 0; at += len)
        len = check_answer(answer + at, got - at, head_request);
    free(answer);
    free(request);
    check_outside();
    survey();
    if (newest != root_time || entries != root_entries)
        fresh_root();
    return 0;
}
