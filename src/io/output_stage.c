/* Atomic results: a staging directory inside OUTDIR that writers fill and that is
 * moved into OUTDIR file by file (rename(2) is atomic per file) only when the whole run
 * has succeeded. A run that fails or is interrupted destroys the stage, so OUTDIR never
 * holds a half-written result file.
 *
 * The staging directory is OUTDIR/.thzmap-staging-<pid>-<n>/, n the first number for
 * which mkdir succeeds, so that concurrent runs into one OUTDIR do not collide.
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

/* "dir/name" in a new string; NULL on allocation failure. */
static char *stage_join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + 1 + strlen(name) + 1;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/%s", dir, name);
    return s;
}

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
        char name[64];
        snprintf(name, sizeof name, ".thzmap-staging-%ld-%d", (long)getpid(), n);
        char *dir = stage_join(outdir, name);
        if (!dir) {
            status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", outdir);
            goto cleanup;
        }
        if (mkdir(dir, 0777) == 0) {
            stage->dir = dir;
            break;
        }
        int e = errno;
        free(dir);
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

thz_status output_stage_commit(output_stage *stage, thz_error *err)
{
    thz_status status = THZ_OK;
    DIR *d = opendir(stage->dir);
    if (!d)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot read the staging directory: %s",
                             stage->dir, strerror(errno));
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        char *from = stage_join(stage->dir, e->d_name);
        char *to = stage_join(stage->outdir, e->d_name);
        struct stat st;
        if (!from || !to) {
            status = thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", stage->outdir);
        } else if (lstat(from, &st) == 0 && S_ISREG(st.st_mode) && rename(from, to) != 0) {
            status = thz_error_set(err, THZ_ERR_IO, "%s: cannot move into place: %s", to,
                                   strerror(errno));
        }
        free(from);
        free(to);
        if (status != THZ_OK)
            break;
    }
    closedir(d);
    if (status != THZ_OK)
        return status;
    /* Only staged files are moved; the directory must now be empty. */
    if (rmdir(stage->dir) != 0)
        return thz_error_set(err, THZ_ERR_IO, "%s: cannot remove the staging directory: %s",
                             stage->dir, strerror(errno));
    stage->committed = true;
    return THZ_OK;
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
            char *path = stage_join(dir, e->d_name);
            if (path)
                unlink(path);
            free(path);
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
