/* Band selection's progress (thz_bands_select): its renders' "render" reports become one
 * stage "bands", in which thz_progress's `channel` is the render (r of `n_channels`
 * renders: the nominal one, then the coarse ones of the nuisances; n_channels is 0 while
 * the nominal one runs if nuisances are asked for: the classes it finds tell which of
 * them change anything) and done/total count the candidate channels of that render. A
 * caller sees the whole selection, not the rows of one channel of one render at a time. */
#ifndef THZ_ANALYSIS_BANDS_PROGRESS_H
#define THZ_ANALYSIS_BANDS_PROGRESS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "thzmap/thzmap.h"

typedef struct bands_progress {
    thz_context *ctx;
    thz_progress_fn fn; /* the caller's, restored by bands_progress_end */
    void *user;
    size_t render, renders;
    size_t last_channel;
    uint64_t last_done;
    bool started;
} bands_progress;

/* Puts the wrapper on ctx (which may be NULL, or have no callback: then nothing),
 * expecting `renders` renders (0: not known until bands_progress_renders). */
void bands_progress_begin(bands_progress *b, thz_context *ctx, size_t renders);
/* The number of renders, once known exactly. */
void bands_progress_renders(bands_progress *b, size_t renders);
/* Gives ctx its callback back. */
void bands_progress_end(bands_progress *b);

#endif
