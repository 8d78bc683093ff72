/* Band tables kept for atmospheres whose table inputs repeat (atm_table_cache.h). */
#include "atmosphere/atm_table_cache.h"

#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

typedef struct cache_entry {
    uint64_t hash;
    unsigned char *key;
    size_t key_n;
    atm_band_table table;
    uint64_t last_use;
} cache_entry;

static pthread_mutex_t cache_lock = PTHREAD_MUTEX_INITIALIZER;
static cache_entry entries[ATM_TABLE_CACHE_ENTRIES]; /* key NULL: free */
static size_t cached_bytes;
static uint64_t use_clock;
static size_t hits;

void atm_table_key_add(atm_table_key *key, const void *data, size_t n)
{
    if (key->failed)
        return;
    while (n > key->cap - key->n) {
        unsigned char *bytes = thz_grow_array(key->bytes, &key->cap, 256, 1);
        if (!bytes) {
            key->failed = true;
            return;
        }
        key->bytes = bytes;
    }
    memcpy(key->bytes + key->n, data, n);
    key->n += n;
}

void atm_table_key_fini(atm_table_key *key)
{
    free(key->bytes);
    memset(key, 0, sizeof *key);
}

/* 64-bit FNV-1a. */
static uint64_t key_hash(const atm_table_key *key)
{
    uint64_t h = 0xcbf29ce484222325u;
    for (size_t i = 0; i < key->n; i++)
        h = (h ^ key->bytes[i]) * 0x100000001b3u;
    return h;
}

static size_t table_bytes(const atm_band_table *t)
{
    return t->n * sizeof *t->alpha_per_m;
}

/* The entry holding key (hash its hash), or NULL. Under cache_lock. */
static cache_entry *find(const atm_table_key *key, uint64_t hash)
{
    for (size_t i = 0; i < ATM_TABLE_CACHE_ENTRIES; i++) {
        cache_entry *e = &entries[i];
        if (e->key && e->hash == hash && e->key_n == key->n &&
            memcmp(e->key, key->bytes, key->n) == 0)
            return e;
    }
    return NULL;
}

static void entry_drop(cache_entry *e)
{
    cached_bytes -= table_bytes(&e->table);
    free(e->key);
    free(e->table.alpha_per_m);
    memset(e, 0, sizeof *e);
}

/* The least recently used entry, NULL where all are free. Under cache_lock. */
static cache_entry *oldest(void)
{
    cache_entry *old = NULL;
    for (size_t i = 0; i < ATM_TABLE_CACHE_ENTRIES; i++)
        if (entries[i].key && (!old || entries[i].last_use < old->last_use))
            old = &entries[i];
    return old;
}

bool atm_table_cache_get(const atm_table_key *key, atm_band_table *out)
{
    if (key->failed || key->n == 0)
        return false;
    uint64_t hash = key_hash(key);
    bool found = false;
    pthread_mutex_lock(&cache_lock);
    cache_entry *e = find(key, hash);
    double *copy = e ? thz_malloc_array(e->table.n, sizeof *copy) : NULL;
    if (copy) {
        memcpy(copy, e->table.alpha_per_m, table_bytes(&e->table));
        *out = e->table;
        out->alpha_per_m = copy;
        e->last_use = ++use_clock;
        hits++;
        found = true;
    }
    pthread_mutex_unlock(&cache_lock);
    return found;
}

void atm_table_cache_put(const atm_table_key *key, const atm_band_table *t)
{
    size_t bytes = table_bytes(t);
    if (key->failed || key->n == 0 || bytes > ATM_TABLE_CACHE_BYTES)
        return;
    uint64_t hash = key_hash(key);
    unsigned char *key_copy = thz_malloc_array(key->n, 1);
    double *alpha = thz_malloc_array(t->n, sizeof *alpha);
    if (!key_copy || !alpha) {
        free(key_copy);
        free(alpha);
        return;
    }
    memcpy(key_copy, key->bytes, key->n);
    memcpy(alpha, t->alpha_per_m, bytes);
    pthread_mutex_lock(&cache_lock);
    cache_entry *slot = NULL;
    if (!find(key, hash)) { /* else another thread tabulated the same band meanwhile */
        for (size_t i = 0; !slot && i < ATM_TABLE_CACHE_ENTRIES; i++)
            if (!entries[i].key)
                slot = &entries[i];
        while (!slot || cached_bytes + bytes > ATM_TABLE_CACHE_BYTES) {
            cache_entry *old = oldest();
            entry_drop(old); /* there is one: bytes fits the empty cache */
            if (!slot)
                slot = old;
        }
        *slot = (cache_entry){
            .hash = hash, .key = key_copy, .key_n = key->n, .table = *t, .last_use = ++use_clock};
        slot->table.alpha_per_m = alpha;
        cached_bytes += bytes;
    }
    pthread_mutex_unlock(&cache_lock);
    if (!slot) {
        free(key_copy);
        free(alpha);
    }
}

void atm_table_cache_clear(void)
{
    pthread_mutex_lock(&cache_lock);
    for (size_t i = 0; i < ATM_TABLE_CACHE_ENTRIES; i++)
        if (entries[i].key)
            entry_drop(&entries[i]);
    pthread_mutex_unlock(&cache_lock);
}

size_t atm_table_cache_hits(void)
{
    pthread_mutex_lock(&cache_lock);
    size_t n = hits;
    pthread_mutex_unlock(&cache_lock);
    return n;
}
