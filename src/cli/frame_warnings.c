/* A sequence's frame warnings, each printed once (frame_warnings.h). */
#include "frame_warnings.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool cli_frame_warnings_first(cli_frame_warnings *w, const char *message)
{
    for (size_t i = 0; i < w->n_seen; i++)
        if (!strcmp(w->seen[i], message)) {
            w->repeats[i]++;
            return false;
        }
    if (w->n_seen < CLI_FRAME_WARNINGS_MAX && (w->seen[w->n_seen] = strdup(message)))
        w->repeats[w->n_seen++] = 0;
    return true;
}

void cli_frame_warnings_finish(cli_frame_warnings *w, const char *command, bool say)
{
    for (size_t i = 0; i < w->n_seen; i++) {
        if (say && w->repeats[i])
            fprintf(stderr, "thzmap %s: warning: the same in %zu later frame%s: %s\n", command,
                    w->repeats[i], w->repeats[i] == 1 ? "" : "s", w->seen[i]);
        free(w->seen[i]);
    }
    w->n_seen = 0;
}
