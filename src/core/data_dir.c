/* Locating the run-time data directory (see data_dir.h for the rule). */
#define _GNU_SOURCE /* dladdr1 and RTLD_DL_LINKMAP (glibc) */
#include "core/data_dir.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <link.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/path.h"

/* The build's own data directory, and the data directory relative to the directories
 * the library and the program are installed in (set by CMake from GNUInstallDirs). */
#ifndef THZ_DATA_DIR
#define THZ_DATA_DIR "data"
#endif
#ifndef THZ_DATA_FROM_LIBDIR
#define THZ_DATA_FROM_LIBDIR "../share/thzmap"
#endif
#ifndef THZ_DATA_FROM_BINDIR
#define THZ_DATA_FROM_BINDIR "../share/thzmap"
#endif

/* An object of the library whose address dladdr maps back to the file holding the
 * library's code (an object, not a function: ISO C has no function-to-void* cast). */
static const char data_dir_anchor = 0;

static thz_status copy_path(char *out, size_t size, const char *path, thz_error *err)
{
    return thz_path_join(out, size, "", path, err);
}

/* The installed data directory next to the file that contains this code, resolved
 * (no symlinks, no ".."), into out; false if there is none or it is not a directory. */
static bool installed_dir(char *out, size_t size)
{
    Dl_info info;
    struct link_map *map = NULL;
    if (!dladdr1(&data_dir_anchor, &info, (void **)&map, RTLD_DL_LINKMAP) || !map)
        return false;
    /* The main program's link map has an empty name (dladdr would report argv[0],
     * which may be a bare name found through PATH): ask the kernel instead. */
    bool in_program = !map->l_name || !map->l_name[0];
    char file[PATH_MAX];
    if (in_program) {
        ssize_t n = readlink("/proc/self/exe", file, sizeof file - 1);
        if (n <= 0)
            return false;
        file[n] = '\0';
    } else if (!realpath(map->l_name, file)) {
        return false;
    }
    char *slash = strrchr(file, '/');
    if (!slash)
        return false;
    slash[1] = '\0';
    char candidate[PATH_MAX], resolved[PATH_MAX];
    if (thz_path_join(candidate, sizeof candidate, file,
                      in_program ? THZ_DATA_FROM_BINDIR : THZ_DATA_FROM_LIBDIR, NULL) != THZ_OK)
        return false;
    struct stat st;
    if (!realpath(candidate, resolved) || stat(resolved, &st) != 0 || !S_ISDIR(st.st_mode))
        return false;
    return copy_path(out, size, resolved, NULL) == THZ_OK;
}

/* The rule of data_dir.h; *source says which step chose the directory, in words. */
static thz_status data_dir_choose(const char *given, char *out, size_t size, const char **source,
                                  thz_error *err)
{
    if (given && given[0]) {
        *source = "as given";
        return copy_path(out, size, given, err);
    }
    const char *env = getenv("THZMAP_DATA_DIR");
    if (env && env[0]) {
        *source = "from THZMAP_DATA_DIR";
        return copy_path(out, size, env, err);
    }
    if (installed_dir(out, size)) {
        *source = "installed with the library";
        return THZ_OK;
    }
    *source = "the build's, as no share/thzmap lies beside the library";
    return copy_path(out, size, THZ_DATA_DIR, err);
}

thz_status thz_data_dir_find(const char *given, char *out, size_t size, thz_error *err)
{
    const char *source;
    return data_dir_choose(given, out, size, &source, err);
}

thz_status thz_data_file(const char *given, const char *name, char *out, size_t size,
                         thz_error *err)
{
    char dir[THZ_PATH_MAX];
    const char *source;
    thz_status st = data_dir_choose(given, dir, sizeof dir, &source, err);
    if (st == THZ_OK)
        st = thz_path_join(out, size, dir, name, err);
    if (st != THZ_OK)
        return st;
    if (access(out, R_OK) != 0)
        return thz_error_set(err, THZ_ERR_IO,
                             "%s: cannot read thzmap's own data file (%s); the data directory "
                             "%s (%s) lacks it: reinstall thzmap, or set THZMAP_DATA_DIR to a "
                             "complete copy of its data",
                             out, strerror(errno), dir, source);
    return THZ_OK;
}
