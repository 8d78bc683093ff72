/* The regular-file check of input files. */
#include "core/file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

/* What a non-regular file is, for the message. */
static const char *file_kind(mode_t mode)
{
    if (S_ISDIR(mode))
        return "a directory";
    if (S_ISFIFO(mode))
        return "a FIFO (named pipe)";
    if (S_ISCHR(mode))
        return "a character device";
    if (S_ISBLK(mode))
        return "a block device";
    if (S_ISSOCK(mode))
        return "a socket";
    return "not a regular file";
}

thz_status file_check_regular(const char *path, const char *label, uint64_t max_bytes,
                              uint64_t *size_bytes, thz_error *err)
{
    const char *name = label ? label : path;
    struct stat info;
    if (stat(path, &info) != 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot open: %s", name, strerror(errno));
    if (!S_ISREG(info.st_mode))
        return thz_error_set(err, THZ_ERR_INPUT, "%s: is %s, expected a regular file", name,
                             file_kind(info.st_mode));
    uint64_t size = (uint64_t)info.st_size;
    if (size > max_bytes)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: is %llu bytes, more than the limit of %llu bytes (%llu MiB)",
                             name, (unsigned long long)size, (unsigned long long)max_bytes,
                             (unsigned long long)(max_bytes >> 20));
    if (size_bytes)
        *size_bytes = size;
    return THZ_OK;
}
