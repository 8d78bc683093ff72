/* Shared by the libFuzzer harnesses of tests/fuzz/ (README.md there): the two entry
 * points libFuzzer calls, and the temporary files through which a harness hands its
 * input to a reader that only takes a path.
 *
 * Each harness fuzz_<name>.c is linked either with libFuzzer (the fuzz build, clang
 * -fsanitize=fuzzer) or with replay_main.c (every build: runs the seed corpus and the
 * regression inputs once, so `make test` exercises them without clang).
 */
#ifndef THZ_TESTS_FUZZ_H
#define THZ_TESTS_FUZZ_H

#include <stddef.h>
#include <stdint.h>

/* libFuzzer's entry points, defined by each harness. Return 0. */
int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes data[0..size) to `name` (e.g. "input.obj") in this process's temporary
 * directory (made on first use under $TMPDIR or /tmp, removed at exit) and returns its
 * path (static storage, valid until the next call). Aborts if the file cannot be
 * written: the harness cannot go on. */
const char *fuzz_temp_file(const char *name, const uint8_t *data, size_t size);

/* The repository's tests/fuzz/ directory (compiled in), for the harnesses' fixtures. */
#define FUZZ_DIR THZ_SOURCE_DIR "/tests/fuzz"

/* Prints a reader's message on stderr when the environment sets FUZZ_VERBOSE (for
 * triage with fuzz_replay_<name>; fuzzing itself stays quiet). */
void fuzz_report(const char *message);

/* Points the library's data directory at tests/fuzz/data/ (tiny line catalogues and
 * tables, so that an input naming the `lines` atmosphere costs milliseconds). */
void fuzz_use_fixture_data(void);

#endif
