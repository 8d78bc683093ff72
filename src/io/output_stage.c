/* Atomic results (output.h): the staging directory, the lock that keeps a second run out
 * of the same OUTDIR, and the clean-up of what a killed run left behind.
 *
 * Names beside OUTDIR (PARENT is the directory holding it, H a hash of its name, so that
 * every name fits NAME_MAX however long OUTDIR's name is):
 *   PARENT/.thzmap-H-lock            held with flock(2) for the stage's lifetime (for a
 *                                    mount point, OUTDIR/.thzmap-lock)
 *   PARENT/.thzmap-H-stage-PID-N     the new run (STAGE_SWAP), or the old run after the swap
 *   PARENT/.thzmap-H-old-PID-N       the old run, only while a swap falls back to two renames
 * A run that holds the lock owns every such name: anything found there is left by a run
 * that died, and is cleaned up before the new stage is made (output_stage_create).
 */
#define _GNU_SOURCE /* O_CLOEXEC, flock */
#include "io/output.h"
#include "io/output_stage_internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/path.h"

/* How many staging names are tried before giving up. */
enum { STAGE_MAX_TRIES = 10000 };
/* How long a lock is waited for whose run is gone (stage_holder_gone), in 10 ms steps. */
enum { STAGE_GONE_HOLDER_WAITS = 500 };

/* Whether the run whose pid the lock file holds has ended, though the lock is still held:
 * then a child it forked holds it (flock follows the descriptor across fork), and that
 * child is being killed with its parent (PR_SET_PDEATHSIG, core/child.c). A run started
 * right after a kill (a batch killed and resumed, a user's second try) waits the few
 * milliseconds that takes instead of being told that a dead process is writing. */
static bool stage_holder_gone(const char *pid)
{
    char *end;
    long holder = strtol(pid, &end, 10);
    return end != pid && holder > 0 && kill((pid_t)holder, 0) != 0 && errno == ESRCH;
}

/* strndup through malloc (alloc.h has no counterpart). */
static char *stage_strndup(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static thz_status stage_nomem(const char *outdir, thz_error *err)
{
    return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while preparing the output",
                         outdir);
}

/* The status of a refusal by the file system of a place the user chose for the results:
 * no permission or a read-only file system is bad usage (exit 2), not a failure. */
static thz_status stage_errno_status(int e)
{
    return e == EACCES || e == EPERM || e == EROFS ? THZ_ERR_INPUT
                                                   : thz_errno_status(e, THZ_ERR_IO);
}

/* mkdir -p: creates path and its missing parents; *created (may be NULL) gets the
 * topmost directory created (malloc'd), or NULL when all existed. */
static thz_status stage_make_dirs(const char *path, char **created, thz_error *err)
{
    thz_status status = THZ_OK;
    char *copy = thz_strdup(path);
    if (!copy)
        return stage_nomem(path, err);
    for (char *p = copy + 1;; p++) {
        bool end = (*p == '\0');
        if (*p != '/' && !end)
            continue;
        *p = '\0';
        if (mkdir(copy, 0777) == 0) {
            if (created && !*created && !(*created = thz_strdup(copy))) {
                status = stage_nomem(path, err);
                goto cleanup;
            }
        } else if (errno != EEXIST) {
            status = thz_error_set(err, stage_errno_status(errno),
                                   "%s: cannot create directory: %s", copy, strerror(errno));
            goto cleanup;
        }
        if (end)
            break;
        *p = '/';
    }
    struct stat st;
    if (stat(copy, &st) != 0 || !S_ISDIR(st.st_mode)) /* a file where OUTDIR's parent is */
        status = thz_error_set(err, THZ_ERR_INPUT, "%s: not a directory", path);
cleanup:
    free(copy);
    return status;
}

/* 64-bit FNV-1a of a name: the H of the sibling names. */
static uint64_t stage_name_hash(const char *name)
{
    uint64_t h = 0xcbf29ce484222325u;
    for (const unsigned char *p = (const unsigned char *)name; *p; p++)
        h = (h ^ *p) * 0x100000001b3u;
    return h;
}

/* Splits the target path into parent and base name (both malloc'd). */
static thz_status stage_split(output_stage *stage, char **base, thz_error *err)
{
    char *slash = strrchr(stage->target, '/');
    if (!slash)
        stage->parent = thz_strdup(".");
    else if (slash == stage->target)
        stage->parent = thz_strdup("/");
    else
        stage->parent = stage_strndup(stage->target, (size_t)(slash - stage->target));
    *base = thz_strdup(slash ? slash + 1 : stage->target);
    if (!stage->parent || !*base)
        return stage_nomem(stage->outdir, err);
    if (!**base)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot write results into the root directory",
                             stage->outdir);
    return THZ_OK;
}

