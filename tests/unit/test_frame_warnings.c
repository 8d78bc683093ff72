/* A sequence's frame warnings (src/cli/frame_warnings.c, the CLI's own; compiled into this
 * test beside the library): each message printed once, the later frames' same counted
 * once a frame, the alike (only their free-standing numbers differ) counted apart, and
 * the closing lines as frame_warnings.h gives them. test_validate.sh and test_batch
 * reach it through real sequences; this checks the rules case by case. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/frame_warnings.h"

/* What cli_frame_warnings_finish prints to stderr, read back from a temporary file. */
static char *finish_output(cli_frame_warnings *w, const char *kept)
{
    FILE *tmp = tmpfile();
    assert_non_null(tmp);
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    assert_true(saved >= 0);
    assert_true(dup2(fileno(tmp), STDERR_FILENO) >= 0);
    cli_frame_warnings_finish(w, "batch", kept, true);
    fflush(stderr);
    assert_true(dup2(saved, STDERR_FILENO) >= 0);
    close(saved);
    long n = ftell(tmp);
    assert_true(n >= 0);
    char *text = calloc((size_t)n + 1, 1);
    assert_non_null(text);
    rewind(tmp);
    assert_int_equal(fread(text, 1, (size_t)n, tmp), (size_t)n);
    fclose(tmp);
    return text;
}

/* The same message in frames 0, 1, 1, 2: printed once, counted in 2 later frames (frame
 * 1's second copy is the same frame). */
static void test_same_counted_once_a_frame(void **state)
{
    (void)state;
    cli_frame_warnings w = {0};
    assert_true(cli_frame_warnings_first(&w, 0, "sensor 'cam' looks at nothing"));
    assert_false(cli_frame_warnings_first(&w, 0, "sensor 'cam' looks at nothing"));
    assert_false(cli_frame_warnings_first(&w, 1, "sensor 'cam' looks at nothing"));
    assert_false(cli_frame_warnings_first(&w, 1, "sensor 'cam' looks at nothing"));
    assert_false(cli_frame_warnings_first(&w, 2, "sensor 'cam' looks at nothing"));
    char *text = finish_output(&w, NULL);
    assert_string_equal(
        text, "thzmap batch: warning: the same in 2 later frames: sensor 'cam' looks at nothing\n");
    free(text);
}

/* Within one frame, messages that differ only in their numbers are each printed; a later
 * frame's alike message is counted with the first, once a frame, in its own line. */
static void test_alike_within_and_across_frames(void **state)
{
    (void)state;
    cli_frame_warnings w = {0};
    assert_true(cli_frame_warnings_first(&w, 0, "noise 0.12 K after 3 passes"));
    assert_true(cli_frame_warnings_first(&w, 0, "noise 0.25 K after 3 passes"));
    assert_false(cli_frame_warnings_first(&w, 1, "noise 0.31 K after 4 passes"));
    assert_false(cli_frame_warnings_first(&w, 1, "noise 1.5e-2 K after 40 passes"));
    assert_false(cli_frame_warnings_first(&w, 2, "noise 0.12 K after 3 passes"));
    char *text = finish_output(&w, "each frame's summary.json has its own");
    assert_string_equal(text, "thzmap batch: warning: the same in 1 later frame: noise 0.12 K "
                              "after 3 passes\n"
                              "thzmap batch: warning: the same but for its numbers in 1 later "
                              "frame (each frame's summary.json has its own): noise 0.12 K after "
                              "3 passes\n");
    free(text);
}

/* A name's digits and a JSON path's index are no numbers: cam1/cam2 and
 * sensors[0]/sensors[1] in later frames are new messages, printed; an exponent is part
 * of its number. */
static void test_names_and_indices_are_not_numbers(void **state)
{
    (void)state;
    cli_frame_warnings w = {0};
    assert_true(cli_frame_warnings_first(&w, 0, "sensor cam1 at 3 m is outside"));
    assert_true(cli_frame_warnings_first(&w, 1, "sensor cam2 at 3 m is outside"));
    assert_false(cli_frame_warnings_first(&w, 2, "sensor cam2 at 4 m is outside"));
    assert_true(cli_frame_warnings_first(&w, 0, "sensors[0]: 2 channels"));
    assert_true(cli_frame_warnings_first(&w, 1, "sensors[1]: 2 channels"));
    assert_false(cli_frame_warnings_first(&w, 2, "sensors[1]: 7 channels"));
    assert_true(cli_frame_warnings_first(&w, 0, "step 1e-3 s"));
    assert_false(cli_frame_warnings_first(&w, 1, "step 2.5E+4 s"));
    assert_true(cli_frame_warnings_first(&w, 1, "step 2.5E s"));
    cli_frame_warnings_finish(&w, "batch", NULL, false);
}

/* A warning of no frame is folded only when the same to the letter, and does not make a
 * frame count twice: frame 1, the batch's own, frame 1 again is one later frame and one
 * repeat of no frame. */
static void test_no_frame(void **state)
{
    (void)state;
    cli_frame_warnings w = {0};
    assert_true(cli_frame_warnings_first(&w, CLI_NO_FRAME, "movie 3 s long"));
    assert_true(cli_frame_warnings_first(&w, CLI_NO_FRAME, "movie 4 s long"));
    assert_false(cli_frame_warnings_first(&w, CLI_NO_FRAME, "movie 4 s long"));
    cli_frame_warnings_finish(&w, "batch", NULL, false);

    assert_true(cli_frame_warnings_first(&w, 0, "disk nearly full"));
    assert_false(cli_frame_warnings_first(&w, 1, "disk nearly full"));
    assert_false(cli_frame_warnings_first(&w, CLI_NO_FRAME, "disk nearly full"));
    assert_false(cli_frame_warnings_first(&w, 1, "disk nearly full"));
    char *text = finish_output(&w, NULL);
    assert_string_equal(text,
                        "thzmap batch: warning: the same in 2 later frames: disk nearly full\n");
    free(text);
}

/* Past CLI_FRAME_WARNINGS_MAX distinct messages, a new one is printed every time (none
 * is lost uncounted). */
static void test_past_the_limit_printed_each_time(void **state)
{
    (void)state;
    cli_frame_warnings w = {0};
    char message[64];
    for (int i = 0; i < CLI_FRAME_WARNINGS_MAX; i++) {
        snprintf(message, sizeof message, "warning %c%c", 'a' + i / 26, 'a' + i % 26);
        assert_true(cli_frame_warnings_first(&w, 0, message));
    }
    assert_true(cli_frame_warnings_first(&w, 0, "one more"));
    assert_true(cli_frame_warnings_first(&w, 1, "one more"));
    assert_false(cli_frame_warnings_first(&w, 1, "warning aa"));
    cli_frame_warnings_finish(&w, "batch", NULL, false);
    assert_int_equal(w.n_seen, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_counted_once_a_frame),
        cmocka_unit_test(test_alike_within_and_across_frames),
        cmocka_unit_test(test_names_and_indices_are_not_numbers),
        cmocka_unit_test(test_no_frame),
        cmocka_unit_test(test_past_the_limit_printed_each_time),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
