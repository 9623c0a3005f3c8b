/* lib/bifurcation.h - brute-force bifurcation diagrams of the friction
 * oscillator (thesis 2.4, Figs. 2.13-2.16) over
 * models/friction_oscillator.h: for each value of the swept parameter,
 * runs from random starts followed past a transient, their sticking
 * displacements, Poincare sections and asymmetry recorded; written as CSV
 * (points, runs) and as the three-panel diagram. Nothing is printed:
 * calls return a status with the problem in msg (CM_EINVAL: the
 * request's). */
#ifndef CM_LIB_BIFURCATION_H
#define CM_LIB_BIFURCATION_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/work.h"
#include "lib/param_grid.h"
#include "models/friction_oscillator.h"

/* The sticking displacements a run keeps (its last ones). */
enum { LAST_STOPS = 10 };

/* The sweep, the runs and the outputs (the command's options). */
typedef struct bif_args {
    model_spec mo;
    param_axis sweep;
    int has_sweep, runs, transient, record, threads;
    long long seed;
    const char *runs_csv;
    chart_outputs out;
    /* a map model's (lib/map_bifurcation.h): the coordinate recorded (NULL:
     * the first) and branch tables drawn over the points */
    const char *of;
    const char *branches[8];
    int n_branches;
    bool has_size; /* the size was given (a map's diagram is otherwise 900x600) */
} bif_args;

/* What one run recorded. */
typedef struct run_result {
    double x0, v0, t0, psi;
    double stops[LAST_STOPS]; /* a ring: the last sticking displacements */
    int sticks;               /* in all of the recorded periods */
    bool ok, valid;           /* valid: the parameter value admits the model */
} run_result;

/* Every run of the sweep. */
typedef struct sweep_results {
    int n_values, runs, record;
    run_result *res;  /* res[value * runs + run] */
    double *sections; /* record * 2 per run, in the same order */
} sweep_results;

/* The command's defaults: friction-oscillator, 10 runs, a transient of
 * 1000 periods, 50 recorded, seed 1, 900x1200 pixels; a->sweep must be
 * given. */
bif_args bifurcation_defaults(void);

/* The model's parameters and every run of the sweep. */
typedef struct bif_result {
    cm_params base;
    sweep_results s;
    cm_model *models;   /* one per value; built where the value admits the model */
    int n_valid;        /* values that do */
    uint64_t done;      /* runs followed */
    double seconds;
} bif_result;

/* Checks the request and follows every run on a->threads threads (0:
 * all), progress in runs through h, stopped by h (CM_ECANCELED, with
 * r->done). r is freed by bifurcation_result_free whatever the status. */
cm_status bifurcation_compute(const bif_args *a, const work_hooks *h, bif_result *r, char *msg,
                              size_t msg_size);

/* The recorded points (a->out.csv), one line per run (a->runs_csv) and
 * the three-panel diagram (a->out.png), each when given; CM_ERANGE when
 * no value of the sweep admits the model. */
cm_status bifurcation_write(const bif_args *a, const bif_result *r, char *msg, size_t msg_size);

void bifurcation_result_free(bif_result *r);

/* n numbers in [-1, 1) that depend only on the seed, the value and the run. */
void bifurcation_random(long long seed, int value, int run, int n, double *u);

/* The result of run r at value index `value`. */
const run_result *bifurcation_result_at(const sweep_results *s, int value, int r);

#endif
