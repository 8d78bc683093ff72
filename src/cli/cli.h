/* The command-line interface: the only code that prints to the user or exits.
 * Each subcommand lives in its own file cmd_<name>.c and is listed in main.c. */
#ifndef THZ_CLI_CLI_H
#define THZ_CLI_CLI_H

#include <stdbool.h>
#include <stdint.h>

#include "thzmap/thzmap.h"

/* Exit statuses (scene-format.md): 0 success, 2 bad usage or input, 1 anything else. */
enum { CLI_EXIT_OK = 0, CLI_EXIT_FAILURE = 1, CLI_EXIT_USAGE = 2 };

int cmd_validate(int argc, char **argv);
int cmd_simulate(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_atmosphere(int argc, char **argv);
int cmd_batch(int argc, char **argv);
int cmd_materials(int argc, char **argv);
int cmd_classify(int argc, char **argv);
int cmd_bands(int argc, char **argv);
int cmd_serve(int argc, char **argv);

/* Prints "thzmap: <message>" to stderr and returns the exit status for err. */
int cli_fail(const thz_error *err);

/* Prints "thzmap <command>: <printf message>" and a hint to use --help; returns 2. */
int cli_usage_error(const char *command, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Monotonic wall-clock time in s (for progress rates and the closing line). */
double cli_now_s(void);

/* True if arg is -h or --help. */
bool cli_is_help(const char *arg);

/* The option argv[*i] when it takes a value: -1 after setting *value to argv[*i + 1]
 * and moving *i past it, when argv[*i] is one of with_value (NULL-terminated);
 * otherwise the usage exit status after saying why (an unknown option, an unexpected
 * argument, an option without its value, or one given twice). */
int cli_option_value(const char *command, int argc, char **argv, int *i,
                     const char *const *with_value, char **value);

/* -1 when the option argv[i] (one that takes a value) is not among argv[1 .. i - 1],
 * else the usage exit status after saying it was given twice (the last one won, silently:
 * `-o a -o b` wrote to b). */
int cli_refuse_repeat(const char *command, char **argv, int i);

/* -1 unless OUTDIR exists and is not a directory; then the usage exit status after
 * saying so: for commands that would otherwise find out only after minutes of work
 * (bands' renders, batch's check of every frame). */
int cli_refuse_file_outdir(const char *command, const char *outdir);

/* True if an option's value looks like an option itself ("-o -q": a forgotten value):
 * anything from "-" and a letter or "--" on; "-" alone and negative numbers are values. */
bool cli_looks_like_option(const char *value);

/* True if text[0..len) is a decimal number as JSON writes one, a leading '+' allowed:
 * no blanks, no hexadecimal, no "inf" or "nan" (what strtod would also take). */
bool cli_decimal_text(const char *text, size_t len);

/* Parse whole numbers and reals from option values; false (after printing a usage
 * error naming `option`) when the text is not one, or is out of [min, max]. Whole
 * numbers may be written with a fraction or an exponent when their value is whole
 * (1e6, 2.5e3). */
bool cli_parse_u64(const char *command, const char *option, const char *text, uint64_t min,
                   uint64_t max, uint64_t *out);
bool cli_parse_double(const char *command, const char *option, const char *text, double min,
                      double max, double *out);
/* A number in (0, max]: what must be above 0 says so (not "from 0", then refused at 0). */
bool cli_parse_positive(const char *command, const char *option, const char *text, double max,
                        double *out);

/* Mends or refuses the process's start (cli_env.c): closed standard streams reopened on
 * /dev/null, SIGXFSZ ignored, a stack limit or OMP_STACKSIZE below what the threads need
 * refused with a message. The exit status to end with, or -1 to go on. */
int cli_environment_check(void);
/* Starts the threads before any work under an address-space limit (ulimit -v), so that
 * libgomp never meets a thread it cannot start later (it ends the process); fewer when
 * not all fit, with a warning. Returns the count to run with: `threads` (0: OpenMP's
 * default), or the lowered count. Without a limit it does nothing. */
uint64_t cli_threads_prepare(const char *command, uint64_t threads);
/* cli_threads_prepare, then warns on stderr when `threads` (--threads; 0, the default,
 * takes what OpenMP finds) exceeds the CPUs the process may run on (its affinity mask:
 * mpirun's and srun's binding), where the threads would share a core unseen. Returns the
 * count to run with. */
uint64_t cli_threads_check(const char *command, uint64_t threads);
/* rc, or CLI_EXIT_FAILURE (with a message) when the standard output could not be written
 * (a full disk, a closed descriptor): a command whose product is what it prints must not
 * end with 0 then. A reader that left a pipe is no failure. */
int cli_stdout_finish(int rc);

#endif
