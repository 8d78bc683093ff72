/* Line catalogues and partition sums for the `lines` model (atm_lines.c), read from am
 * 14.0's CSV tables or HITRAN .par files (atm_catalog.c). Internal to src/atmosphere/.
 */
#ifndef THZ_ATMOSPHERE_ATM_CATALOG_H
#define THZ_ATMOSPHERE_ATM_CATALOG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* Largest line catalogue or table read: HITRAN's whole H2O list (all bands) as .par is
 * about 50 MB; a .par of every molecule is streamed, a CSV is held in memory. */
#define ATM_CATALOG_MAX_FILE_BYTES ((uint64_t)512 << 20)

/* One catalogue line as read (HITRAN reference state, am units). */
typedef struct raw_line {
    double nu0_ghz, s296_cm2_ghz, elower_k;
    double gamma_air, gamma_self; /* GHz/hPa, HWHM at 296 K */
    double n_air;
    double delta_air; /* GHz/hPa */
    int iso;
    /* line mixing (coupled lines only) */
    double y0, y1, yx, g0, g1, gx, d0, d1, dx, tref_k;
} raw_line;

typedef struct raw_catalog {
    size_t n, cap;
    raw_line *lines;
} raw_catalog;

/* Partition sums Q(T) of each isotopologue on an even temperature grid. */
typedef struct partition_sums {
    size_t n_t, n_iso;
    double t0_k, dt_k;
    double *q; /* n_t * n_iso */
} partition_sums;

/* A catalogue by its name: a HITRAN .par file (lines of `molecule`: 1 H2O, 7 O2) or am's
 * CSV table (without line mixing). The lines are appended to cat; on failure the message
 * names the file, line and column. */
thz_status atm_catalog_read(const char *path, int molecule, raw_catalog *cat, thz_error *err);
/* am 14.0's CSV catalogue (data/atmosphere/am14_*_lines*.csv); coupled: with the line
 * mixing columns. */
thz_status atm_catalog_read_csv(const char *path, bool coupled, raw_catalog *cat, thz_error *err);
/* Whether atm_catalog_read reads path as a HITRAN .par file. */
bool atm_catalog_is_par(const char *path);

/* A partition-sum table (columns T_K, Q_iso1, Q_iso2, ...); q->q is malloc'd. */
thz_status atm_partition_sums_read(const char *path, partition_sums *q, thz_error *err);
/* Q(T) of isotopologue iso (1-based), linear in T; NAN outside the table. */
double atm_partition_sum(const partition_sums *q, int iso, double t_k);

#endif
