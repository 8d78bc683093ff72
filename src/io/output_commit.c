/* Moving a finished run into OUTDIR (output_stage_commit), in the two modes of
 * output_stage_internal.h.
 *
 * STAGE_SWAP, the usual case: OUTDIR may hold files this run does not write (other
 * sensors of an earlier run, a user's notes) and directories (another run's OUTDIR).
 *   1. Each regular file of OUTDIR that the stage lacks is hard-linked into the stage,
 *      so the new OUTDIR carries it from the first instant; but not a file of a name the
 *      run claims (output_stage_claim): an earlier run's, which this one replaces.
 *   2. renameat2(RENAME_EXCHANGE) swaps the stage and OUTDIR in one step: OUTDIR is now
 *      the new run, whole, and the stage's name holds the old one. (Where the file system
 *      cannot exchange, OUTDIR is renamed aside and the stage renamed in: for an instant
 *      OUTDIR is missing, and a run killed then is put back by the next run.)
 *   3. What OUTDIR held that is not a regular file (directories, links), or that could
 *      not be linked (and is not claimed), is renamed back into the new OUTDIR; the old
 *      run is removed.
 * A kill at any instant leaves OUTDIR the old run or the new one, each whole; what
 * step 3 had not moved back yet is moved back by the next run into that OUTDIR.
 *
 * STAGE_FILES: moves the files it will replace aside (STAGE/.thzmap-replaced/), renames
 * the new ones in, and on any failure renames the old ones back: all or nothing on
 * failure, a mix after a crash in the middle (the next run puts the old ones back where
 * the new ones are missing). Once all are in, the claimed files it did not write are
 * removed.
 */
#define _GNU_SOURCE /* renameat2, RENAME_EXCHANGE */
#include "io/output_stage_internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/path.h"
#include "io/output.h"

static void stage_free_names(char **names, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

static int stage_name_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The names in dir other than "." and ".." (regular files only when regular_only),
 * sorted so that the order of the moves does not depend on readdir. */
static thz_status stage_list(const char *dir, bool regular_only, char ***names_out, size_t *n_out,
                             thz_error *err)
{
    *names_out = NULL;
    *n_out = 0;
    DIR *d = opendir(dir);
    if (!d)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot read the directory: %s", dir,
                             strerror(errno));
    thz_status status = THZ_OK;
    char **names = NULL;
    size_t n = 0, cap = 0;
    struct dirent *e;
    while (status == THZ_OK && (e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        if (regular_only) {
            char path[THZ_PATH_MAX];
            struct stat st;
            if (thz_path_join(path, sizeof path, dir, e->d_name, NULL) != THZ_OK ||
                lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
                continue;
        }
        if (n == cap) {
            size_t new_cap = cap ? 2 * cap : 16;
            char **grown = thz_realloc_array(names, new_cap, sizeof *names);
            if (!grown) {
                status =
                    thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while committing", dir);
                break;
            }
            names = grown;
            cap = new_cap;
        }
        if (!(names[n] = thz_strdup(e->d_name))) {
            status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while committing", dir);
            break;
        }
        n++;
    }
    closedir(d);
    if (status != THZ_OK) {
        stage_free_names(names, n);
        return status;
    }
    if (n)
        qsort(names, n, sizeof *names, stage_name_cmp);
    *names_out = names;
    *n_out = n;
    return THZ_OK;
}

/* Allocates nothing (no opendir, whose buffer is malloc'd): a run that fails for lack of
 * memory must still remove its stage. Rescans while a pass removed something, as
 * removing entries while reading the directory may make it skip some. */
void stage_remove_files(const char *dir)
{
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        _Alignas(struct dirent64) char buf[4096];
        bool removed = true;
        for (int pass = 0; removed && pass < 8 && lseek(fd, 0, SEEK_SET) == 0; pass++) {
            removed = false;
            ssize_t n;
            while ((n = getdents64(fd, buf, sizeof buf)) > 0) {
                for (ssize_t at = 0; at < n;) {
                    const struct dirent64 *e = (const struct dirent64 *)(buf + at);
                    at += e->d_reclen;
                    /* unlinkat without AT_REMOVEDIR leaves directories (and . and ..) */
                    if (unlinkat(fd, e->d_name, 0) == 0)
                        removed = true;
                }
            }
        }
        close(fd);
    }
    rmdir(dir);
}

void stage_move_others(const char *dir, const char *into)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        char from[THZ_PATH_MAX], to[THZ_PATH_MAX];
        struct stat st;
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") ||
            !strcmp(e->d_name, ".thzmap-replaced") ||
            thz_path_join(from, sizeof from, dir, e->d_name, NULL) != THZ_OK ||
            thz_path_join(to, sizeof to, into, e->d_name, NULL) != THZ_OK ||
            lstat(from, &st) != 0 || S_ISREG(st.st_mode))
            continue;
        if (lstat(to, &st) != 0 && errno == ENOENT)
            rename(from, to);
    }
    closedir(d);
}

