/* Status and error messages. */
#include "core/error.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The length of the valid UTF-8 character at s (at most n bytes), or 0 when s does not
 * start one (a stray continuation byte, an overlong form, a surrogate, beyond U+10FFFF or
 * cut short). */
static size_t utf8_char_length(const unsigned char *s, size_t n)
{
    unsigned char c = s[0];
    size_t len = c >= 0xc2 && c <= 0xdf   ? 2
                 : c >= 0xe0 && c <= 0xef ? 3
                 : c >= 0xf0 && c <= 0xf4 ? 4
                                          : 0;
    if (len == 0 || len > n)
        return 0;
    for (size_t i = 1; i < len; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    if ((c == 0xe0 && s[1] < 0xa0) || (c == 0xed && s[1] >= 0xa0) || (c == 0xf0 && s[1] < 0x90) ||
        (c == 0xf4 && s[1] >= 0x90))
        return 0;
    return len;
}

/* Writes the text of in[0..n) into out (room for cap bytes and the NUL), each control
 * byte and each byte that starts no valid UTF-8 character as the four characters \xNN;
 * cut at a character where the escapes overflow. Returns the bytes written. */
static size_t text_clean_into(char *out, size_t cap, const char *in, size_t n)
{
    size_t w = 0;
    for (size_t i = 0; i < n;) {
        const unsigned char *c = (const unsigned char *)in + i;
        size_t len = *c >= 0x80 ? utf8_char_length(c, n - i) : (*c < 0x20 || *c == 0x7f ? 0 : 1);
        size_t need = len ? len : 4;
        if (w + need > cap)
            break;
        if (len)
            memcpy(out + w, c, len);
        else
            snprintf(out + w, 5, "\\x%02x", *c);
        w += need;
        i += len ? len : 1;
    }
    out[w] = '\0';
    return w;
}

/* Rewrites msg (a C string in cap bytes) so that it is one line of valid UTF-8 (as
 * text_clean_into). Messages quote what they refused (a CSV cell, a mesh token), and raw
 * bytes from a file would reach the terminal as control sequences, and the GUI server's
 * and Python's JSON and str as invalid text. Idempotent (what it writes is ASCII it
 * leaves alone). */
static void error_clean(char *msg, size_t cap)
{
    char in[sizeof((thz_error *)0)->message];
    size_t n = strnlen(msg, cap - 1);
    if (n >= sizeof in)
        n = sizeof in - 1;
    memcpy(in, msg, n);
    text_clean_into(msg, cap - 1, in, n);
}

char *thz_text_clean(const char *s)
{
    size_t n = strlen(s);
    char *out = malloc(4 * n + 1);
    if (out)
        text_clean_into(out, 4 * n, s, n);
    return out;
}

thz_status thz_error_set(thz_error *err, thz_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        error_clean(err->message, sizeof err->message);
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
    error_clean(err->message, sizeof err->message);
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
