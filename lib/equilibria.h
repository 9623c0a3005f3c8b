/* lib/equilibria.h - equilibria of a flow model and their branches over
 * models/flow_equilibria.h: one equilibrium by Newton with its
 * eigenvalues; the branch through it in one parameter with its folds and
 * Hopf points (thesis 3.2: chip-4d's Hopf points at xi = 4.42808 and
 * 11.8039); the Hopf points along a second parameter's values (a Hopf
 * curve, thesis Fig. 3.8). Written as CSV. Nothing is printed: calls
 * return a status with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_EQUILIBRIA_H
#define CM_LIB_EQUILIBRIA_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/param_grid.h"
#include "models/flow_equilibria.h"

typedef struct eq_args {
    model_spec mo;
    branch_spec b;    /* from: the start of Newton, in the flow's coordinates */
    param_axis curve; /* with a branch: the Hopf points at each of these values */
    bool has_curve;
    const char *csv;
} eq_args;

/* The command's defaults: chip-4d, both ways, 10000 points a way. */
eq_args equilibria_defaults(void);

typedef struct eq_hopf {
    double q;       /* the curve's parameter */
    cm_eq_event ev; /* the Hopf point on the branch at q */
} eq_hopf;

/* A fold or Hopf point between pts[before - 1] and pts[before]. */
typedef struct eq_event {
    cm_eq_event ev;
    size_t before;
} eq_event;

typedef struct eq_result {
    cm_model m;       /* at the parameters given */
    cm_params base;   /* the parameters given */
    cm_equilibrium start;
    cm_equilibrium *pts; /* the branch in order along it (lo side first) */
    size_t n_pts, cap_pts;
    eq_event *events; /* in the same order */
    size_t n_events, cap_events;
    int why[2]; /* how each way ended (CM_BRANCH_*; 0: not followed) */
    eq_hopf *hopf;
    size_t n_hopf, cap_hopf;
} eq_result;

/* Checks the request (a flow model; --from of the flow's dimension; the
 * branch's parameter is the model's and its range holds the model's
 * value) and computes. r is freed by equilibria_result_free whatever the
 * status; CM_ENOTFOUND when Newton does not converge from a->from. */
cm_status equilibria_compute(const eq_args *a, eq_result *r, char *msg, size_t msg_size);

/* The rows as CSV at a->csv (NULL: nothing): kind (equilibrium, point,
 * fold, hopf), the branch parameter's value, the curve's (with a curve),
 * the flow's coordinates, the eigenvalues (re_k, im_k by decreasing real
 * part), the unstable count and a Hopf point's omega. */
cm_status equilibria_write(const eq_args *a, const eq_result *r, char *msg, size_t msg_size);

/* The result as text (the equilibrium, the branch's folds and Hopf
 * points, the Hopf curve) and as the JSON document of `cellmap equilibria
 * --json` (docs/cellmap.schema.json), to f. */
void equilibria_report(FILE *f, const eq_args *a, const eq_result *r);
void equilibria_json(FILE *f, const eq_args *a, const eq_result *r);

void equilibria_result_free(eq_result *r);

/* "fold" or "hopf". */
const char *equilibria_event_name(int kind);

/* Why a way of the branch ended, in words. */
const char *equilibria_why(int why);

#endif
