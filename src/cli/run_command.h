/* The shared body of `thzmap simulate` and `thzmap render`: option parsing, scene
 * loading, overrides, the run with progress and Ctrl-C, and the closing report. */
#ifndef THZ_CLI_RUN_COMMAND_H
#define THZ_CLI_RUN_COMMAND_H

#include <stdbool.h>

/* Exit status of a run stopped by SIGINT/SIGTERM (128 + SIGINT, as shells report). */
#define CLI_EXIT_INTERRUPTED 130

/* argv[0] is the command name; `render` selects the render command's options. */
int cli_run_command(int argc, char **argv, bool render);

#endif
