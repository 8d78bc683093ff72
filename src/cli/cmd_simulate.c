/* thzmap simulate: not implemented yet. */
#include <stdio.h>

#include "cli/cli.h"

int cmd_simulate(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "thzmap simulate: not implemented yet\n");
    return CLI_EXIT_FAILURE;
}
