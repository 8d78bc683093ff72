/* The `lines` model's input files, read and kept (atm_inputs.h). */
#include "atmosphere/atm_inputs.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/csv.h"

#define COUPLED_MATCH_GHZ 0.005 /* .par O2 lines this close to a coupled line are it */

/* ---- reading --------------------------------------------------------------------- */

/* Drops from cat the lines of isotopologue 1 within COUPLED_MATCH_GHZ of a coupled
 * line: a HITRAN O2 list holds the 60 GHz band and 118.75 GHz line, which the
 * coupled table already has (with line mixing). */
static void drop_coupled_duplicates(raw_catalog *cat, const raw_catalog *coupled)
{
    size_t n = 0;
    for (size_t i = 0; i < cat->n; i++) {
        bool dup = false;
        for (size_t j = 0; !dup && cat->lines[i].iso == 1 && j < coupled->n; j++)
            dup = fabs(cat->lines[i].nu0_ghz - coupled->lines[j].nu0_ghz) < COUPLED_MATCH_GHZ;
        if (!dup)
            cat->lines[n++] = cat->lines[i];
    }
    cat->n = n;
}

/* MT_CKD's table (columns nu_cm-1, C_foreign_ref_..., C_self_ref_..., self_texp). */
static thz_status read_continuum(atm_inputs *in, const char *path, thz_error *err)
{
    csv_table csv;
    thz_status st = csv_read(path, NULL, &csv, err);
    if (st != THZ_OK)
        return st;
    size_t c_nu, c_f, c_s, c_x;
    st = csv_column_index(&csv, "nu_cm-1", &c_nu, err);
    if (st == THZ_OK)
        st = csv_column_index(&csv, "C_foreign_ref_cm2_per_molec_per_cm-1", &c_f, err);
    if (st == THZ_OK)
        st = csv_column_index(&csv, "C_self_ref_cm2_per_molec_per_cm-1", &c_s, err);
    if (st == THZ_OK)
        st = csv_column_index(&csv, "self_texp", &c_x, err);
    if (st != THZ_OK)
        goto cleanup;
    in->cont_step_cm1 = csv.n_rows > 1 ? csv_value(&csv, 1, c_nu) : 0.0;
    if (csv.n_rows < 4 || csv_value(&csv, 0, c_nu) != 0.0 || !(in->cont_step_cm1 > 0.0)) {
        st = thz_error_set(err, THZ_ERR_INPUT,
                           "%s: the continuum table must start at 0 cm^-1, be evenly spaced and "
                           "have at least 4 rows",
                           path);
        goto cleanup;
    }
    in->c_foreign = thz_malloc_array(csv.n_rows, sizeof *in->c_foreign);
    in->c_self = thz_malloc_array(csv.n_rows, sizeof *in->c_self);
    in->self_texp = thz_malloc_array(csv.n_rows, sizeof *in->self_texp);
    if (!in->c_foreign || !in->c_self || !in->self_texp) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading %s", path);
        goto cleanup;
    }
    for (size_t r = 0; r < csv.n_rows; r++) {
        double nu = csv_value(&csv, r, c_nu);
        if (fabs(nu - (double)r * in->cont_step_cm1) > 1e-6 * in->cont_step_cm1) {
            st = thz_error_set(err, THZ_ERR_INPUT, "%s:%zu: wavenumbers must be evenly spaced",
                               path, csv.row_lines[r]);
            goto cleanup;
        }
        in->c_foreign[r] = csv_value(&csv, r, c_f);
        in->c_self[r] = csv_value(&csv, r, c_s);
        in->self_texp[r] = csv_value(&csv, r, c_x);
    }
    in->n_cont = csv.n_rows;
cleanup:
    csv_fini(&csv);
    return st;
}

static void inputs_fini(atm_inputs *in)
{
    free(in->h2o.lines);
    free(in->o2.lines);
    free(in->o2_coupled.lines);
    free(in->q_h2o.q);
    free(in->q_o2.q);
    free(in->c_foreign);
    free(in->c_self);
    free(in->self_texp);
    memset(in, 0, sizeof *in);
}

static thz_status inputs_read(const char *const paths[ATM_IN_FILES], atm_inputs *in, thz_error *err)
{
    memset(in, 0, sizeof *in);
    thz_status st = atm_catalog_read(paths[ATM_IN_H2O], 1, &in->h2o, err);
    if (st == THZ_OK)
        st = atm_catalog_read(paths[ATM_IN_O2], 7, &in->o2, err);
    if (st == THZ_OK)
        st = atm_catalog_read_csv(paths[ATM_IN_O2_COUPLED], true, &in->o2_coupled, err);
    if (st == THZ_OK)
        st = atm_partition_sums_read(paths[ATM_IN_Q_H2O], &in->q_h2o, err);
    if (st == THZ_OK)
        st = atm_partition_sums_read(paths[ATM_IN_Q_O2], &in->q_o2, err);
    if (st == THZ_OK && paths[ATM_IN_CONTINUUM][0] != '\0')
        st = read_continuum(in, paths[ATM_IN_CONTINUUM], err);
    if (st != THZ_OK) {
        inputs_fini(in);
        return st;
    }
    if (atm_catalog_is_par(paths[ATM_IN_O2]))
        drop_coupled_duplicates(&in->o2, &in->o2_coupled);
    return THZ_OK;
}