/* target = OUTDIR without trailing '/'; the real path where its last part is "." or
 * ".." (whose parent is not the directory holding it) or a symbolic link to a
 * directory. */
static thz_status stage_target(output_stage *stage, thz_error *err)
{
    size_t len = strlen(stage->outdir);
    while (len > 1 && stage->outdir[len - 1] == '/')
        len--;
    const char *last = stage->outdir + len;
    while (last > stage->outdir && last[-1] != '/')
        last--;
    size_t last_len = (size_t)(stage->outdir + len - last);
    bool dots = (last_len == 1 && last[0] == '.') || (last_len == 2 && !strncmp(last, "..", 2));
    stage->target = stage_strndup(stage->outdir, len);
    if (!stage->target)
        return stage_nomem(stage->outdir, err);
    /* OUTDIR a symbolic link to a directory: the results go into the directory it names
     * (the link stays), staged beside that directory. */
    struct stat lst, st;
    bool link_to_dir = lstat(stage->target, &lst) == 0 && S_ISLNK(lst.st_mode) &&
                       stat(stage->target, &st) == 0 && S_ISDIR(st.st_mode);
    if (!dots && !link_to_dir)
        return THZ_OK;
    free(stage->target);
    stage->target = realpath(stage->outdir, NULL);
    if (!stage->target)
        return thz_error_set(err, THZ_ERR_IO, "%s: %s", stage->outdir, strerror(errno));
    return THZ_OK;
}

/* Takes PARENT/.thzmap-H-lock, refusing when another run holds it. The lock file is
 * removed by whoever holds it last, so the flock'd file must still be the one at the
 * path (same inode) once the lock is had; otherwise it was removed meanwhile: retry. */
static thz_status stage_lock(output_stage *stage, const char *lock_path, thz_error *err)
{
    for (int attempt = 0, waits = 0; attempt < 100; attempt++) {
        int fd = open(lock_path, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
        /* A directory access() calls writable may still refuse (root on sysfs; procfs
         * says ENOENT, the directory being there): bad output directory, as access()'s
         * refusal is. */
        if (fd < 0)
            return thz_error_set(err, errno == ENOENT ? THZ_ERR_INPUT : stage_errno_status(errno),
                                 "%s: cannot create the lock file (%s): make its directory "
                                 "writable, or choose another output directory",
                                 lock_path, strerror(errno));
        if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
            int e = errno;
            char pid[32] = {0};
            ssize_t n = read(fd, pid, sizeof pid - 1);
            close(fd);
            if (e != EWOULDBLOCK)
                return thz_error_set(err, THZ_ERR_IO, "%s: cannot lock: %s", lock_path,
                                     strerror(e));
            pid[n > 0 ? n : 0] = '\0';
            pid[strcspn(pid, "\n")] = '\0';
            if (pid[0] && strtol(pid, NULL, 10) == (long)getpid()) /* a library caller's */
                return thz_error_set(err, THZ_ERR_IO,
                                     "%s: this process has an output open there already "
                                     "(another thread writing its results there, or an "
                                     "output not yet committed or destroyed)",
                                     stage->outdir);
            if (stage_holder_gone(pid) && waits++ < STAGE_GONE_HOLDER_WAITS) {
                nanosleep(&(struct timespec){.tv_nsec = 10000000}, NULL);
                attempt--;
                continue;
            }
            return thz_error_set(err, THZ_ERR_IO,
                                 "%s: another thzmap run (process %s) is writing its results "
                                 "there; wait for it to end or choose another output directory",
                                 stage->outdir, pid[0] ? pid : "unknown");
        }
        struct stat a, b;
        if (fstat(fd, &a) == 0 && stat(lock_path, &b) == 0 && a.st_ino == b.st_ino &&
            a.st_dev == b.st_dev) {
            char pid[32];
            int n = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
            if (ftruncate(fd, 0) != 0 || write(fd, pid, (size_t)n) != n) {
                /* the pid is only for the message of a refused run */
            }
            /* Out of memory: the lock is ours, so remove it (as output_stage_destroy
             * would, which needs lock_path) and let go. */
            if (!(stage->lock_path = thz_strdup(lock_path))) {
                unlink(lock_path);
                close(fd);
                return stage_nomem(stage->outdir, err);
            }
            stage->lock_fd = fd;
            return THZ_OK;
        }
        close(fd);
    }
    return thz_error_set(err, THZ_ERR_IO, "%s: cannot take the lock file", lock_path);
}