/* Step 1 of STAGE_SWAP, and the check that no staged file would replace a directory.
 * Files that cannot be linked (another file system's rules) are moved in step 3. */
static thz_status stage_carry_files(const struct output_stage *stage, thz_error *err)
{
    char **names = NULL;
    size_t n = 0;
    thz_status status = stage_list(stage->target, false, &names, &n, err);
    for (size_t i = 0; i < n && status == THZ_OK; i++) {
        char old[THZ_PATH_MAX], staged[THZ_PATH_MAX];
        struct stat so, ss;
        status = thz_path_join(old, sizeof old, stage->target, names[i], err);
        if (status == THZ_OK)
            status = thz_path_join(staged, sizeof staged, stage->dir, names[i], err);
        if (status != THZ_OK || lstat(old, &so) != 0)
            continue;
        if (lstat(staged, &ss) == 0) {
            if (S_ISDIR(so.st_mode))
                status = thz_error_set(err, THZ_ERR_IO,
                                       "%s: is a directory, where this run writes a file of its "
                                       "name; nothing committed, the previous results stay",
                                       old);
        } else if (S_ISREG(so.st_mode) && !stage_claimed(stage, names[i])) {
            link(old, staged); /* on failure: moved after the swap */
        }
    }
    stage_free_names(names, n);
    return status;
}

/* Step 3 of STAGE_SWAP: `old` holds the previous OUTDIR. Its entries without a namesake
 * in `into` are the user's that step 1 could not link across (a file system without
 * hard links, a file another user owns under fs.protected_hardlinks), a link or a
 * directory: moved into `into`; or regular files the run claims, which it did not
 * write: removed. Those with one (replaced by this run's file, or linked across) are
 * removed, then `old` if empty. Nothing else is removed that has not been found a
 * namesake: where the listing or a move fails, the entry stays in `old`. */
static void stage_return_old(const struct output_stage *stage, const char *old, const char *into)
{
    char **names = NULL;
    size_t n = 0;
    if (stage_list(old, false, &names, &n, NULL) != THZ_OK)
        return;
    for (size_t i = 0; i < n; i++) {
        char from[THZ_PATH_MAX], to[THZ_PATH_MAX];
        struct stat sf, st;
        if (thz_path_join(from, sizeof from, old, names[i], NULL) != THZ_OK ||
            thz_path_join(to, sizeof to, into, names[i], NULL) != THZ_OK || lstat(from, &sf) != 0)
            continue;
        if (lstat(to, &st) != 0) {
            if (errno != ENOENT)
                continue;
            if (S_ISREG(sf.st_mode) && stage_claimed(stage, names[i]))
                unlink(from);
            else
                rename(from, to);
        } else if (!S_ISDIR(sf.st_mode)) {
            unlink(from);
        }
    }
    stage_free_names(names, n);
    rmdir(old);
}

