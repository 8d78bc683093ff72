/* The scene files a sequence names: one "scene" (every frame built from it) or a plain
 * list "scenes" (frame i of each sweep value is scene i, as it is): their paths resolved
 * against the sequence file's directory, their directories (the base of the relative
 * paths inside them) and their JSON documents, each checked to be a regular file
 * holding a JSON object. batch_sequence.c builds the frames from what this loads.
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "scene/load.h"

enum { SCENES_MAX = 100000 };

/* Resolves name against seq_dir into seq->scene_paths[k] and seq->scene_dirs[k] and
 * loads the file into docs[k] (its real path when confined to seq->root); where: its
 * JSON path in the sequence ("scenes[2]"). */
static thz_status scenes_load_one(const char *label, const char *seq_dir, const char *where,
                                  const char *name, thz_sequence *seq, size_t k, json_t **docs,
                                  thz_error *err)
{
    char path[4096], what[4400];
    if (!name || !name[0])
        return thz_error_set(err, THZ_ERR_INPUT, "%s: %s: expected a scene file's name (a string)",
                             label, where);
    if (snprintf(path, sizeof path, "%s%s%s", name[0] == '/' ? "" : seq_dir,
                 name[0] == '/' ? "" : "/", name) >= (int)sizeof path)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: %s: path too long", label, where);
    char *real = NULL;
    const char *refusal = NULL;
    thz_status st = load_file_check(name, path, seq->root, &real, &refusal);
    if (st == THZ_ERR_INPUT)
        return thz_error_set(err, st, "%s: %s: \"%s\" %s", label, where, name, refusal);
    if (st != THZ_OK)
        return thz_error_set(err, st, "%s: out of memory", label);
    seq->scene_paths[k] = thz_strdup(path);
    char *slash = strrchr(path, '/');
    if (slash)
        *slash = '\0';
    seq->scene_dirs[k] = thz_strdup(slash ? (path[0] ? path : "/") : ".");
    if (!seq->scene_paths[k] || !seq->scene_dirs[k]) {
        free(real);
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", label);
    }
    snprintf(what, sizeof what, "%s: %s: %s", label, where, seq->scene_paths[k]);
    st = load_json_file(seq->scene_paths[k], real, what, "scene", LOAD_MAX_SCENE_BYTES, &docs[k],
                        err);
    free(real);
    if (st != THZ_OK)
        return st;
    if (!json_is_object(docs[k]))
        return thz_error_set(err, THZ_ERR_INPUT, "%s: expected a scene object",
                             seq->scene_paths[k]);
    return THZ_OK;
}

thz_status batch_scenes_load(const char *label, const json_t *root, const char *seq_dir,
                             thz_sequence *seq, json_t ***docs, thz_error *err)
{
    *docs = NULL;
    const json_t *one = json_object_get(root, "scene"), *list = json_object_get(root, "scenes");
    if (one && list)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: scenes: give either \"scene\" (with keyframes) or \"scenes\" "
                             "(a list of scene files), not both",
                             label);
    if (!one && !list)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: scene: expected the scene file's name (a string), or "
                             "\"scenes\": a list of scene files",
                             label);
    if (list && (!json_is_array(list) || json_array_size(list) == 0))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: scenes: expected a non-empty list of scene files, got %s", label,
                             json_is_array(list)    ? "an empty one"
                             : json_is_string(list) ? "a string"
                             : json_is_object(list) ? "an object"
                                                    : "a number or a literal");
    if (list && json_array_size(list) > SCENES_MAX)
        return thz_error_set(err, THZ_ERR_INPUT, "%s: scenes: more than 100000 scene files", label);
    if (list && json_object_get(root, "keyframes"))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: keyframes: not with \"scenes\" (each listed scene is one frame, "
                             "as it is); use \"scene\" with keyframes",
                             label);
    if (list && json_object_get(root, "frames"))
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s: frames: not with \"scenes\" (one frame per listed scene)", label);
    size_t n = list ? json_array_size(list) : 1;
    seq->n_scenes = n;
    seq->scene_list = list != NULL;
    seq->scene_paths = thz_calloc(n, sizeof *seq->scene_paths);
    seq->scene_dirs = thz_calloc(n, sizeof *seq->scene_dirs);
    *docs = thz_calloc(n, sizeof **docs);
    if (!seq->scene_paths || !seq->scene_dirs || !*docs)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", label);
    for (size_t k = 0; k < n; k++) {
        char where[32] = "scene";
        if (list)
            snprintf(where, sizeof where, "scenes[%zu]", k);
        const json_t *name = list ? json_array_get(list, k) : one;
        thz_status st =
            scenes_load_one(label, seq_dir, where, json_string_value(name), seq, k, *docs, err);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}

void batch_scenes_free(json_t **docs, size_t n)
{
    for (size_t k = 0; docs && k < n; k++)
        json_decref(docs[k]);
    free(docs);
}