static bool stage_has_prefix(const char *name, const char *prefix)
{
    return strncmp(name, prefix, strlen(prefix)) == 0;
}

/* Restores and removes what runs killed before us left (we hold the lock, so no live
 * run owns any of it):
 *   - an old run parked by the two-rename fallback, OUTDIR missing: put back;
 *   - a stage, or an old run after its swap: the directories and links of the old
 *     OUTDIR that had not been moved back yet go back into OUTDIR; the rest (regular
 *     files: results, or links of files OUTDIR holds too) is removed;
 *   - a stage of the file-by-file mode inside OUTDIR (also thzmap 0.1's stages): the
 *     moved-aside old results go back where OUTDIR lacks them, the rest is removed. */
static void stage_clean_leftovers(const output_stage *stage, const char *base_prefix)
{
    char old_prefix[300], stage_prefix[300];
    snprintf(old_prefix, sizeof old_prefix, "%s-old-", base_prefix);
    snprintf(stage_prefix, sizeof stage_prefix, "%s-stage-", base_prefix);
    struct stat st;
    bool have_outdir = lstat(stage->target, &st) == 0;
    for (int pass = 0; pass < 2; pass++) {
        const char *scan = pass == 0 ? stage->parent : stage->target;
        DIR *d = opendir(scan);
        if (!d)
            continue;
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            char path[THZ_PATH_MAX], aside[THZ_PATH_MAX];
            if (thz_path_join(path, sizeof path, scan, e->d_name, NULL) != THZ_OK)
                continue;
            if (pass == 0 && stage_has_prefix(e->d_name, old_prefix) && !have_outdir) {
                have_outdir = rename(path, stage->target) == 0;
                continue;
            }
            bool ours = pass == 0 ? stage_has_prefix(e->d_name, old_prefix) ||
                                        stage_has_prefix(e->d_name, stage_prefix)
                                  : stage_has_prefix(e->d_name, ".thzmap-staging-");
            if (!ours)
                continue;
            if (pass == 1 &&
                thz_path_join(aside, sizeof aside, path, ".thzmap-replaced", NULL) == THZ_OK) {
                stage_move_others(aside, stage->target); /* links and directories */
                DIR *a = opendir(aside);
                struct dirent *f;
                while (a && (f = readdir(a)) != NULL) {
                    char from[THZ_PATH_MAX], to[THZ_PATH_MAX];
                    if (f->d_name[0] == '.' ||
                        thz_path_join(from, sizeof from, aside, f->d_name, NULL) != THZ_OK ||
                        thz_path_join(to, sizeof to, stage->target, f->d_name, NULL) != THZ_OK)
                        continue;
                    if (lstat(to, &st) != 0)
                        rename(from, to);
                }
                if (a)
                    closedir(a);
                stage_remove_files(aside);
            }
            if (have_outdir)
                stage_move_others(path, stage->target);
            stage_remove_files(path);
        }
        closedir(d);
        if (!have_outdir)
            break;
    }
}

/* Whether OUTDIR exists and is a mount point (its parent is another file system). */
static bool stage_mount_point(const output_stage *stage)
{
    struct stat out, parent;
    return stat(stage->target, &out) == 0 && S_ISDIR(out.st_mode) &&
           stat(stage->parent, &parent) == 0 && parent.st_dev != out.st_dev;
}

/* STAGE_FILES when OUTDIR exists and is a mount point or the working directory. */
static stage_mode stage_choose_mode(const output_stage *stage)
{
    struct stat out, cwd;
    if (stat(stage->target, &out) != 0 || !S_ISDIR(out.st_mode))
        return STAGE_SWAP;
    if (stage_mount_point(stage))
        return STAGE_FILES;
    if (stat(".", &cwd) == 0 && cwd.st_dev == out.st_dev && cwd.st_ino == out.st_ino)
        return STAGE_FILES;
    return STAGE_SWAP;
}

