/* lib/stability.h - the analytic charts of the PD-controlled micro-chaos
 * map (thesis 4.5, App. C.4; Figs. 4.12, 4.14, C.4) over
 * models/microchaos_pd.h: the stability domain in the P-D plane with the
 * eigen-structure curves, the regular fixed points against P with the
 * border collisions, the fewest fixed points a stable choice of gains
 * allows against alpha, and the control error's bounds; written as CSV
 * and charts. Nothing is printed: calls return a status with the problem
 * in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_STABILITY_H
#define CM_LIB_STABILITY_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/microchaos_pd.h"

typedef struct stab_args {
    model_spec mo;
    param_axis P, alpha;
    int has_P, has_alpha;
    chart_outputs out;
} stab_args;

/* Everything at one P (alpha, beta of the model). */
typedef struct stab_row {
    double P;
    cm_pd_stability st; /* its D_b0, D_b1 */
    cm_pd_eigen_curves ec;
    int64_t m_fix_max, m_max; /* -1: P <= alpha^2 */
    double x_max_sw, x_max;
} stab_row;

/* The row at P (alpha, beta, D of the model). */
void stability_row_at(double alpha, double beta, double P, double D, stab_row *r);

/* The command's defaults: microchaos-pd, 900x1200 pixels. */
stab_args stability_defaults(void);

/* The model's parameters and a row per value of a->P. */
typedef struct stab_result {
    cm_params base;
    double alpha, beta, P, D; /* the model's */
    stab_row *rows;           /* a->P.n of them */
} stab_result;

/* Checks the model and fills the axes not given (P from 1.0025 alpha^2 to
 * 1.2 P_max in 400 values, alpha 0.05..3 in 300), then computes r (freed
 * by stability_result_free whatever the status). */
cm_status stability_compute(stab_args *a, stab_result *r, char *msg, size_t msg_size);

/* The rows as CSV at a->out.csv and the charts at a->out.png (either
 * may be NULL), the model's point (P, D) marked. */
cm_status stability_write(const stab_args *a, const stab_result *r, char *msg, size_t msg_size);

void stability_result_free(stab_result *r);

/* What the model's point is (stable or not, its fixed points, the control
 * error), as text to f and as a JSON document on standard output. */
void stability_report(FILE *f, double alpha, double beta, double P, double D);
void stability_json(const char *model, const cm_params *p, double alpha, double beta, double P,
                    double D);

#endif
