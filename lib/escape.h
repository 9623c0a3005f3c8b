/* lib/escape.h - the transient chaos of the 1-D micro-chaos map with
 * Coulomb friction (thesis 4.3, Figs. 4.5, 4.7) over
 * models/transient_escape.h: at one parameter point or along a sweep, the
 * repeller, the bounds on the escape rate and the mean escape number from
 * its fractal dimension, the exact mean escape number, an ensemble's and
 * cell mapping's; written as CSV and as the thesis' figures. Nothing is
 * printed: calls return a status with the problem in msg (CM_EINVAL: the
 * request's). */
#ifndef CM_LIB_ESCAPE_H
#define CM_LIB_ESCAPE_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/transient_escape.h"

enum { SEED = 20260412, MAX_PARTITION = 1000000 };

typedef struct esc_args {
    model_spec mo;
    param_axis sweep;
    int has_sweep, has_I0, threads;
    double I0;
    long cells, ensemble;
    chart_outputs out;
} esc_args;

/* Everything at one parameter point. */
typedef struct esc_point {
    bool valid;
    char why[200];
    cm_te t;
    double exact;    /* NaN: no finite Markov partition */
    long partition;
    cm_te_ensemble ens;
    double scm_mean; /* NaN: not computed */
    long scm_stay;   /* cells that never leave: cell-map cycles and their basins */
} esc_point;

/* The command's defaults: microchaos-1d-friction, 100000 cells, an
 * ensemble of 10^6, 1000x600 pixels. */
esc_args escape_defaults(void);

/* The model's parameters and the points (the sweep's, or one). */
typedef struct esc_result {
    cm_params base;
    esc_point *pts;
    int n, valid; /* points, and those in the case of 4.3 */
} esc_result;

/* Checks the request and computes every point on a->threads threads (0:
 * all); a point that is not the case of 4.3 is !valid with why, and a
 * single point that is not fails (CM_EINVAL). r is freed by
 * escape_result_free whatever the status. */
cm_status escape_compute(const esc_args *a, esc_result *r, char *msg, size_t msg_size);

/* The points as CSV at a->out.csv and the figure at a->out.png (either
 * may be NULL): Fig. 4.7 along a sweep, else Fig. 4.5 at the point. */
cm_status escape_write(const esc_args *a, const esc_result *r, char *msg, size_t msg_size);

void escape_result_free(esc_result *r);

#endif
