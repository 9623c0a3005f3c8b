/* lib/api_ranks.h - cm_ranks (cellmap/cellmap.h) for the library's solves:
 * the MPI ranks of lib/ranks.h, from libcellmap-mpi.so.0, which libcellmap
 * loads under mpirun only. */
#ifndef CM_LIB_API_RANKS_H
#define CM_LIB_API_RANKS_H

#ifndef CELLMAP_EXPERIMENTAL
#define CELLMAP_EXPERIMENTAL
#endif
#include "cellmap/cellmap.h"
#include "lib/ranks.h"

/* The ranks a solve shares its regions among (solve_request.ranks), or
 * NULL: one rank (r NULL, or opened outside mpirun). */
solve_ranks *api_ranks_solve(cm_ranks *r);

#endif