thz_status stage_commit_swap(struct output_stage *stage, thz_error *err)
{
    struct stat st;
    if (lstat(stage->target, &st) != 0) {
        if (errno == ENOENT && rename(stage->dir, stage->target) == 0)
            return THZ_OK;
        if ((errno != EEXIST && errno != ENOTEMPTY) || lstat(stage->target, &st) != 0)
            return thz_error_set(err, THZ_ERR_IO, "%s: cannot move the results into place: %s",
                                 stage->outdir, strerror(errno));
        /* made by another process since: swapped with as any OUTDIR, with its mode */
    }
    thz_status status = stage_carry_files(stage, err);
    if (status != THZ_OK)
        return status;
    /* The new OUTDIR is the stage: it takes the old one's permissions and, where this
     * process may give them, its owner and group, or a private results directory would
     * come back as the umask makes new ones. */
    if (chmod(stage->dir, st.st_mode & 07777) != 0)
        return thz_error_set(err, THZ_ERR_IO,
                             "%s: cannot give the results the directory's permissions: %s; "
                             "nothing committed, the previous results stay",
                             stage->outdir, strerror(errno));
    if ((st.st_uid != geteuid() || st.st_gid != getegid()) &&
        chown(stage->dir, st.st_uid, st.st_gid) != 0) {
        /* not allowed (another user's directory that this one may write in): kept as
         * created, owned by whoever ran thzmap */
    }
    if (renameat2(AT_FDCWD, stage->dir, AT_FDCWD, stage->target, RENAME_EXCHANGE) != 0) {
        int e = errno;
        if (e != EINVAL && e != ENOSYS && e != EOPNOTSUPP)
            return thz_error_set(err, THZ_ERR_IO,
                                 "%s: cannot swap in the results: %s; nothing committed, the "
                                 "previous results stay",
                                 stage->outdir, strerror(e));
        /* No exchange on this file system: two renames, the old run parked under a name
         * the next run recognises (output_stage.c) should we die in between. */
        char parked[THZ_PATH_MAX + 64];
        snprintf(parked, sizeof parked, "%s-old-%ld-0", stage->prefix, (long)getpid());
        if (rename(stage->target, parked) != 0)
            return thz_error_set(err, THZ_ERR_IO, "%s: cannot move the previous results aside: %s",
                                 stage->outdir, strerror(errno));
        if (rename(stage->dir, stage->target) != 0) {
            e = errno;
            rename(parked, stage->target);
            return thz_error_set(err, THZ_ERR_IO,
                                 "%s: cannot move the results into place: %s; nothing "
                                 "committed, the previous results stay",
                                 stage->outdir, strerror(e));
        }
        stage_return_old(stage, parked, stage->target);
        return THZ_OK;
    }
    stage_return_old(stage, stage->dir, stage->target); /* the stage's name now holds the old run */
    return THZ_OK;
}

/* ---- STAGE_FILES ---------------------------------------------------------------- */

/* Where the commit keeps the files it replaces until it has succeeded. */
static const char stage_aside_name[] = ".thzmap-replaced";

/* The three places of a staged file: in the stage, in OUTDIR, moved aside. */
static thz_status stage_paths(const struct output_stage *stage, const char *aside, const char *name,
                              char *staged, char *target, char *moved, thz_error *err)
{
    thz_status status = thz_path_join(staged, THZ_PATH_MAX, stage->dir, name, err);
    if (status == THZ_OK)
        status = thz_path_join(target, THZ_PATH_MAX, stage->target, name, err);
    if (status == THZ_OK)
        status = thz_path_join(moved, THZ_PATH_MAX, aside, name, err);
    return status;
}

/* Undoes a failed commit: removes the first n_placed new files from OUTDIR and renames
 * the moved-aside files (had_old) back. False if some old file could not be put back. */
static bool stage_roll_back(const struct output_stage *stage, const char *aside, char **names,
                            const bool *had_old, size_t n, size_t n_placed)
{
    bool ok = true;
    for (size_t i = 0; i < n; i++) {
        char staged[THZ_PATH_MAX], target[THZ_PATH_MAX], moved[THZ_PATH_MAX];
        if (stage_paths(stage, aside, names[i], staged, target, moved, NULL) != THZ_OK)
            continue;
        if (had_old[i]) /* atomically replaces the new file, if placed */
            ok &= rename(moved, target) == 0;
        else if (i < n_placed)
            unlink(target);
    }
    return ok;
}

