/* lib/bifurcation.h - brute-force bifurcation diagrams of the friction
 * oscillator (thesis 2.4, Figs. 2.13-2.16) over
 * models/friction_oscillator.h: for each value of the swept parameter,
 * runs from random starts followed past a transient, their sticking
 * displacements, Poincare sections and asymmetry recorded; written as CSV
 * (points, runs) and as the three-panel diagram. Nothing is printed: a
 * failed write returns false with the problem in msg. */
#ifndef CM_LIB_BIFURCATION_H
#define CM_LIB_BIFURCATION_H

#include <stdbool.h>

#include "lib/outfile.h"
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

/* Runs from the random start; sections[2 k], [2 k + 1]: the k-th recorded Poincare point. */
/* Run r at value index `value` of o (a random start from a->seed),
 * recording a->record sections into sections (2 doubles each). */
void bifurcation_run(const bif_args *a, const cm_fo *o, int value, int r, run_result *res,
                double *sections);

/* The result of run r at value index `value`. */
const run_result *bifurcation_result_at(const sweep_results *s, int value, int r);

/* The recorded points (sticks and sections) as CSV at a->out.csv. */
bool bifurcation_write_points_csv(const bif_args *a, const sweep_results *s, char *msg,
                                  size_t msg_size);

/* One line per run (start, asymmetry, sticks) as CSV at a->runs_csv. */
bool bifurcation_write_runs_csv(const bif_args *a, const sweep_results *s, char *msg,
                                size_t msg_size);

/* The three-panel diagram at a->out.png. */
bool bifurcation_write_png(const bif_args *a, const cm_params *base, const sweep_results *s,
                           char *msg, size_t msg_size);

/* Frees the results and the models of the values (models[k] built where
 * its oscillator is set). */
void bifurcation_free(sweep_results *s, cm_model *models);

#endif
