/* thzmap render SCENE.json --photon-map FILE -o OUTDIR: re-render from a saved map. */
#include "cli.h"
#include "run_command.h"

int cmd_render(int argc, char **argv)
{
    return cli_run_command(argc, argv, true);
}
