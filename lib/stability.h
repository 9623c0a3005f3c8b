/* lib/stability.h - the analytic charts of the PD-controlled micro-chaos
 * map (thesis 4.5, App. C.4; Figs. 4.12, 4.14, C.4) over
 * models/microchaos_pd.h: the stability domain in the P-D plane with the
 * eigen-structure curves, the regular fixed points against P with the
 * border collisions, the fewest fixed points a stable choice of gains
 * allows against alpha, and the control error's bounds; written as CSV
 * and charts. Nothing is printed: a failed write returns false with the
 * problem in msg. */
#ifndef CM_LIB_STABILITY_H
#define CM_LIB_STABILITY_H

#include <stdbool.h>

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

/* The rows (a->P.n of them) as CSV at a->out.csv. */
bool stability_write_csv(const stab_args *a, const stab_row *rows, char *msg, size_t msg_size);

/* The charts at a->out.png, the model's point (P0, D0) marked. */
bool stability_write_png(const stab_args *a, const cm_params *p, const stab_row *rows,
                         double alpha, double beta, double P0, double D0, char *msg,
                         size_t msg_size);

#endif
