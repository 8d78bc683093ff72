/* thzmap render: not implemented yet. */
#include <stdio.h>

#include "cli/cli.h"

int cmd_render(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "thzmap render: not implemented yet\n");
    return CLI_EXIT_FAILURE;
}
