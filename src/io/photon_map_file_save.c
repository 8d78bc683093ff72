/* photon-map.thzpm saved in place of a file: written beside it and renamed
 * (photon_map_file.h). */
#define _GNU_SOURCE /* gettid */
#include "io/photon_map_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/path.h"

thz_status photon_map_file_save(const char *path, const thz_scene *scene,
                                const photon_map *const *maps, const photon_stats *stats,
                                int threads, thz_error *err)
{
    struct stat old, lst;
    bool exists = stat(path, &old) == 0, replaces = exists && S_ISREG(old.st_mode);
    bool link = lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode);
    char target[THZ_PATH_MAX], tmp[THZ_PATH_MAX + 64];
    char *real = replaces && link ? realpath(path, NULL) : NULL;
    bool in_place = (exists && !replaces) || (link && !real);
    int n = snprintf(target, sizeof target, "%s", real ? real : path);
    free(real);
    const char *slash = strrchr(target, '/');
    int fd = -1;
    for (int tries = 0; !in_place && n < (int)sizeof target && fd < 0 && tries < 100; tries++) {
        /* the thread's id: names of two threads' saves never meet */
        snprintf(tmp, sizeof tmp, "%.*s.thzmap-pm-%ld-%ld-%d.part",
                 slash ? (int)(slash - target + 1) : 0, target, (long)getpid(), (long)gettid(),
                 tries);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST)
            break;
    }
    if (fd < 0)
        return photon_map_file_write(path, scene, maps, stats, threads, err);
    /* the replaced file's mode before a byte is written: a private map stays private */
    if (replaces && fchmod(fd, old.st_mode & 07777) != 0) {
        /* not allowed: kept as created */
    }
    close(fd);
    thz_status st = photon_map_file_write(tmp, scene, maps, stats, threads, err);
    if (st == THZ_OK && rename(tmp, target) != 0)
        st = thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO),
                           "cannot write photon map %s: %s", path, strerror(errno));
    if (st != THZ_OK) {
        unlink(tmp);
        /* the message names the file as the caller did, not the temporary one */
        char *at = err ? strstr(err->message, tmp) : NULL;
        if (at) {
            char message[sizeof err->message];
            snprintf(message, sizeof message, "%.*s%s%s", (int)(at - err->message), err->message,
                     path, at + strlen(tmp));
            memcpy(err->message, message, sizeof message);
        }
    }
    return st;
}
