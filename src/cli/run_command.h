/* The shared body of `thzmap simulate` and `thzmap render`: option parsing, scene
 * loading, overrides, the run with progress and Ctrl-C, and the closing report. */
#ifndef THZ_CLI_RUN_COMMAND_H
#define THZ_CLI_RUN_COMMAND_H

#include <stdbool.h>

#include "thzmap/thzmap.h"

/* Exit status of a run stopped by SIGINT/SIGTERM (128 + SIGINT, as shells report). */
#define CLI_EXIT_INTERRUPTED 130

/* The exit handler's slot (installing the handler on the first call): an output
 * directory open in this process, or NULL. libgomp calls exit() when it cannot allocate
 * or start a thread; the handler then destroys what the slot holds, removing its
 * staging directory and lock, and says so. simulate and render keep their OUTDIR there,
 * batch each frame's (thz_batch_options.open_output). */
thz_output **cli_exit_guard(void);

/* argv[0] is the command name; `render` selects the render command's options. */
int cli_run_command(int argc, char **argv, bool render);

#endif
