/* File paths: the one way to join a directory and a file name, so that a path that does
 * not fit its buffer is an error naming the path instead of a silently cut file name
 * (which would write a result under a wrong name).
 */
#ifndef THZ_CORE_PATH_H
#define THZ_CORE_PATH_H

#include <stddef.h>

#include "core/error.h"

/* The longest path, NUL included, that thzmap builds: Linux's PATH_MAX, beyond which
 * open(2) fails anyway. Path buffers are `char path[THZ_PATH_MAX]`. */
enum { THZ_PATH_MAX = 4096 };

/* Writes "dir/name" into out (size bytes, NUL included): one '/' between them even when
 * dir ends in '/', and name alone when dir is empty. THZ_ERR_IO with a message naming
 * the path and the limit if it does not fit (out then holds ""). */
thz_status thz_path_join(char *out, size_t size, const char *dir, const char *name, thz_error *err);

#endif
