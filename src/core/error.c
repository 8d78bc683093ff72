/* Status and error messages. */
#include "core/error.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

thz_status thz_error_set(thz_error *err, thz_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void thz_error_prefix(thz_error *err, const char *fmt, ...)
{
    if (!err)
        return;
    char prefix[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    char joined[sizeof err->message];
    size_t n = strlen(prefix);
    if (n >= sizeof joined)
        n = sizeof joined - 1;
    memcpy(joined, prefix, n);
    size_t rest = strnlen(err->message, sizeof err->message - 1);
    if (rest > sizeof joined - 1 - n)
        rest = sizeof joined - 1 - n;
    memcpy(joined + n, err->message, rest);
    joined[n + rest] = '\0';
    memcpy(err->message, joined, sizeof joined);
}

thz_status thz_errno_status(int errnum, thz_status otherwise)
{
    return errnum == ENOMEM ? THZ_ERR_NOMEM : otherwise;
}

void thz_error_clear(thz_error *err)
{
    if (err) {
        err->status = THZ_OK;
        err->message[0] = '\0';
    }
}

const char *thz_version(void)
{
    return THZ_VERSION_STRING;
}

const char *thz_status_name(thz_status status)
{
    switch (status) {
    case THZ_OK:
        return "ok";
    case THZ_ERR_INPUT:
        return "bad input";
    case THZ_ERR_IO:
        return "input/output error";
    case THZ_ERR_NOMEM:
        return "out of memory";
    case THZ_ERR_LIMIT:
        return "over a limit";
    case THZ_ERR_CANCELLED:
        return "cancelled";
    case THZ_ERR_INTERNAL:
        return "internal error";
    }
    return "unknown status";
}