thz_status output_stage_create(const char *outdir, output_stage **out, thz_error *err)
{
    *out = NULL;
    if (!outdir || !outdir[0])
        return thz_error_set(err, THZ_ERR_IO, "the output directory name is empty");
    output_stage *stage = calloc(1, sizeof *stage);
    if (!stage)
        return stage_nomem(outdir, err);
    stage->lock_fd = -1;
    char *base = NULL;
    thz_status status = THZ_OK;
    if (!(stage->outdir = thz_strdup(outdir))) {
        status = stage_nomem(outdir, err);
        goto cleanup;
    }
    status = stage_target(stage, err);
    if (status == THZ_OK)
        status = stage_split(stage, &base, err);
    if (status == THZ_OK)
        status = stage_make_dirs(stage->parent, &stage->created_root, err);
    if (status != THZ_OK)
        goto cleanup;
    struct stat st;
    struct stat to;
    if (lstat(stage->target, &st) == 0 && S_ISLNK(st.st_mode) && stat(stage->target, &to) != 0) {
        status = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: is a symbolic link to a missing path (expected a directory "
                               "for the results, or a name to create one)",
                               outdir);
        goto cleanup;
    }
    if (lstat(stage->target, &st) == 0 && !S_ISDIR(st.st_mode)) {
        /* the user's choice of OUTDIR: bad usage (exit 2), not a failure of the machine */
        status = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: exists and is not a directory (expected a directory for "
                               "the results, or a name to create one)",
                               outdir);
        goto cleanup;
    }
    /* Known before the run, not after it: a name the file system cannot hold (the stage's
     * own name is short, so only the last move failed), and an OUTDIR this user cannot
     * write, whose files a run would swap out of sight but could not delete. */
    long name_max = pathconf(stage->parent, _PC_NAME_MAX);
    if (name_max > 0 && strlen(base) > (size_t)name_max) {
        status = thz_error_set(err, THZ_ERR_INPUT,
                               "%s: its name is %zu bytes long, more than the %ld the file system "
                               "allows",
                               outdir, strlen(base), name_max);
        goto cleanup;
    }
    if (lstat(stage->target, &st) == 0 && access(stage->target, W_OK) != 0) {
        status = thz_error_set(err, stage_errno_status(errno),
                               "%s: exists and is not writable (%s): make it writable, or choose "
                               "another output directory",
                               outdir, strerror(errno));
        goto cleanup;
    }
    char name[64], path[THZ_PATH_MAX];
    snprintf(name, sizeof name, ".thzmap-%016" PRIx64, stage_name_hash(base));
    status = thz_path_join(path, sizeof path, stage->parent, name, err);
    if (status != THZ_OK)
        goto cleanup;
    if (!(stage->prefix = thz_strdup(path))) {
        status = stage_nomem(outdir, err);
        goto cleanup;
    }
    stage->mode = stage_choose_mode(stage);
    /* the lock and the staging directory go beside OUTDIR (or into it, STAGE_FILES) */
    const char *holder = stage->mode == STAGE_FILES ? stage->target : stage->parent;
    if (access(holder, W_OK | X_OK) != 0) {
        status = thz_error_set(err, stage_errno_status(errno),
                               "%s: cannot write in %s, where a run stages its results before "
                               "they replace OUTDIR (%s): make it writable, or choose another "
                               "output directory",
                               outdir, holder, strerror(errno));
        goto cleanup;
    }
    /* The lock goes beside OUTDIR wherever the caller stands: a run from inside OUTDIR
     * (-o .) stages and commits file by file, but must meet a run from elsewhere (-o out,
     * swapped) at the same lock, or both ran and each removed the other's stage as a
     * dead run's. Inside OUTDIR only where no swapping run can be: a mount point, or a
     * parent this user cannot write. */
    bool lock_inside = stage->mode == STAGE_FILES &&
                       (stage_mount_point(stage) || access(stage->parent, W_OK | X_OK) != 0);
    char lock_path[THZ_PATH_MAX + 8];
    if (lock_inside)
        status = thz_path_join(lock_path, THZ_PATH_MAX, stage->target, ".thzmap-lock", err);
    else
        snprintf(lock_path, sizeof lock_path, "%s-lock", stage->prefix);
    if (status == THZ_OK)
        status = stage_lock(stage, lock_path, err);
    if (status != THZ_OK)
        goto cleanup;
    stage_clean_leftovers(stage, name);

    for (int n = 0; n < STAGE_MAX_TRIES && !stage->dir; n++) {
        char dir[THZ_PATH_MAX + 64];
        if (stage->mode == STAGE_FILES) {
            snprintf(name, sizeof name, ".thzmap-staging-%ld-%d", (long)getpid(), n);
            status = thz_path_join(dir, THZ_PATH_MAX, stage->target, name, err);
        } else {
            snprintf(dir, sizeof dir, "%s-stage-%ld-%d", stage->prefix, (long)getpid(), n);
        }
        /* Fails early, before the run, if the path leaves no room for file names. */
        char probe[THZ_PATH_MAX];
        if (status == THZ_OK)
            status = thz_path_join(probe, sizeof probe, dir, "summary.json", err);
        if (status == THZ_OK)
            status = thz_path_join(probe, sizeof probe, stage->target, "summary.json", err);
        if (status != THZ_OK)
            goto cleanup;
        if (mkdir(dir, 0777) == 0) {
            if (!(stage->dir = thz_strdup(dir))) {
                rmdir(dir);
                status = stage_nomem(outdir, err);
                goto cleanup;
            }
        } else if (errno != EEXIST) {
            status = thz_error_set(err, THZ_ERR_IO, "%s: cannot create the staging directory: %s",
                                   outdir, strerror(errno));
            goto cleanup;
        }
    }
    if (!stage->dir) {
        status = thz_error_set(err, THZ_ERR_IO, "%s: no free staging directory name", outdir);
        goto cleanup;
    }
    free(base);
    *out = stage;
    return THZ_OK;
cleanup:
    free(base);
    output_stage_destroy(stage);
    return status;
}

