/* src/attractor_opts.h - the options that set the true-orbit check of a
 * solve's attractors (lib/attractor_report.h) and what figures and labels
 * show, as every command that takes them parses them. */
#ifndef CM_SRC_ATTRACTOR_OPTS_H
#define CM_SRC_ATTRACTOR_OPTS_H

#include "lib/attractor_report.h"
#include "src/args.h"

#define ATTRACTOR_OPTIONS_HELP                                                                     \
    "  --attractor-steps T,R[,MAX]  the true-orbit check of each cell group: T steps of\n"         \
    "                      transient, a record of R steps (doubled while undecided), at most\n"    \
    "                      MAX steps a group (default 16,500,1048576; MAX 8192 for ODE flows)\n"         \
    "  --attractor-tol TOL[,MATCH]  recurrence within TOL cell widths is periodic; cycles\n"      \
    "                      within MATCH cell widths are one attractor (default 1e-4,1e-2)\n"  \
    "  --outside-steps N   follow an orbit that leaves the computed cells N steps on the\n"      \
    "                      true map: back in, it goes where the cell it lands in goes;\n"        \
    "                      beyond the world, it diverges; else it is outside (default 100;\n"   \
    "                      0: not followed, every such cell outside)\n"

#define BY_OPTION_HELP                                                                             \
    "  --by attractors|groups  figures and labels by the system's attractors (default;\n"      \
    "                      their footprints marked) or by cell mapping's groups (the\n"          \
    "                      thesis' figures are drawn by groups)\n"

/* Handles --attractor-steps, --attractor-tol and --outside-steps; true if the current option
 * was one of them (a bad value is reported and *error set). */
bool attractor_options_take(cli *c, cm_attractor_options *o, int *error);

/* Handles --by groups|attractors (BY_*); true if the current option was it. */
bool by_option_take(cli *c, int *by, int *error);

#endif
