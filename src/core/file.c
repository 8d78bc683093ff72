/* The regular-file check of input files, what a file is from its first bytes, and whether
 * a directory changed while it was read. */
#include "core/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

size_t file_read_head(const char *path, unsigned char *head)
{
    struct stat info;
    if (stat(path, &info) != 0 || !S_ISREG(info.st_mode))
        return 0;                              /* a FIFO would block the open */
    int fd = open(path, O_RDONLY | O_CLOEXEC); /* not stdio's: it allocates a buffer */
    if (fd < 0)
        return 0;
    size_t n = 0;
    while (n < FILE_HEAD_BYTES) {
        ssize_t got = read(fd, head + n, FILE_HEAD_BYTES - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            break;
        n += (size_t)got;
    }
    int saved = errno;
    close(fd);
    errno = saved;
    return n;
}

static bool file_starts(const unsigned char *head, size_t n, const char *magic, size_t len)
{
    return n >= len && memcmp(head, magic, len) == 0;
}

const char *file_kind_hint(const unsigned char *head, size_t n)
{
    static const struct {
        const char *magic;
        size_t offset, len;
        const char *what;
    } kinds[] = {
        {FILE_MAGIC_PHOTON_MAP, 0, 8,
         "a photon-map file, which `thzmap render --photon-map` reads"},
        {"ply\n", 0, 4,
         "a PLY mesh, which a scene names in a shape's \"file\", {\"type\": \"mesh\", \"file\": "
         "...}"},
        {"ply\r\n", 0, 5,
         "a PLY mesh, which a scene names in a shape's \"file\", {\"type\": \"mesh\", \"file\": "
         "...}"},
        {"glTF", 0, 4,
         "a glTF binary mesh, which a scene names in a shape's \"file\", {\"type\": \"mesh\", "
         "\"file\": ...}"},
        {"\x89PNG\r\n\x1a\n", 0, 8, "a PNG image"},
        {"ENVI", 0, 4, "an ENVI header"},
        {"ftyp", 4, 4, "an MP4 movie"},
    };
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (n >= kinds[i].offset &&
            file_starts(head + kinds[i].offset, n - kinds[i].offset, kinds[i].magic, kinds[i].len))
            return kinds[i].what;
    return NULL;
}

thz_status file_write_text(const char *path, const char *text, thz_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
    int why = 0; /* the first failure's errno: a full disk says so */
    errno = 0;
    if (fputs(text, f) < 0 || fputc('\n', f) == EOF)
        why = errno ? errno : EIO;
    if (fclose(f) != 0 && !why)
        why = errno ? errno : EIO;
    if (why)
        return thz_error_set(err, THZ_ERR_IO, "%s: write failed: %s", path, strerror(why));
    return THZ_OK;
}

bool file_dir_unchanged(const struct stat *a, const struct stat *b)
{
    return a->st_dev == b->st_dev && a->st_ino == b->st_ino &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec &&
           a->st_ctim.tv_sec == b->st_ctim.tv_sec && a->st_ctim.tv_nsec == b->st_ctim.tv_nsec;
}
