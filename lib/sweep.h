/* lib/sweep.h - a model solved at each value of one parameter (one region
 * each, with the system's attractors found by their true orbits, or cell
 * mapping's groups) and the attractors and sticking zones counted in a
 * window of state space; the points written as CSV. Nothing is printed:
 * calls return the problem in msg. */
#ifndef CM_LIB_SWEEP_H
#define CM_LIB_SWEEP_H

#include <stdbool.h>

#include "lib/attractor_report.h"
#include "lib/outfile.h"
#include "lib/project.h"
#include "lib/work.h"

/* The most values one sweep takes, and bisection steps of a change. */
enum { MAX_VALUES = 200, MAX_REFINE = 40 };

/* The parameter's values, the lattice, the window and the check (the
 * command's options). */
typedef struct sweep_args {
    model_spec mo;
    lattice_spec lat;
    char name[32];
    double values[MAX_VALUES];
    int n_values, max_steps, threads, refine, n_near;
    double near_lo[CM_MAX_DIM], near_hi[CM_MAX_DIM];
    const char *csv;
    bool json, quiet;
    int by;                   /* --by: count attractors (default) or groups */
    cm_attractor_options att; /* --attractor-steps, --attractor-tol */
} sweep_args;

/* What one value gave. */
typedef struct sweep_point {
    double value;
    uint32_t attractors, sticking, groups; /* attractors and sticking zones in the window */
    uint64_t attractor_cells, sticking_cells, sink_cells;
    double seconds;
} sweep_point;

/* Where the count of attractors changes: between lo and hi. */
typedef struct sweep_change {
    sweep_point lo, hi;
    bool several; /* by more than one: bisection followed one of the changes */
} sweep_change;

/* What the caller hears as the sweep goes (each may be NULL): a point
 * solved, a change located (after its bisection, only with a->refine). */
typedef struct sweep_report {
    void (*point)(void *user, const sweep_args *a, const sweep_point *pt);
    void (*change)(void *user, const sweep_args *a, const sweep_change *ch);
    void *user;
} sweep_report;

/* The sweep: its lattice and box, the points solved (the values' and the
 * bisections', by value) and the changes. */
typedef struct sweep_result {
    cm_lattice lat;
    cm_box box;
    sweep_point *pts;
    int n;
    sweep_change *changes;
    int n_changes;
    double failed_value; /* the value whose solve failed (the status says how) */
} sweep_result;

/* Checks the request (values increasing, the window), the model, the
 * parameter, the lattice and every value, and starts r (zeroed) with the
 * lattice and box; r is freed by sweep_result_free whatever happens next. */
cm_status sweep_check_setup(const sweep_args *a, sweep_result *r, char *msg, size_t msg_size);

/* Solves every value of the setup sweep_check_setup made in r (then
 * bisects each change a->refine times), progress in values through h,
 * stopped by h (CM_ECANCELED, r->n values solved). */
cm_status sweep_compute(const sweep_args *a, const work_hooks *h, const sweep_report *rep,
                        sweep_result *r, char *msg, size_t msg_size);

void sweep_result_free(sweep_result *r);

/* Solves the box at a->name = value and counts it into *pt. */
cm_status sweep_solve_at(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                         double value, sweep_point *pt, char *msg, size_t msg_size);

/* The n points as CSV at a->csv. */
bool sweep_write_csv(const sweep_args *a, const sweep_point *pts, int n, char *msg,
                     size_t msg_size);

#endif