/* ---- the cache ------------------------------------------------------------------- */

/* A file as it was read: its name and what tells a changed file (0s: no file). */
typedef struct file_id {
    uint64_t dev, ino, size;
    int64_t mtime_s, mtime_ns;
} file_id;

typedef struct inputs_entry {
    atm_inputs in; /* first: acquire hands out &entry->in */
    char *paths[ATM_IN_FILES];
    file_id ids[ATM_IN_FILES];
    unsigned refs; /* acquired and not yet released */
    bool cached;   /* in slots[] (else freed at its last release) */
    uint64_t last_use;
} inputs_entry;

static pthread_mutex_t cache_lock = PTHREAD_MUTEX_INITIALIZER;
static inputs_entry *slots[ATM_INPUTS_CACHED];
static uint64_t use_clock;
static uint64_t reads; /* the last read_id handed out */

static void entry_free(inputs_entry *e)
{
    inputs_fini(&e->in);
    for (int i = 0; i < ATM_IN_FILES; i++)
        free(e->paths[i]);
    free(e);
}

/* The files' identities (false: one cannot be stat'ed; the read reports it). */
static bool files_identify(const char *const paths[ATM_IN_FILES], file_id ids[ATM_IN_FILES])
{
    for (int i = 0; i < ATM_IN_FILES; i++) {
        memset(&ids[i], 0, sizeof ids[i]);
        struct stat s;
        if (paths[i][0] == '\0')
            continue;
        if (stat(paths[i], &s) != 0)
            return false;
        ids[i] = (file_id){(uint64_t)s.st_dev, (uint64_t)s.st_ino, (uint64_t)s.st_size,
                           (int64_t)s.st_mtim.tv_sec, (int64_t)s.st_mtim.tv_nsec};
    }
    return true;
}

static bool entry_matches(const inputs_entry *e, const char *const paths[ATM_IN_FILES],
                          const file_id ids[ATM_IN_FILES])
{
    for (int i = 0; i < ATM_IN_FILES; i++)
        if (strcmp(e->paths[i], paths[i]) != 0 || memcmp(&e->ids[i], &ids[i], sizeof ids[i]) != 0)
            return false;
    return true;
}

/* Puts e in a free slot, or in that of the least recently used set none holds; where
 * every slot is held, e stays out (freed at its release). Under cache_lock. */
static void cache_insert(inputs_entry *e)
{
    int victim = -1;
    for (int i = 0; i < ATM_INPUTS_CACHED; i++) {
        if (!slots[i]) {
            victim = i;
            break;
        }
        if (slots[i]->refs == 0 && (victim < 0 || slots[i]->last_use < slots[victim]->last_use))
            victim = i;
    }
    if (victim < 0)
        return;
    if (slots[victim])
        entry_free(slots[victim]);
    slots[victim] = e;
    e->cached = true;
}

thz_status atm_inputs_acquire(const char *const paths[ATM_IN_FILES], const atm_inputs **out,
                              thz_error *err)
{
    *out = NULL;
    file_id ids[ATM_IN_FILES];
    bool known = files_identify(paths, ids);
    if (known) {
        pthread_mutex_lock(&cache_lock);
        for (int i = 0; i < ATM_INPUTS_CACHED; i++) {
            inputs_entry *e = slots[i];
            if (e && entry_matches(e, paths, ids)) {
                e->refs++;
                e->last_use = ++use_clock;
                *out = &e->in;
                break;
            }
        }
        pthread_mutex_unlock(&cache_lock);
        if (*out)
            return THZ_OK;
    }
    inputs_entry *e = thz_calloc(1, sizeof *e);
    if (!e)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory reading the line catalogues");
    thz_status st = inputs_read(paths, &e->in, err);
    if (st != THZ_OK) {
        free(e);
        return st;
    }
    e->refs = 1;
    pthread_mutex_lock(&cache_lock);
    e->in.read_id = ++reads;
    pthread_mutex_unlock(&cache_lock);
    /* kept only when every file is as it was before the read (else one changed while it
     * was read: this process uses what it read, the next reads it again) */
    file_id after[ATM_IN_FILES];
    bool keep = known && files_identify(paths, after) && memcmp(ids, after, sizeof ids) == 0;
    for (int i = 0; keep && i < ATM_IN_FILES; i++)
        keep = (e->paths[i] = thz_strdup(paths[i])) != NULL; /* none: not kept */
    if (keep) {
        memcpy(e->ids, ids, sizeof ids);
        pthread_mutex_lock(&cache_lock);
        e->last_use = ++use_clock;
        cache_insert(e);
        pthread_mutex_unlock(&cache_lock);
    }
    *out = &e->in;
    return THZ_OK;
}

void atm_inputs_release(const atm_inputs *in)
{
    if (!in)
        return;
    inputs_entry *e = (inputs_entry *)(uintptr_t)in; /* in is e's first member */
    pthread_mutex_lock(&cache_lock);
    bool last = --e->refs == 0 && !e->cached;
    pthread_mutex_unlock(&cache_lock);
    if (last)
        entry_free(e);
}
