/* Atomic results: a staging directory inside OUTDIR that writers fill and that is
 * moved into OUTDIR file by file (rename(2) is atomic per file) only when the whole run
 * has succeeded. A run that fails or is interrupted destroys the stage, so OUTDIR never
 * holds a half-written result file.
 *
 * The staging directory is OUTDIR/.thzmap-staging-<pid>-<n>/, n the first number for
 * which mkdir succeeds, so that concurrent runs into one OUTDIR do not collide.
 *
 * The commit is all or nothing as far as POSIX allows (a crash in the middle of it can
 * still leave a mix; a failure cannot): it first moves the files it will replace aside
 * into STAGE/.thzmap-replaced/, then renames the new files in. If any rename fails it
 * renames the moved-aside files back and removes the new ones it placed, so OUTDIR holds
 * exactly the previous results again; on success it removes the moved-aside files.
 */
#include "io/output.h"

#include <dirent.h>
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/path.h"

struct output_stage {
    char *outdir;
    char *dir; /* the staging directory */
    bool committed;
    bool created_outdir; /* OUTDIR did not exist before: a failed run removes it again */
};

/* How many staging names are tried before giving up (each failed try is a directory
 * of the same name left by another run of the same pid, e.g. in a container). */
enum { STAGE_MAX_TRIES = 10000 };

/* mkdir -p: creates path and its missing parents (mode 0777 before umask). */
static thz_status stage_make_dirs(const char *path, thz_error *err)
{
    thz_status status = THZ_OK;
    if (path[0] == '\0')
        return thz_error_set(err, THZ_ERR_IO, "the output directory name is empty");
    char *copy = thz_strdup(path);
    if (!copy)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    size_t len = strlen(copy);
    while (len > 1 && copy[len - 1] == '/')
        copy[--len] = '\0';
    for (char *p = copy + 1;; p++) {
        bool end = (*p == '\0');
        if (*p != '/' && !end)
            continue;
        char saved = *p;
        *p = '\0';
        if (mkdir(copy, 0777) != 0 && errno != EEXIST) {
            status = thz_error_set(err, THZ_ERR_IO, "%s: cannot create directory: %s", copy,
                                   strerror(errno));
            goto cleanup;
        }
        *p = saved;
        if (end)
            break;
    }
    struct stat st;
    if (stat(copy, &st) != 0 || !S_ISDIR(st.st_mode)) {
        status = thz_error_set(err, THZ_ERR_IO, "%s: not a directory", path);
        goto cleanup;
    }
cleanup:
    free(copy);
    return status;
}

/* Where the commit keeps the files it replaces until it has succeeded: inside the stage,
 * so hidden and private to this run. No staged file has this name (every writer's file
 * name has an extension after the sensor name or is summary.json or photon-map.*). */
static const char stage_aside_name[] = ".thzmap-replaced";

thz_status output_stage_create(const char *outdir, output_stage **out, thz_error *err)
{
    *out = NULL;
    struct stat before;
    bool existed = stat(outdir, &before) == 0;
    thz_status status = stage_make_dirs(outdir, err);
    if (status != THZ_OK)
        return status;
    output_stage *stage = calloc(1, sizeof *stage);
    if (!stage)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", outdir);
    stage->created_outdir = !existed;
    stage->outdir = thz_strdup(outdir);
    if (!stage->outdir) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", outdir);
        goto cleanup;
    }
    for (int n = 0; n < STAGE_MAX_TRIES; n++) {
        char name[64], dir[THZ_PATH_MAX];
        snprintf(name, sizeof name, ".thzmap-staging-%ld-%d", (long)getpid(), n);
        /* Fails early, before the run, if OUTDIR leaves no room for file names. */
        status = thz_path_join(dir, sizeof dir, outdir, name, err);
        if (status != THZ_OK)
            goto cleanup;
        if (mkdir(dir, 0777) == 0) {
            stage->dir = thz_strdup(dir);
            if (!stage->dir) {
                rmdir(dir);
                status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", outdir);
                goto cleanup;
            }
            break;
        }
        int e = errno;
        if (e != EEXIST) {
            status = thz_error_set(err, THZ_ERR_IO, "%s: cannot create the staging directory: %s",
                                   outdir, strerror(e));
            goto cleanup;
        }
    }
    if (!stage->dir) {
        status = thz_error_set(err, THZ_ERR_IO, "%s: no free staging directory name", outdir);
        goto cleanup;
    }
    *out = stage;
    return THZ_OK;
cleanup:
    free(stage->outdir);
    free(stage);
    return status;
}

const char *output_stage_dir(const output_stage *stage)
{
    return stage->dir;
}

