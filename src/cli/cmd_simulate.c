/* thzmap simulate SCENE.json -o OUTDIR: fire photons and render every sensor. */
#include "cli.h"
#include "run_command.h"

int cmd_simulate(int argc, char **argv)
{
    return cli_run_command(argc, argv, false);
}
