/* A sequence's frame warnings, each printed once (frame_warnings.h). */
#include "frame_warnings.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* True for a character of an identifier-like word (cam1, ch2, x86_64, h2o). */
static bool frame_warning_word_char(char c)
{
    return isalnum((unsigned char)c) || c == '_';
}

/* True when p starts an index, digits alone between '[' and ']' (sensors[1], objects[12]). */
static bool frame_warning_index(const char *message, const char *p)
{
    const char *q = p;
    while (isdigit((unsigned char)*q))
        q++;
    return q > p && *q == ']' && p > message && p[-1] == '[';
}

/* The message with each free-standing number (a run of digits and points holding a digit,
 * with an exponent, not following a letter, digit or '_') written '#': "at 0.123 K after 3
 * passes" -> "at # K after # passes", while the digits of a name stay: "cam1" and "cam2"
 * differ; so do a JSON path's indices, "sensors[0]" and "sensors[1]" (they name different
 * things: one's warning counted with the other's was never printed). python/thzmap/
 * sequence.py's _NUMBER is the same rule. */
static char *frame_warning_shape(const char *message)
{
    char *out = malloc(strlen(message) + 1), *o = out;
    if (!out)
        return NULL;
    for (const char *p = message; *p;) {
        if (frame_warning_index(message, p)) {
            while (*p != ']')
                *o++ = *p++;
            continue;
        }
        const char *q = p;
        while (isdigit((unsigned char)*q) || (*q == '.' && isdigit((unsigned char)q[1])))
            q++;
        if (q > p && isdigit((unsigned char)*p) &&
            (p == message || !frame_warning_word_char(p[-1]))) {
            if ((*q == 'e' || *q == 'E') &&
                (isdigit((unsigned char)q[1]) ||
                 ((q[1] == '-' || q[1] == '+') && isdigit((unsigned char)q[2])))) {
                q += 2;
                while (isdigit((unsigned char)*q))
                    q++;
            }
            *o++ = '#';
            p = q;
        } else {
            *o++ = *p++;
        }
    }
    *o = '\0';
    return out;
}

/* Counts frame in entry i's frames: once a frame, in its same or alike count. A warning of
 * no frame is counted each time and leaves the last frame as it was, so that a frame's
 * message, the batch's own, and the frame's again count that frame once. */
static void frame_warning_count(cli_frame_warnings *w, size_t i, size_t frame, bool same)
{
    if (frame != CLI_NO_FRAME) {
        if (w->last[i] == frame)
            return;
        w->last[i] = frame;
    }
    if (same)
        w->repeats[i]++;
    else
        w->alike[i]++;
}

bool cli_frame_warnings_first(cli_frame_warnings *w, size_t frame, const char *message)
{
    for (size_t i = 0; i < w->n_seen; i++)
        if (!strcmp(w->seen[i], message)) {
            frame_warning_count(w, i, frame, true);
            return false;
        }
    char *shape = frame_warning_shape(message);
    if (shape && frame != CLI_NO_FRAME)
        for (size_t i = 0; i < w->n_seen; i++)
            if (w->first[i] != CLI_NO_FRAME && w->first[i] < frame && w->shape[i] &&
                !strcmp(w->shape[i], shape)) {
                frame_warning_count(w, i, frame, false);
                free(shape);
                return false;
            }
    if (w->n_seen < CLI_FRAME_WARNINGS_MAX && (w->seen[w->n_seen] = strdup(message))) {
        size_t i = w->n_seen++;
        w->shape[i] = shape;
        w->first[i] = w->last[i] = frame;
        w->repeats[i] = w->alike[i] = 0;
    } else {
        free(shape);
    }
    return true;
}

void cli_frame_warnings_finish(cli_frame_warnings *w, const char *command, const char *kept,
                               bool say)
{
    for (size_t i = 0; i < w->n_seen; i++) {
        if (say && w->repeats[i])
            fprintf(stderr, "thzmap %s: warning: the same in %zu later frame%s: %s\n", command,
                    w->repeats[i], w->repeats[i] == 1 ? "" : "s", w->seen[i]);
        if (say && w->alike[i])
            fprintf(
                stderr,
                "thzmap %s: warning: the same but for its numbers in %zu later frame%s%s%s%s: %s\n",
                command, w->alike[i], w->alike[i] == 1 ? "" : "s", kept ? " (" : "",
                kept ? kept : "", kept ? ")" : "", w->seen[i]);
        free(w->seen[i]);
        free(w->shape[i]);
    }
    w->n_seen = 0;
}
