/* thzmap serve: the browser GUI's server (docs/gui.md), until SIGINT or SIGTERM. */
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "progress.h"
#include "../serve/serve.h"

#define CMD "serve"

/* The front end's bundle of the build tree (CMake), used when no installed one exists. */
#ifndef THZ_WEB_BUILD_DIR
#define THZ_WEB_BUILD_DIR "web"
#endif

static void print_help(void)
{
    printf("usage: thzmap serve [--host 127.0.0.1] [--port 8765] [--root DIR]\n"
           "\n"
           "Serves the browser GUI (scene editor, runs, results) and its JSON API until\n"
           "Ctrl-C. Prints the URL to open, which holds a random access token; every\n"
           "request without the token is refused (401, 403). The API reads and writes\n"
           "files only under the root, and so do the scenes and sequences it loads: a\n"
           "file a scene names (mesh, table, response, line catalogue, a sequence's\n"
           "scene) that is absolute or lies outside the root, symlinks resolved, is\n"
           "refused. docs/gui.md describes the page and the API.\n"
           "\n"
           "options:\n"
           "  --host ADDR   the address to listen on (default 127.0.0.1, this machine\n"
           "                only; from another machine use an SSH tunnel:\n"
           "                ssh -L 8765:127.0.0.1:8765 HOST)\n"
           "  --port N      the TCP port (default 8765; 0: any free port)\n"
           "  --root DIR    the directory whose files the page may use (default: the\n"
           "                current directory)\n"
           "  -h, --help    this help\n");
}

/* Whether dir is an existing directory. */
static bool is_dir(const char *dir)
{
    struct stat st;
    return stat(dir, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The web bundle: THZMAP_WEB_DIR; else PREFIX/share/thzmap/web next to the installed
 * program (PREFIX/bin/thzmap); else the build tree's web/. Into out[PATH_MAX]. */
static void find_web_dir(char *out)
{
    const char *env = getenv("THZMAP_WEB_DIR");
    if (env && env[0]) {
        snprintf(out, PATH_MAX, "%s", env);
        return;
    }
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            int n_out = snprintf(out, PATH_MAX, "%s/../share/thzmap/web", exe);
            if (n_out > 0 && n_out < PATH_MAX && is_dir(out))
                return;
        }
    }
    snprintf(out, PATH_MAX, "%s", THZ_WEB_BUILD_DIR);
}

int cmd_serve(int argc, char **argv)
{
    serve_options opt = {.host = "127.0.0.1", .port = 8765, .root = "."};
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (cli_is_help(arg)) {
            print_help();
            return CLI_EXIT_OK;
        }
        static const char *const with_value[] = {"--host", "--port", "--root", NULL};
        char *val = NULL;
        int rc = cli_option_value(CMD, argc, argv, &i, with_value, &val);
        if (rc >= 0)
            return rc;
        uint64_t port = 0;
        if (strcmp(arg, "--host") == 0) {
            opt.host = val;
        } else if (strcmp(arg, "--root") == 0) {
            opt.root = val;
        } else {
            if (!cli_parse_u64(CMD, arg, val, 0, 65535, &port))
                return CLI_EXIT_USAGE;
            opt.port = (unsigned)port;
        }
    }
    if (!serve_available()) {
        fprintf(stderr, "thzmap serve: this thzmap was built without the web server (GNU "
                        "libmicrohttpd): install libmicrohttpd-dev and build again\n");
        return CLI_EXIT_USAGE;
    }
    char web_dir[PATH_MAX];
    find_web_dir(web_dir);
    opt.web_dir = web_dir;

    cli_signals_install();
    signal(SIGPIPE, SIG_IGN); /* a browser closing a connection is not an error */
    char why[512];
    bool usage = false;
    serve *s = serve_start(&opt, why, sizeof why, &usage);
    if (!s) {
        fprintf(stderr, "thzmap serve: %s\n", why);
        return usage ? CLI_EXIT_USAGE : CLI_EXIT_FAILURE;
    }
    bool v6 = strchr(opt.host, ':') != NULL;
    printf("thzmap serve: open http://%s%s%s:%u/?token=%s (root %s; Ctrl-C stops)\n", v6 ? "[" : "",
           opt.host, v6 ? "]" : "", serve_port(s), serve_token(s), serve_root(s));
    fflush(stdout);
    while (!cli_interrupt_signal()) {
        struct timespec ts = {.tv_sec = 0, .tv_nsec = 100000000};
        nanosleep(&ts, NULL);
    }
    fprintf(stderr, "thzmap serve: stopping (a running job is cancelled; its output is not "
                    "written, but for the frames a batch finished)\n");
    serve_stop(s);
    return 128 + cli_interrupt_signal();
}
