/* The run-time data directory: where the library finds the files it ships
 * (data/atmosphere/: the line catalogues, partition sums, continuum and ITU tables).
 *
 * The one rule, in this order (the first that applies wins):
 *   1. a directory the caller names (an internal option; NULL or "" skips it);
 *   2. the environment variable THZMAP_DATA_DIR, when set and not empty;
 *   3. relative to the installed binary that contains this code: the shared library
 *      libthzmap.so (its directory + "/../share/thzmap" for PREFIX/lib) or, when the
 *      library is linked statically, the executable (PREFIX/bin → PREFIX/share/thzmap),
 *      used when that directory exists; so an installed tree can be moved as a whole;
 *   4. the data/ directory of the source tree the build was made from (compiled in),
 *      so that the uninstalled build and the tests work without installing.
 * Nothing is cached: the environment is read on every call.
 */
#ifndef THZ_CORE_DATA_DIR_H
#define THZ_CORE_DATA_DIR_H

#include <stddef.h>

#include "core/error.h"

/* Writes the data directory chosen by the rule above into out (size bytes, NUL
 * included; THZ_PATH_MAX is enough). given may be NULL. THZ_ERR_IO naming the path if
 * it does not fit (out then holds ""). Thread-safe; reads the environment. */
thz_status thz_data_dir_find(const char *given, char *out, size_t size, thz_error *err);

/* The path of the data file `name` ("atmosphere/am14_h2o_lines.csv") in that directory,
 * into out, checked readable. A file missing there is THZ_ERR_IO, not bad input: thzmap
 * installed in part, or THZMAP_DATA_DIR naming an incomplete copy; the message names the
 * file, the directory, which rule chose it, and the remedy. */
thz_status thz_data_file(const char *given, const char *name, char *out, size_t size,
                         thz_error *err);

#endif
