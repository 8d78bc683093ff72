/* Joining a directory and a file name, with the length checked. */
#include "core/path.h"

#include <string.h>

thz_status thz_path_join(char *out, size_t size, const char *dir, const char *name, thz_error *err)
{
    size_t d = strlen(dir), n = strlen(name);
    const char *sep = (d == 0 || dir[d - 1] == '/') ? "" : "/";
    size_t s = strlen(sep);
    if (size == 0 || d + s + n >= size) {
        if (size)
            out[0] = '\0';
        /* The limit first: a path this long fills most of the message and is cut. A path
         * too long is the caller's (a directory named too deep), so bad input: exit 2. */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "path of %zu bytes, longer than the limit of %zu bytes: %s%s%s",
                             d + s + n, size ? size - 1 : 0, dir, sep, name);
    }
    memcpy(out, dir, d);
    memcpy(out + d, sep, s);
    memcpy(out + d + s, name, n + 1);
    return THZ_OK;
}
