/* The hash of a frame's inputs (batch_internal.h): 64-bit FNV-1a over bytes, and over
 * the content of every file a frame's scene names, each file read once per sequence.
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "core/file.h"

/* The hash of a file the frames name ("file", "*_file" keys), cached per path; 0 when
 * it cannot be read (the scene loader then reports it). */
static uint64_t hash_file(json_t *cache, const char *scene_dir, const char *name)
{
    char path[4096];
    if (name[0] == '/')
        snprintf(path, sizeof path, "%s", name);
    else
        snprintf(path, sizeof path, "%s/%s", scene_dir, name);
    json_t *cached = json_object_get(cache, path);
    if (cached)
        return (uint64_t)strtoull(json_string_value(cached), NULL, 16);
    uint64_t h = BATCH_HASH_INIT;
    thz_error ignored; /* a FIFO or device would block or never end (core/file.h) */
    FILE *f = file_check_regular(path, path, UINT64_MAX, NULL, &ignored) == THZ_OK
                  ? fopen(path, "rb")
                  : NULL;
    if (f) {
        unsigned char buf[65536];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0)
            h = batch_hash_bytes(h, buf, n);
        fclose(f);
    } else {
        h = 0;
    }
    char hex[17];
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)h);
    json_object_set_new(cache, path, json_string(hex));
    return h;
}

uint64_t batch_hash_files(json_t *cache, const char *scene_dir, const json_t *v, uint64_t h)
{
    if (json_is_object(v)) {
        const char *key;
        json_t *child;
        json_object_foreach((json_t *)v, key, child)
        {
            size_t len = strlen(key);
            int is_file = !strcmp(key, "file") || (len > 5 && !strcmp(key + len - 5, "_file"));
            if (is_file && json_is_string(child)) {
                uint64_t fh = hash_file(cache, scene_dir, json_string_value(child));
                h = batch_hash_bytes(h, &fh, sizeof fh);
            } else {
                h = batch_hash_files(cache, scene_dir, child, h);
            }
        }
    } else if (json_is_array(v)) {
        for (size_t i = 0; i < json_array_size(v); i++)
            h = batch_hash_files(cache, scene_dir, json_array_get(v, i), h);
    }
    return h;
}

uint64_t batch_hash_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= UINT64_C(1099511628211);
    }
    return h;
}
