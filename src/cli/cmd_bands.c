/* thzmap bands: placeholder until the band selection lands (see below). */
#include "cli.h"

int cmd_bands(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    return CLI_EXIT_FAILURE;
}
