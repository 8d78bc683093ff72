/* A batch's output directory: created (mkdir -p), locked against a second batch into it
 * (an open file description's lock, which a second batch of the same process meets too),
 * and cleaned of what a batch killed inside a frame's commit left beside finished frames.
 * batch_run.c runs the frames, batch_json.c writes batch.json and the frames' frame.json
 * (batch_run_state.h).
 */
#define _GNU_SOURCE /* F_OFD_SETLK */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "batch/batch_internal.h"
#include "batch/batch_run_state.h"
#include "core/error.h"
#include "core/path.h"

thz_status batch_mkdirs(const char *dir, thz_error *err)
{
    char path[THZ_PATH_MAX];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path)
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", dir);
    for (char *p = path + 1;; p++) {
        char c = *p;
        if (c != '/' && c != '\0')
            continue;
        *p = '\0';
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            /* a place the user may not write, or a file on the way, is bad usage (exit
             * 2), as for simulate's OUTDIR */
            int e = errno;
            return thz_error_set(err,
                                 e == EACCES || e == EPERM || e == EROFS || e == ENOTDIR
                                     ? THZ_ERR_INPUT
                                     : THZ_ERR_IO,
                                 "%s: cannot create the directory: %s", path, strerror(e));
        }
        *p = c;
        if (!c)
            break;
    }
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) /* a file where OUTDIR is: bad usage */
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: exists and is not a directory (expected a directory for "
                             "the results, or a name to create one)",
                             dir);
    return THZ_OK;
}

/* Whether dir holds what a killed output commit leaves beside the directory it commits
 * (.thzmap-H-lock, .thzmap-H-stage-..., .thzmap-H-old-...; io/output_stage.c). */
static int batch_has_leftovers(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int found = 0;
    while (d && !found && (e = readdir(d)) != NULL)
        found = !strncmp(e->d_name, ".thzmap-", 8) && strcmp(e->d_name, ".thzmap-batch-lock");
    if (d)
        closedir(d);
    return found;
}

void batch_clean_finished(const batch_state *b)
{
    const thz_sequence *seq = b->seq;
    for (size_t s = 0; s < seq->n_sweeps; s++) {
        char parent[THZ_PATH_MAX], dir[THZ_PATH_MAX], sweep[32];
        batch_sweep_dir(seq, s, sweep, sizeof sweep);
        if (seq->has_sweep)
            snprintf(parent, sizeof parent, "%s/%s", b->outdir, sweep);
        else
            snprintf(parent, sizeof parent, "%s", b->outdir);
        if (!batch_has_leftovers(parent))
            continue;
        for (size_t f = s * seq->frames; f < (s + 1) * seq->frames; f++) {
            if (b->state[f] != FRAME_REUSED ||
                snprintf(dir, sizeof dir, "%s/%s", b->outdir, seq->frame_dir[f]) >= (int)sizeof dir)
                continue;
            thz_output *output = NULL;
            thz_error ignored;
            if (thz_output_open(dir, &output, &ignored) == THZ_OK)
                thz_output_destroy(output);
        }
    }
}

thz_status batch_lock(const char *outdir, int *fd, thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status st = thz_path_join(path, sizeof path, outdir, ".thzmap-batch-lock", err);
    if (st != THZ_OK)
        return st;
    *fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (*fd < 0)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* An open file description's lock, as the outputs' flock (io/output_stage.c): a
     * process-associated (POSIX) lock never conflicts with one of the same process, so
     * two batches into OUTDIR from two threads (Python, a C program) both ran and mixed
     * their frames, and closing any descriptor of the file let the lock go. The children
     * forked for plotting share the description, and die with the batch (core/child.c:
     * PR_SET_PDEATHSIG), so a SIGKILLed batch leaves no holder behind. */
    struct flock lk = {.l_type = F_WRLCK, .l_whence = SEEK_SET};
    if (fcntl(*fd, F_OFD_SETLK, &lk) != 0) {
        int e = errno;
        close(*fd);
        *fd = -1;
        /* held: EAGAIN or EACCES; else no lock could be had (ENOLCK on a network file
         * system without a lock service, EINVAL where open file description locks are
         * unknown), which no other batch is to blame for */
        if (e != EAGAIN && e != EACCES)
            return thz_error_set(err, THZ_ERR_IO, "%s: cannot lock: %s", path, strerror(e));
        return thz_error_set(err, THZ_ERR_IO,
                             "%s: another thzmap batch is running into this directory", outdir);
    }
    return THZ_OK;
}
