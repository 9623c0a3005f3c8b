/* lib/horseshoe.h - the Smale horseshoes of the PD-controlled micro-chaos
 * map at its switching lines (thesis 4.5.3, Figs. 4.15-4.19) over
 * models/microchaos_pd.h: the trapezoids L and R, the escape conditions of
 * a full binary shift, and the periodic points of the restricted maps,
 * whose growth bounds the topological entropy from below; written as CSV
 * and as the thesis' figures. Nothing is printed: a failed write returns
 * false with the problem in msg. */
#ifndef CM_LIB_HORSESHOE_H
#define CM_LIB_HORSESHOE_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/microchaos_pd.h"

/* What to compute and write (the command's options). */
typedef struct hs_args {
    model_spec mo;
    int64_t m0, m1;
    int has_m, periods, has_sweep, crisis;
    param_axis sweep;
    chart_outputs out;
} hs_args;

/* One switching line at one P. */
typedef struct hs_item {
    double P;
    cm_pd_horseshoe h;
    uint64_t periodic; /* N_n */
    double entropy;    /* log(N_n)/n; NaN for N_n = 0 */
} hs_item;

/* The horseshoe at switching line m, with its periodic points of period n. */
void horseshoe_item_at(double alpha, double beta, double P, double D, int64_t m, int n,
                       hs_item *it);

/* The items as CSV at a->out.csv. */
bool horseshoe_write_csv(const hs_args *a, const hs_item *items, int count, char *msg,
                         size_t msg_size);

/* The figure at a->out.png: the crisis chart or the sweep (nm lines per
 * value of P), or the horseshoes at one point (alpha, beta, P, D). */
bool horseshoe_write_png(const hs_args *a, const hs_item *items, int nm, int count, double alpha,
                         double beta, double P, double D, const char *params, char *msg,
                         size_t msg_size);

#endif
