/* Locating the data directory of data/atmosphere/ (its CSV tables are read by
 * core/csv.h). */
#include <stdlib.h>

#include "atmosphere/atm_internal.h"

#ifndef THZ_DATA_DIR
#define THZ_DATA_DIR "data"
#endif

const char *atm_data_dir(const char *dir)
{
    if (dir && dir[0])
        return dir;
    const char *env = getenv("THZMAP_DATA_DIR");
    if (env && env[0])
        return env;
    return THZ_DATA_DIR;
}
