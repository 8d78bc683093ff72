/* Input files: the one check every reader makes before it opens a file, so that a FIFO
 * or a device given as an input (which would block the open or never end) and a file
 * larger than the reader's limit are refused with a message instead of a hang or an
 * exhausted memory.
 */
#ifndef THZ_CORE_FILE_H
#define THZ_CORE_FILE_H

#include <stdint.h>

#include "core/error.h"

/* THZ_OK when path names a regular file (symbolic links followed) of at most max_bytes
 * bytes, with its size in *size_bytes (may be NULL). THZ_ERR_INPUT otherwise, with a
 * message that starts with `label` (NULL: path) and says what the path is instead (no
 * such file, a directory, a FIFO, a device, ...) or the size and the limit. Does not
 * open the file (opening a FIFO blocks). */
thz_status file_check_regular(const char *path, const char *label, uint64_t max_bytes,
                              uint64_t *size_bytes, thz_error *err);

#endif
