/* A loaded sequence's frames through the public API (include/thzmap/batch.h): counts,
 * each frame's place, time, directory and input hash, its scene as JSON text or loaded,
 * and freeing. batch_sequence.c builds what these read.
 */
#include <stdlib.h>
#include <string.h>

#include "batch/batch_internal.h"
#include "core/error.h"

void thz_sequence_destroy(thz_sequence *seq)
{
    if (!seq)
        return;
    for (size_t f = 0; f < seq->n_frames; f++) {
        if (seq->frame_json)
            free(seq->frame_json[f]);
        if (seq->frame_dir)
            free(seq->frame_dir[f]);
    }
    for (size_t s = 0; seq->sweep_label && s < seq->n_sweeps; s++)
        free(seq->sweep_label[s]);
    for (size_t s = 0; seq->sweep_json && s < seq->n_sweeps; s++)
        json_decref(seq->sweep_json[s]);
    free(seq->sweep_json);
    free(seq->frame_json);
    free(seq->frame_dir);
    free(seq->hash);
    free(seq->sweep_label);
    free(seq->movies_unmade);
    free(seq->path);
    free(seq->root);
    for (size_t k = 0; k < seq->n_scenes; k++) {
        if (seq->scene_paths)
            free(seq->scene_paths[k]);
        if (seq->scene_dirs)
            free(seq->scene_dirs[k]);
    }
    free(seq->scene_paths);
    free(seq->scene_dirs);
    free(seq);
}

size_t batch_frame_scene(const thz_sequence *seq, size_t f)
{
    return seq->scene_list ? f % seq->frames : 0;
}

size_t thz_sequence_frame_count(const thz_sequence *seq)
{
    return seq ? seq->n_frames : 0;
}

size_t thz_sequence_sweep_count(const thz_sequence *seq)
{
    return seq ? seq->n_sweeps : 0;
}

size_t thz_sequence_frames_per_sweep(const thz_sequence *seq)
{
    return seq ? seq->frames : 0;
}

thz_status thz_sequence_frame(const thz_sequence *seq, size_t i, thz_frame_info *out)
{
    if (!out)
        return THZ_ERR_INPUT;
    memset(out, 0, sizeof *out);
    if (!seq || i >= seq->n_frames)
        return THZ_ERR_INPUT;
    *out = (thz_frame_info){.sweep = i / seq->frames,
                            .index = i % seq->frames,
                            .time_s = (double)(i % seq->frames) / seq->fps,
                            .dir = seq->frame_dir[i],
                            .hash = seq->hash[i]};
    return THZ_OK;
}

size_t thz_sequence_frame_json(const thz_sequence *seq, size_t i, char *buf, size_t size)
{
    if (!seq || i >= seq->n_frames || !seq->frame_json[i]) {
        if (buf && size > 0) /* an empty text, not what the buffer held */
            buf[0] = '\0';
        return 0;
    }
    size_t len = strlen(seq->frame_json[i]);
    if (buf && size > 0) {
        size_t n = len < size - 1 ? len : size - 1;
        memcpy(buf, seq->frame_json[i], n);
        buf[n] = '\0';
    }
    return len;
}

thz_status thz_sequence_frame_scene(const thz_sequence *seq, size_t i, thz_scene **out,
                                    thz_error *err)
{
    if (!out)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "thz_sequence_frame_scene: no place for the scene");
    *out = NULL;
    if (!seq || i >= seq->n_frames || !seq->frame_json[i])
        return thz_error_set(err, THZ_ERR_INPUT, "thz_sequence_frame_scene: no frame %zu", i);
    size_t k = batch_frame_scene(seq, i);
    return thz_scene_load_string_within(seq->frame_json[i], seq->scene_dirs[k], seq->scene_paths[k],
                                        seq->root, out, err);
}
