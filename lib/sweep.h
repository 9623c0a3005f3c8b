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

/* The most values one sweep takes, bisection steps of a change, and
 * changes bisected between two neighbouring values. */
enum { MAX_VALUES = 200, MAX_REFINE = 40, SWEEP_CHANGES = 4 };

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
    double match;             /* attractors of neighbouring values are one within this share of
                                 the region in every dimension (0: SWEEP_MATCH) */
    const char *fractions;    /* each value's basin shares by tracked attractor as CSV, or NULL */
    const char *png;          /* the shares stacked against the parameter, or NULL */
    int width, height;        /* its size (0: 900 x 560) */
    const char *keep;         /* a directory: each value solved into NAME=VALUE.cmdb there
                                 (as `solve --db`), or NULL: in memory */
    const char *command;      /* the command line, for the kept files' provenance (NULL:
                                 "cellmap sweep") */
    bool no_seeds;            /* no attractor looked for from a neighbouring value's */
} sweep_args;

#define SWEEP_MATCH 0.05

/* An attractor of one value (in the window, not a sticking zone), with
 * the id tracking gives it across values (lib/sweep_track.h). */
typedef struct sweep_attractor {
    uint32_t id;       /* 1, 2, ... by first appearance; 0 until tracked */
    int kind;          /* enum cm_attractor_kind */
    uint32_t period;   /* 0: aperiodic */
    double centre[CM_MAX_DIM], lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int64_t anchor[CM_MAX_DIM]; /* the smallest cell of its footprint (a seed's start) */
    uint64_t basin_cells;
    bool seeded;       /* found by a true orbit from a neighbouring value's attractor, the
                          lattice showing no cell of its basin (basin_cells 0) */
} sweep_attractor;

/* What one value gave. */
typedef struct sweep_point {
    double value;
    uint32_t attractors, sticking, groups; /* attractors and sticking zones in the window */
    uint64_t attractor_cells, sticking_cells, sink_cells;
    /* by attractors: the region's cells, and where they go besides the
     * window's attractors and sticking zones */
    uint64_t cells, elsewhere_cells, diverged_cells, outside_cells, undecided_cells;
    sweep_attractor *att; /* the window's attractors (attractors entries), owned by the
                             result's pts[] (copies of a point share them) */
    double seconds;
} sweep_point;

/* Where the attractors change (by attractors: an attractor of one value
 * has no match at the other, or a matched one's basin collapses to less
 * than half its cells; by groups: their count changes): between lo and
 * hi. */
typedef struct sweep_change {
    sweep_point lo, hi;
    bool several; /* more than one attractor lost or gained within lo .. hi */
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
/* Where a tracked attractor begins or ends, between two solved values, or
 * its basin collapses to less than half its cells. */
enum { SWEEP_APPEARS, SWEEP_VANISHES, SWEEP_MERGES, SWEEP_COLLAPSES };
typedef struct sweep_event {
    int kind;
    uint32_t id, into; /* into: the attractor a merging one joins */
    double from, to;   /* the values around it */
} sweep_event;

typedef struct sweep_result {
    cm_lattice lat;
    cm_box box;
    double period[CM_MAX_DIM]; /* the model's periodic coordinates (0: not periodic) */
    sweep_point *pts;
    int n;
    sweep_change *changes;
    int n_changes;
    sweep_event *events; /* by attractors, after sweep_compute: by value */
    int n_events;
    uint32_t tracked;    /* ids given */
    double failed_value; /* the value whose solve failed (the status says how) */
} sweep_result;

/* Checks the request (values increasing, the window), the model, the
 * parameter, the lattice and every value, and starts r (zeroed) with the
 * lattice and box; r is freed by sweep_result_free whatever happens next. */
cm_status sweep_check_setup(const sweep_args *a, sweep_result *r, char *msg, size_t msg_size);

/* Solves every value of the setup sweep_check_setup made in r (then
 * bisects each change a->refine times, finding up to SWEEP_CHANGES
 * between two neighbouring values one after the other), progress in
 * values through h,
 * stopped by h (CM_ECANCELED, r->n values solved). */
cm_status sweep_compute(const sweep_args *a, const work_hooks *h, const sweep_report *rep,
                        sweep_result *r, char *msg, size_t msg_size);

void sweep_result_free(sweep_result *r);

/* Solves the box at a->name = value (into a file of a->keep, when given)
 * and counts it into *pt. */
cm_status sweep_solve_at(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                         double value, sweep_point *pt, char *msg, size_t msg_size);

/* The largest distance between the centres of x and y along a dimension,
 * as a share of the region's extent there (around a periodic coordinate's
 * circle, the shorter way). */
double sweep_distance(const sweep_result *r, const sweep_attractor *x, const sweep_attractor *y);

/* Matches q's attractors to p's (neighbouring values): pairs within
 * a->match of each other (sweep_distance), taken nearest first (ties by
 * index), each attractor in at most one; pair[j]: the index in p of q's
 * j-th attractor's match, -1 for none; *matched: the pairs. */
cm_status sweep_match(const sweep_args *a, const sweep_result *r, const sweep_point *p,
                      const sweep_point *q, int *pair, uint32_t *matched);

/* The n points as CSV at a->csv. */
bool sweep_write_csv(const sweep_args *a, const sweep_point *pts, int n, char *msg,
                     size_t msg_size);

#endif
