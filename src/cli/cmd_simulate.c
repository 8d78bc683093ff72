/* thzmap simulate SCENE.json -o OUTDIR: render every sensor (after the photon phase for the
 * integrators that need one). */
#include "cli.h"
#include "run_command.h"

int cmd_simulate(int argc, char **argv)
{
    return cli_run_command(argc, argv, false);
}
