/* Input files: the one check every reader makes before it opens a file, so that a FIFO
 * or a device given as an input (which would block the open or never end) and a file
 * larger than the reader's limit are refused with a message instead of a hang or an
 * exhausted memory; and what a file is from its first bytes, for the message when a
 * file of one kind is given where another was expected.
 */
#ifndef THZ_CORE_FILE_H
#define THZ_CORE_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>

#include "core/error.h"

/* THZ_OK when path names a regular file (symbolic links followed) of at most max_bytes
 * bytes, with its size in *size_bytes (may be NULL). THZ_ERR_INPUT otherwise, with a
 * message that starts with `label` (NULL: path) and says what the path is instead (no
 * such file, a directory, a FIFO, a device, ...) or the size and the limit. Does not
 * open the file (opening a FIFO blocks). */
thz_status file_check_regular(const char *path, const char *label, uint64_t max_bytes,
                              uint64_t *size_bytes, thz_error *err);

/* The first bytes of thzmap's photon-map file (io/photon_map_file.h gives its layout). */
#define FILE_MAGIC_PHOTON_MAP "THZPMAP\x1a"
/* The bytes file_read_head reads (every magic below fits). */
#define FILE_HEAD_BYTES 16u

/* Reads up to FILE_HEAD_BYTES bytes from the start of the regular file at path into
 * head (its size at least FILE_HEAD_BYTES); returns how many, 0 when it cannot (errno
 * then says why). It allocates nothing. */
size_t file_read_head(const char *path, unsigned char *head);

/* What a file is from its first n bytes, as a phrase for a message: "a photon-map file,
 * which `thzmap render --photon-map` reads", "a PLY mesh, which a scene names in an
 * object's \"mesh\"", a glTF binary mesh, a PNG image, an ENVI header, an MP4 movie; NULL
 * for anything else (JSON among it). */
const char *file_kind_hint(const unsigned char *head, size_t n);

/* Writes text and a newline to path (created or replaced): THZ_ERR_IO naming path and
 * the first failure's reason ("No space left on device") when it cannot. */
thz_status file_write_text(const char *path, const char *text, thz_error *err);

/* Whether a directory stat'ed before and after reading files in it (a = before, b =
 * after) is the same and unchanged: a run's commit into it gives it a new inode (the
 * exchange) or renames files into it (a new modification or change time), so readers of
 * several files of one run (classify) read again when this is false. */
bool file_dir_unchanged(const struct stat *a, const struct stat *b);

#endif