/* The last step of STAGE_FILES: removes OUTDIR's regular files that the run claims and
 * did not write (not among the n sorted names it placed). A listing that fails leaves
 * them: the results are in place already. */
static void stage_drop_claimed(const struct output_stage *stage, char **placed, size_t n)
{
    char **names = NULL;
    size_t n_names = 0;
    if (!stage->n_claims || stage_list(stage->target, true, &names, &n_names, NULL) != THZ_OK)
        return;
    for (size_t i = 0; i < n_names; i++) {
        char path[THZ_PATH_MAX];
        if (stage_claimed(stage, names[i]) &&
            !(n && bsearch(&names[i], placed, n, sizeof *placed, stage_name_cmp)) &&
            thz_path_join(path, sizeof path, stage->target, names[i], NULL) == THZ_OK)
            unlink(path);
    }
    stage_free_names(names, n_names);
}

thz_status stage_commit_files(struct output_stage *stage, thz_error *err)
{
    char **names = NULL;
    size_t n = 0, n_placed = 0;
    bool *had_old = NULL, made_aside = false;
    char aside[THZ_PATH_MAX], staged[THZ_PATH_MAX], target[THZ_PATH_MAX], moved[THZ_PATH_MAX];
    thz_status status = stage_list(stage->dir, true, &names, &n, err);
    if (status != THZ_OK)
        return status;
    had_old = thz_calloc(n, sizeof *had_old);
    if (!had_old) {
        status =
            thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while committing", stage->outdir);
        goto cleanup;
    }
    status = thz_path_join(aside, sizeof aside, stage->dir, stage_aside_name, err);
    if (status != THZ_OK)
        goto cleanup;
    if (mkdir(aside, 0777) != 0) {
        status = thz_error_set(err, THZ_ERR_IO, "%s: cannot create: %s", aside, strerror(errno));
        goto cleanup;
    }
    made_aside = true;
    /* 1. The previous files that the new ones replace, aside (not a directory: renaming
     * the file onto it fails below, and the rollback follows). */
    for (size_t i = 0; i < n && status == THZ_OK; i++) {
        struct stat st;
        status = stage_paths(stage, aside, names[i], staged, target, moved, err);
        if (status != THZ_OK)
            break;
        if (lstat(target, &st) != 0) {
            if (errno != ENOENT)
                status = thz_error_set(err, THZ_ERR_IO, "%s: %s", target, strerror(errno));
        } else if (!S_ISDIR(st.st_mode)) {
            if (rename(target, moved) != 0)
                status = thz_error_set(err, THZ_ERR_IO, "%s: cannot move aside: %s", target,
                                       strerror(errno));
            else
                had_old[i] = true;
        }
    }
    /* 2. The new files in. */
    for (; n_placed < n && status == THZ_OK; n_placed++) {
        status = stage_paths(stage, aside, names[n_placed], staged, target, moved, err);
        if (status == THZ_OK && rename(staged, target) != 0)
            status = thz_error_set(err, THZ_ERR_IO, "%s: cannot move into place: %s", target,
                                   strerror(errno));
        if (status != THZ_OK)
            break;
    }
    if (status != THZ_OK) {
        if (stage_roll_back(stage, aside, names, had_old, n, n_placed))
            thz_error_prefix(err, "nothing committed, the previous results stay: ");
        else
            thz_error_prefix(
                err, "commit failed and so did its rollback (previous files are in %s): ", aside);
        goto cleanup;
    }
    for (size_t i = 0; i < n; i++)
        if (had_old[i] &&
            stage_paths(stage, aside, names[i], staged, target, moved, NULL) == THZ_OK)
            unlink(moved);
    stage_drop_claimed(stage, names, n);
    rmdir(aside);
    made_aside = false;
    if (rmdir(stage->dir) != 0)
        status = thz_error_set(err, THZ_ERR_IO,
                               "%s: results committed, but the staging directory %s cannot be "
                               "removed: %s",
                               stage->outdir, stage->dir, strerror(errno));
cleanup:
    if (made_aside && status != THZ_OK)
        rmdir(aside); /* only when empty: a failed rollback leaves the old files there */
    stage_free_names(names, n);
    free(had_old);
    return status;
}