static int stage_name_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void stage_free_names(char **names, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

/* The names of the regular files in dir (what writers create), sorted so that the
 * commit's order, and so which file a failure stops at, does not depend on readdir. */
static thz_status stage_list(const char *dir, char ***names_out, size_t *n_out, thz_error *err)
{
    *names_out = NULL;
    *n_out = 0;
    DIR *d = opendir(dir);
    if (!d)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot read the staging directory: %s", dir,
                             strerror(errno));
    thz_status status = THZ_OK;
    char **names = NULL;
    size_t n = 0, cap = 0;
    struct dirent *e;
    while (status == THZ_OK && (e = readdir(d)) != NULL) {
        char path[THZ_PATH_MAX];
        struct stat st;
        status = thz_path_join(path, sizeof path, dir, e->d_name, err);
        if (status != THZ_OK || lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        if (n == cap) {
            size_t new_cap = cap ? 2 * cap : 16;
            char **grown = thz_realloc_array(names, new_cap, sizeof *names);
            if (!grown) {
                status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", dir);
                break;
            }
            names = grown;
            cap = new_cap;
        }
        names[n] = thz_strdup(e->d_name);
        if (!names[n]) {
            status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", dir);
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

/* The three places of a staged file: in the stage, in OUTDIR, moved aside. */
static thz_status stage_paths(const output_stage *stage, const char *aside, const char *name,
                              char *staged, char *target, char *moved, thz_error *err)
{
    thz_status status = thz_path_join(staged, THZ_PATH_MAX, stage->dir, name, err);
    if (status == THZ_OK)
        status = thz_path_join(target, THZ_PATH_MAX, stage->outdir, name, err);
    if (status == THZ_OK)
        status = thz_path_join(moved, THZ_PATH_MAX, aside, name, err);
    return status;
}

/* Undoes a failed commit: removes the first n_placed new files from OUTDIR and renames
 * the moved-aside files (had_old) back. Returns false if some old file could not be put
 * back (it then stays in aside, which nothing removes). */
static bool stage_roll_back(const output_stage *stage, const char *aside, char **names,
                            const bool *had_old, size_t n, size_t n_placed)
{
    bool ok = true;
    for (size_t i = 0; i < n; i++) {
        char staged[THZ_PATH_MAX], target[THZ_PATH_MAX], moved[THZ_PATH_MAX];
        if (stage_paths(stage, aside, names[i], staged, target, moved, NULL) != THZ_OK)
            continue;   /* cannot happen: the same joins succeeded before */
        if (had_old[i]) /* atomically replaces the new file, if placed */
            ok &= rename(moved, target) == 0;
        else if (i < n_placed)
            unlink(target);
    }
    return ok;
}

thz_status output_stage_commit(output_stage *stage, thz_error *err)
{
    char **names = NULL;
    size_t n = 0, n_placed = 0;
    bool *had_old = NULL, made_aside = false;
    char aside[THZ_PATH_MAX], staged[THZ_PATH_MAX], target[THZ_PATH_MAX], moved[THZ_PATH_MAX];
    thz_status status = stage_list(stage->dir, &names, &n, err);
    if (status != THZ_OK)
        return status;
    had_old = thz_calloc(n, sizeof *had_old);
    if (!had_old) {
        status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", stage->outdir);
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

    /* 1. The files of the previous results that the new ones replace, aside. A directory
     * of a staged file's name is not moved: renaming the file onto it fails below. */
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

    /* Committed: the previous results go, then the (now empty) stage. */
    stage->committed = true;
    for (size_t i = 0; i < n; i++)
        if (had_old[i] &&
            stage_paths(stage, aside, names[i], staged, target, moved, NULL) == THZ_OK)
            unlink(moved);
    if (rmdir(aside) != 0 || rmdir(stage->dir) != 0)
        status = thz_error_set(err, THZ_ERR_IO,
                               "%s: results committed, but the staging directory %s cannot be "
                               "removed: %s",
                               stage->outdir, stage->dir, strerror(errno));
    made_aside = false;
cleanup:
    if (made_aside && status != THZ_OK)
        rmdir(aside); /* only when empty: a failed rollback leaves the old files there */
    stage_free_names(names, n);
    free(had_old);
    return status;
}

/* Removes dir's regular files (writers create nothing else) and dir itself. */
static void stage_remove(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            char path[THZ_PATH_MAX];
            if (thz_path_join(path, sizeof path, dir, e->d_name, NULL) == THZ_OK)
                unlink(path);
        }
        closedir(d);
    }
    rmdir(dir);
}

void output_stage_destroy(output_stage *stage)
{
    if (!stage)
        return;
    if (!stage->committed && stage->dir)
        stage_remove(stage->dir);
    /* rmdir removes only an empty directory: OUTDIR goes only if nothing else is there */
    if (!stage->committed && stage->created_outdir && stage->outdir)
        rmdir(stage->outdir);
    free(stage->dir);
    free(stage->outdir);
    free(stage);
}
