/* cellmap-mpi: `cellmap solve` on MPI ranks, which `cellmap solve` runs
 * under mpirun (lib/ranks.h); only this program links MPI. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/ranks.h"
#include "src/args.h"
#include "src/commands.h"

int main(int argc, char **argv)
{
    char msg[512];
    solve_ranks *rk;
    int rc = ranks_open(&argc, &argv, NULL, &rk, msg, sizeof msg) == CM_OK ? EXIT_OK : EXIT_USAGE;
    if (rk && rk->rank != 0 && !getenv("CELLMAP_RANKS_STDERR") && /* rank 0 speaks for all */
        (!freopen("/dev/null", "w", stderr) || !freopen("/dev/null", "w", stdout)))
        rc = EXIT_FAIL;
    if (rc != EXIT_OK)
        fprintf(stderr, "cellmap solve: %s\n", msg);
    else if (argc < 2 || strcmp(argv[1], "solve") != 0)
        fprintf(stderr, "cellmap-mpi runs `cellmap solve` only\n"), rc = EXIT_USAGE;
    else
        rc = cmd_solve_on(argc - 1, argv + 1, rk);
    ranks_close(rk, rc == EXIT_OK);
    return rc;
}