const char *output_stage_dir(const output_stage *stage)
{
    return stage->dir;
}

void output_stage_error_names_outdir(const output_stage *stage, thz_error *err)
{
    if (!stage || !err)
        return;
    size_t n = strlen(stage->dir);
    char *at = strstr(err->message, stage->dir);
    if (!at || at[n] != '/')
        return;
    char message[sizeof err->message];
    snprintf(message, sizeof message, "%.*s%s%s%s", (int)(at - err->message), err->message,
             stage->outdir, stage->outdir[strlen(stage->outdir) - 1] == '/' ? "" : "/", at + n + 1);
    memcpy(err->message, message, sizeof message);
}

static thz_status stage_add_claim(output_stage *stage, const char *name, bool sensor,
                                  thz_error *err)
{
    stage_claim *grown = thz_realloc_array(stage->claims, stage->n_claims + 1, sizeof *grown);
    if (!grown)
        return stage_nomem(stage->outdir, err);
    stage->claims = grown;
    if (!(grown[stage->n_claims].name = thz_strdup(name)))
        return stage_nomem(stage->outdir, err);
    grown[stage->n_claims++].sensor = sensor;
    return THZ_OK;
}

thz_status output_stage_claim(output_stage *stage, const char *name, thz_error *err)
{
    return stage_add_claim(stage, name, false, err);
}

thz_status output_stage_claim_sensor(output_stage *stage, const char *sensor, thz_error *err)
{
    char stem[THZ_PATH_MAX];
    if (!output_file_name(stem, sizeof stem, sensor, "", ""))
        return thz_error_set(err, THZ_ERR_INPUT, "sensor %.64s...: file name too long", sensor);
    return stage_add_claim(stage, stem, true, err);
}

bool stage_claimed(const struct output_stage *stage, const char *name)
{
    for (size_t i = 0; i < stage->n_claims; i++) {
        const stage_claim *c = &stage->claims[i];
        if (c->sensor ? output_sensor_file(c->name, name) : !strcmp(c->name, name))
            return true;
    }
    return false;
}

thz_status output_stage_commit(output_stage *stage, thz_error *err)
{
    thz_status status =
        stage->mode == STAGE_SWAP ? stage_commit_swap(stage, err) : stage_commit_files(stage, err);
    if (status == THZ_OK)
        stage->committed = true;
    return status;
}

/* Removes the directories from created_root down to the parent if they are empty.
 * Allocates nothing: it also runs when the run failed for lack of memory. */
static void stage_remove_created(const output_stage *stage)
{
    if (!stage->created_root || !stage->parent)
        return;
    char p[THZ_PATH_MAX];
    if (snprintf(p, sizeof p, "%s", stage->parent) >= (int)sizeof p)
        return;
    size_t root_len = strlen(stage->created_root);
    while (strlen(p) >= root_len && rmdir(p) == 0) {
        char *slash = strrchr(p, '/');
        if (!slash || slash == p)
            break;
        *slash = '\0';
    }
}

void output_stage_destroy(output_stage *stage)
{
    if (!stage)
        return;
    if (!stage->committed && stage->dir)
        stage_remove_files(stage->dir);
    if (stage->lock_fd >= 0) {
        unlink(stage->lock_path); /* while still holding it: see stage_lock */
        close(stage->lock_fd);
    }
    if (!stage->committed)
        stage_remove_created(stage);
    free(stage->outdir);
    free(stage->target);
    free(stage->parent);
    free(stage->prefix);
    free(stage->dir);
    free(stage->lock_path);
    free(stage->created_root);
    for (size_t i = 0; i < stage->n_claims; i++)
        free(stage->claims[i].name);
    free(stage->claims);
    free(stage);
}
