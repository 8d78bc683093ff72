/* A sequence's frame warnings, each printed once (thzmap batch, thzmap validate of a
 * sequence): a sequence's frames often warn alike, so the first frame with a message
 * prints it, naming the frame, and the later frames' same message is only counted, said
 * at the end ("the same in K later frames: ..."). A message that differs from an earlier
 * frame's only in its free-standing numbers (a time limit's noise reached, a camera's
 * distance as it moves; not the digit of a name such as cam1, nor an index such as
 * sensors[1]) is counted with it too
 * ("... the same but for its numbers: ..."; a batch's frames' summary.json keep their
 * own). Within one frame every message that is not the same to the letter is printed
 * (its channels' alike warnings among them). */
#ifndef THZ_CLI_FRAME_WARNINGS_H
#define THZ_CLI_FRAME_WARNINGS_H

#include <stdbool.h>
#include <stddef.h>

/* Distinct messages remembered (more are printed each time). */
#define CLI_FRAME_WARNINGS_MAX 64
/* The frame of a warning that belongs to none (a batch's own): folded only when the
 * same to the letter. */
#define CLI_NO_FRAME ((size_t)-1)

typedef struct cli_frame_warnings {
    char *seen[CLI_FRAME_WARNINGS_MAX];
    char *shape[CLI_FRAME_WARNINGS_MAX]; /* the message with each number as '#' */
    size_t first[CLI_FRAME_WARNINGS_MAX], last[CLI_FRAME_WARNINGS_MAX]; /* frames */
    size_t repeats[CLI_FRAME_WARNINGS_MAX]; /* later frames with the same message */
    size_t alike[CLI_FRAME_WARNINGS_MAX];   /* later frames with one of its shape only */
    size_t n_seen;
} cli_frame_warnings;

/* True when message is new (the caller prints it), false when an earlier frame had it, or
 * one that differs only in its numbers (counted). Zero-initialise w before the first call;
 * frames come in order (CLI_NO_FRAME for a warning of no frame). */
bool cli_frame_warnings_first(cli_frame_warnings *w, size_t frame, const char *message);

/* When say, prints "thzmap COMMAND: warning: the same in K later frame(s): ..." (and
 * "... the same but for its numbers in K later frame(s) (KEPT): ...", KEPT where the
 * frames' own are, or NULL) to stderr for each message that later frames repeated; frees
 * what w holds either way. */
void cli_frame_warnings_finish(cli_frame_warnings *w, const char *command, const char *kept,
                               bool say);

#endif
