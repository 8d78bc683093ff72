/* `thzmap serve` in a build without GNU libmicrohttpd: the command says so (CMake
 * compiles this file instead of the server's). */
#include <stdio.h>

#include "serve.h"

bool serve_available(void)
{
    return false;
}

serve *serve_start(const serve_options *opt, char *why, size_t size, bool *usage)
{
    (void)opt;
    *usage = true;
    snprintf(why, size, "built without GNU libmicrohttpd");
    return NULL;
}

unsigned serve_port(const serve *s)
{
    (void)s;
    return 0;
}

const char *serve_token(const serve *s)
{
    (void)s;
    return "";
}

const char *serve_root(const serve *s)
{
    (void)s;
    return "";
}

void serve_stop(serve *s)
{
    (void)s;
}
