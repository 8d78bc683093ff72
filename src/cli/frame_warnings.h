/* A sequence's frame warnings, each printed once (thzmap batch, thzmap validate of a
 * sequence): a sequence's frames often warn alike, so the first frame with a message
 * prints it, naming the frame, and the later frames' same message is only counted, said
 * at the end ("the same in K later frames: ..."). */
#ifndef THZ_CLI_FRAME_WARNINGS_H
#define THZ_CLI_FRAME_WARNINGS_H

#include <stdbool.h>
#include <stddef.h>

/* Distinct messages remembered (more are printed each time). */
#define CLI_FRAME_WARNINGS_MAX 64

typedef struct cli_frame_warnings {
    char *seen[CLI_FRAME_WARNINGS_MAX];
    size_t repeats[CLI_FRAME_WARNINGS_MAX], n_seen;
} cli_frame_warnings;

/* True when message is new (the caller prints it), false when an earlier frame had it
 * (counted). Zero-initialise w before the first call. */
bool cli_frame_warnings_first(cli_frame_warnings *w, const char *message);

/* When say, prints "thzmap COMMAND: warning: the same in K later frame(s): ..." to stderr
 * for each message that later frames repeated; frees what w holds either way. */
void cli_frame_warnings_finish(cli_frame_warnings *w, const char *command, bool say);

#endif
