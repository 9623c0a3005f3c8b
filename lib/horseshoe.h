/* lib/horseshoe.h - the Smale horseshoes of the PD-controlled micro-chaos
 * map at its switching lines (thesis 4.5.3, Figs. 4.15-4.19) over
 * models/microchaos_pd.h: the trapezoids L and R, the escape conditions of
 * a full binary shift, and the periodic points of the restricted maps,
 * whose growth bounds the topological entropy from below; written as CSV
 * and as the thesis' figures. Nothing is printed: calls return a status
 * with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_HORSESHOE_H
#define CM_LIB_HORSESHOE_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/microchaos_pd.h"
#include "models/pd_strips.h" /* the images' limits */

/* What to compute and write (the command's options). */
typedef struct hs_args {
    model_spec mo;
    int64_t m0, m1;
    int has_m, periods, has_sweep, crisis;
    int images, preimages; /* the point's figure: f^images, f^-preimages of L and R (1, 0) */
    param_axis sweep;
    param_axis plane; /* with has_plane: D over the P-D plane (Fig. 4.19) */
    int has_plane;
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

/* The command's defaults: microchaos-pd, period 12, 1000x600 pixels. */
hs_args horseshoe_defaults(void);

/* The model's parameters and the lines (m0..m1 at each value of P). */
typedef struct hs_result {
    cm_params base;
    double alpha, beta, P, D; /* the model's */
    hs_item *items;           /* count = nm lines times the values of P */
    int nm, count;
} hs_result;

/* Checks the request, takes the lines 1..m_max when a->has_m is not set,
 * and computes r (freed by horseshoe_result_free whatever the status). */
cm_status horseshoe_compute(hs_args *a, hs_result *r, char *msg, size_t msg_size);

/* The lines as CSV at a->out.csv and the figure at a->out.png (either may
 * be NULL): the crisis chart or the sweep, or the horseshoes at the
 * model's point. */
cm_status horseshoe_write(const hs_args *a, const hs_result *r, char *msg, size_t msg_size);

void horseshoe_result_free(hs_result *r);

/* One line's summary as a line of text to f; the result as a JSON document
 * on standard output. */
void horseshoe_report_item(FILE *f, const hs_args *a, const hs_item *it);
void horseshoe_json(const hs_args *a, const hs_result *r);

#endif
