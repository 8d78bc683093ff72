/* thzmap atmosphere: not implemented yet. */
#include <stdio.h>

#include "cli/cli.h"

int cmd_atmosphere(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "thzmap atmosphere: not implemented yet\n");
    return CLI_EXIT_FAILURE;
}
