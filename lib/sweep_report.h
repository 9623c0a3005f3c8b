/* lib/sweep_report.h - what a sweep (lib/sweep.h) found, written: a line
 * per value solved and per change bisected, the tracked attractors' basin
 * shares per value and where each begins and ends (text, JSON, CSV), and
 * the shares stacked against the parameter as a figure (as Attractors.jl's
 * basins curves). Write calls return the problem in msg. */
#ifndef CM_LIB_SWEEP_REPORT_H
#define CM_LIB_SWEEP_REPORT_H

#include <stdio.h>

#include "lib/sweep.h"

/* One value solved, one change bisected: a line each. */
void sweep_print_point(FILE *f, const char *name, const sweep_point *pt);
void sweep_print_change(FILE *f, const char *name, const sweep_change *ch);

/* The tracked attractors: a line per value with each one's share of the
 * region's cells (and the sticking, elsewhere, diverged, outside and
 * undecided shares), then a line per event. Nothing without tracking. */
void sweep_print_tracked(FILE *f, const sweep_args *a, const sweep_result *r);

/* The sweep as the JSON document of `cellmap sweep --json`. */
void sweep_json(FILE *f, const sweep_args *a, const sweep_result *r);

/* The shares at a->fractions as rows NAME,basin,kind,period,cells,share,
 * centre_0,centre_1,...: basin a tracked attractor's id, or sticking
 * (zones in the window), elsewhere (attractors and zones outside it),
 * diverged, outside (left the region, not back), undecided (kind, period
 * and centre then empty);
 * the figure at a->png. Either may be NULL (sweep_check_setup refuses
 * them with --by groups). */
cm_status sweep_write_tracked(const sweep_args *a, const sweep_result *r, char *msg,
                              size_t msg_size);

#endif
