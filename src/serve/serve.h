/* `thzmap serve`: the HTTP server of the browser GUI (docs/gui.md), a client of the
 * public library API like the rest of the program. src/serve/ is the only code that
 * includes microhttpd.h; the command (src/cli/cmd_serve.c) starts and stops it and does
 * all the printing.
 */
#ifndef THZ_SERVE_SERVE_H
#define THZ_SERVE_SERVE_H

#include <stdbool.h>
#include <stddef.h>

typedef struct serve_options {
    const char *host;    /* address to bind: "127.0.0.1" (default), "::1", "0.0.0.0", ... */
    unsigned port;       /* 0: a free port */
    const char *root;    /* an existing directory; the process works inside it */
    const char *web_dir; /* the front end's bundle; NULL or missing: a page says so */
} serve_options;

typedef struct serve serve;

/* Whether this build has the server (libmicrohttpd was found at build time). */
bool serve_available(void);

/* Starts the server (its threads run until serve_stop). The process's working directory
 * becomes the root. On failure returns NULL with a one-line reason in why[size]; *usage
 * is then true when the options are at fault (port taken, bad address, root missing). */
serve *serve_start(const serve_options *opt, char *why, size_t size, bool *usage);

/* The port it listens on, the access token (32 hex digits) and the resolved root. */
unsigned serve_port(const serve *s);
const char *serve_token(const serve *s);
const char *serve_root(const serve *s);

/* Stops: cancels the running job (its output is removed, as in an interrupted run),
 * drops the queued ones, closes every connection and frees everything. NULL: nothing. */
void serve_stop(serve *s);

#endif
