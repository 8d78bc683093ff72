/* Band tables already computed in this process (atmosphere_prepare's, atmosphere.c), so
 * that an atmosphere whose table inputs are those of an earlier one copies the tables
 * instead of tabulating again: a sequence's frames each load their scene, and with the
 * same air every frame computed the same tables (the walker's two channels with `lines`:
 * 6.8 ms of the 10.3 ms each frame's check took; docs/atmosphere.md). An entry is keyed
 * by the bytes of everything its table is computed from (atmosphere.c's table_key_model
 * and band_table: the model's data and air, the band's interval); a hit is a
 * byte-for-byte match of the whole key, found through its 64-bit hash, so a table handed
 * out is the one tabulating would give, to the bit. At most ATM_TABLE_CACHE_ENTRIES
 * tables holding at most ATM_TABLE_CACHE_BYTES of points are kept, the least recently
 * used dropped first. Thread-safe. Internal to src/atmosphere/. */
#ifndef THZ_ATMOSPHERE_ATM_TABLE_CACHE_H
#define THZ_ATMOSPHERE_ATM_TABLE_CACHE_H

#include <stdbool.h>
#include <stddef.h>

#include "atmosphere/atmosphere.h"

#define ATM_TABLE_CACHE_ENTRIES 64
#define ATM_TABLE_CACHE_BYTES ((size_t)64 << 20)

/* A key: bytes appended in a fixed order by whoever knows what a table depends on. */
typedef struct atm_table_key {
    unsigned char *bytes;
    size_t n, cap;
    bool failed; /* out of memory while adding: the key matches nothing, is never stored */
} atm_table_key;

/* Appends n bytes of data; an empty key is {0}. */
void atm_table_key_add(atm_table_key *key, const void *data, size_t n);
void atm_table_key_fini(atm_table_key *key);

/* A copy of the table stored under key into *out (the caller frees out->alpha_per_m):
 * true; false (out untouched) where none is, or the copy ran out of memory. */
bool atm_table_cache_get(const atm_table_key *key, atm_band_table *out);

/* Stores a copy of t under key (nothing where one is there already, the key failed, t is
 * larger than ATM_TABLE_CACHE_BYTES or memory runs out: the cache is an optimisation). */
void atm_table_cache_put(const atm_table_key *key, const atm_band_table *t);

/* For tests: drops every table, and how many gets have hit since the process started. */
void atm_table_cache_clear(void);
size_t atm_table_cache_hits(void);

#endif
