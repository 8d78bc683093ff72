/* Status and error messages: the one way every module reports failure.
 *
 * A fallible function returns a thz_status and, when err is not NULL, writes a
 * one-line message into it. Input errors name the file and line:column or JSON path.
 */
#ifndef THZ_CORE_ERROR_H
#define THZ_CORE_ERROR_H

#include "thzmap/thzmap.h"

/* Sets err (if not NULL) to status and a printf-formatted message; returns status so
 * that callers can write `return thz_error_set(err, THZ_ERR_INPUT, "...")`. */
thz_status thz_error_set(thz_error *err, thz_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Prefixes err's message with a printf-formatted context ("scene.json: "). */
void thz_error_prefix(thz_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The status of a C library or system call that failed with errno `errnum`:
 * THZ_ERR_NOMEM for ENOMEM (it could not allocate: no fault of the input or the disk),
 * `otherwise` for anything else. */
thz_status thz_errno_status(int errnum, thz_status otherwise);

/* A malloc'd copy of s that is valid UTF-8 without control characters: each control
 * byte and each byte that starts no valid UTF-8 character becomes the four characters
 * \xNN, as in every error message. NULL when out of memory. */
char *thz_text_clean(const char *s);

/* Clears err to THZ_OK and an empty message. */
void thz_error_clear(thz_error *err);

#endif
