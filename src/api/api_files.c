/* Telling thzmap's files apart (thz_file_identify): a photon-map file by its first bytes,
 * a scene or sequence file by the "format" of its JSON object. */
#include <errno.h>
#include <jansson.h>
#include <string.h>

#include "api/api.h"
#include "core/file.h"
#include "scene/load.h"

thz_status thz_file_identify(const char *path, thz_file_kind *out, thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_file_identify: no place for the kind");
    *out = THZ_FILE_OTHER;
    if (!path)
        return thz_error_set(err, THZ_ERR_INPUT, "thz_file_identify: no path");
    thz_error_clear(err);
    uint64_t size = 0;
    thz_status st = file_check_regular(path, NULL, UINT64_MAX, &size, err);
    if (st != THZ_OK)
        return st;
    unsigned char head[FILE_HEAD_BYTES];
    errno = 0;
    size_t n = file_read_head(path, head);
    if (n == 0 && size > 0 && errno == ENOMEM)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory while opening the file", path);
    if (n == 0 && size > 0 && errno != 0)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: cannot read: %s", path, strerror(errno));
    if (n >= 8 && memcmp(head, FILE_MAGIC_PHOTON_MAP, 8) == 0) {
        *out = THZ_FILE_PHOTON_MAP;
        return THZ_OK;
    }
    if (size > LOAD_MAX_SCENE_BYTES)
        return THZ_OK; /* no scene or sequence is this large */
    json_t *doc = NULL;
    thz_error parse = {0};
    st = load_json_file(path, NULL, NULL, "file", LOAD_MAX_SCENE_BYTES, &doc, &parse);
    if (st == THZ_ERR_NOMEM)
        return thz_error_set(err, st, "%s", parse.message);
    if (st != THZ_OK)
        return THZ_OK; /* not JSON (or changed under us): none of thzmap's JSON files */
    const char *format = json_string_value(json_object_get(doc, "format"));
    if (format && (!strcmp(format, LOAD_FORMAT) || !strcmp(format, LOAD_FORMAT_1_1)))
        *out = THZ_FILE_SCENE;
    else if (format && !strcmp(format, LOAD_SEQUENCE_FORMAT))
        *out = THZ_FILE_SEQUENCE;
    json_decref(doc);
    return THZ_OK;
}
