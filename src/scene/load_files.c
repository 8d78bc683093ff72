/* The files a scene or a sequence names (meshes, CSV tables, channel responses, line
 * catalogues, a sequence's scenes): their names resolved against the directory of the
 * file that names them and, when loading is confined to a root (`thzmap serve --root`,
 * thz_scene_load_within), refused unless they lie under it. Every file reference of
 * the loader (load_file_path) and of sequences goes through load_file_check, and the
 * scene and sequence files themselves through load_file_confine, so the rule lives
 * here alone.
 *
 * Time of check and time of use: the check resolves the path (realpath: symlinks,
 * "." and "..") and the caller then opens that resolved path, which holds no symlink.
 * A directory on it replaced by a symlink between the two steps is not seen; that needs
 * write access under the root, which the server's API does not give (it writes .json
 * files only, atomically).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "scene/load.h"

/* Refusals: they say what the name is, never what lies outside the root. */
static const char load_files_absolute[] =
    "is an absolute path, refused: with a served root (thzmap serve --root) a scene may "
    "name only files under the root, by relative paths";
static const char load_files_outside[] = "is outside the served root, refused";
static const char load_files_missing[] = "does not exist under the served root";
static const char load_files_unresolved[] =
    "cannot be resolved under the served root (a broken link, a loop of links or no "
    "permission), refused";

/* Whether the real path `real` is the real path `root` or lies below it. */
static bool load_files_below(const char *root, const char *real)
{
    size_t n = strlen(root);
    if (strncmp(real, root, n) != 0)
        return false;
    return real[n] == '\0' || real[n] == '/' || (n == 1 && root[0] == '/');
}

/* Why `path`, which realpath could not resolve (errno still its failure), is refused:
 * its deepest ancestor that resolves decides. Outside the root: outside, whatever lies
 * beyond it, so that a missing or unreadable name outside reads as any other name
 * outside. Under the root: missing, unless a link, a loop or a permission stood in the
 * way. NULL when memory runs out. */
static const char *load_files_why_unresolved(const char *path, const char *root)
{
    struct stat lst;
    /* a missing name; not a broken link, a loop or a denied search */
    bool missing = (errno == ENOENT || errno == ENOTDIR) && lstat(path, &lst) != 0;
    char *probe = thz_strdup(path);
    if (!probe)
        return NULL;
    const char *why = NULL;
    while (!why) {
        if (strcmp(probe, ".") == 0 || strcmp(probe, "/") == 0) {
            why = load_files_unresolved; /* not even the top resolves */
            break;
        }
        char *slash = strrchr(probe, '/');
        while (slash && slash > probe && slash[-1] == '/')
            slash--;
        if (slash == probe)
            slash[1] = '\0'; /* "/x": its ancestor is "/" */
        else if (slash)
            *slash = '\0';
        else
            strcpy(probe, ".");
        char *real = realpath(probe, NULL);
        if (real)
            why = !load_files_below(root, real) ? load_files_outside
                  : missing                     ? load_files_missing
                                                : load_files_unresolved;
        else if ((errno != ENOENT && errno != ENOTDIR) || lstat(probe, &lst) == 0)
            missing = false; /* an ancestor that exists yet does not resolve */
        free(real);
    }
    free(probe);
    return why;
}

thz_status load_file_confine(const char *path, const char *root, char **real, const char **refusal)
{
    *real = NULL;
    *refusal = NULL;
    if (!root) {
        *real = thz_strdup(path);
        return *real ? THZ_OK : THZ_ERR_NOMEM;
    }
    errno = 0;
    char *resolved = realpath(path, NULL);
    if (!resolved && errno == ENOMEM)
        return THZ_ERR_NOMEM;
    if (!resolved) {
        *refusal = load_files_why_unresolved(path, root);
        return *refusal ? THZ_ERR_INPUT : THZ_ERR_NOMEM;
    }
    if (!load_files_below(root, resolved)) {
        free(resolved);
        *refusal = load_files_outside;
        return THZ_ERR_INPUT;
    }
    *real = resolved;
    return THZ_OK;
}

thz_status load_file_check(const char *name, const char *path, const char *root, char **real,
                           const char **refusal)
{
    *real = NULL;
    *refusal = NULL;
    if (root && name[0] == '/') {
        *refusal = load_files_absolute;
        return THZ_ERR_INPUT;
    }
    return load_file_confine(path, root, real, refusal);
}

thz_status load_root_real(const char *root, char **real, thz_error *err)
{
    *real = NULL;
    if (!root)
        return THZ_OK;
    errno = 0;
    *real = realpath(root, NULL);
    if (!*real && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    struct stat st;
    if (!*real || stat(*real, &st) != 0 || !S_ISDIR(st.st_mode)) {
        free(*real);
        *real = NULL;
        return thz_error_set(err, THZ_ERR_INPUT, "%s: the root is not a directory", root);
    }
    return THZ_OK;
}

thz_status load_file_path(load_ctx *ctx, const load_cursor *k, const char *name, char **path,
                          char **label)
{
    *path = NULL;
    if (name[0] == '/' || !ctx->dir || !ctx->dir[0] || strcmp(ctx->dir, ".") == 0) {
        *label = thz_strdup(name);
    } else {
        size_t n = strlen(ctx->dir) + strlen(name) + 2;
        *label = malloc(n);
        if (*label)
            snprintf(*label, n, "%s/%s", ctx->dir, name);
    }
    const char *refusal = NULL;
    thz_status st =
        *label ? load_file_check(name, *label, ctx->root, path, &refusal) : THZ_ERR_NOMEM;
    if (st != THZ_OK) {
        free(*label);
        *label = NULL;
    }
    if (st == THZ_ERR_INPUT)
        return load_fail(ctx, k, "\"%s\" %s", name, refusal);
    if (st != THZ_OK)
        return thz_error_set(ctx->err, st, "out of memory");
    return THZ_OK;
}
