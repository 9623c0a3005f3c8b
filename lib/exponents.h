/* lib/exponents.h - the Lyapunov spectrum of one orbit of any model over
 * models/lyapunov_spectrum.h: a flow's by its variational equations, a
 * map's (a flow's section or stroboscopic map included) by the QR of its
 * Jacobian, with the Kaplan-Yorke dimension and, for a flow's map, the
 * mean flight between iterates, which turns exponents per iterate into
 * exponents per unit of the flow's time (thesis 3.2: lambda_flow =
 * lambda_map / mean return time). The delay model chip-bue by Farmer's
 * discretised map or the synchronisation estimate (models/dde_lyapunov.h,
 * thesis 3.4.2). The running estimates are written as CSV and drawn.
 * Nothing is printed but by the report calls: calls return a status with
 * the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_EXPONENTS_H
#define CM_LIB_EXPONENTS_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/project.h"
#include "models/lyapunov_spectrum.h"

typedef struct exp_args {
    model_spec mo;
    double from[CM_MAX_DIM]; /* the flow's coordinates (of_map: the map's) */
    int n_from;              /* 0: the centre of the model's example region */
    bool of_map;             /* the map's spectrum (a map model always) */
    cm_spectrum_options o;
    /* chip-bue: Farmer's map on `samples` per delay, Gram-Schmidt every
     * gs steps (the thesis' Euler tangents with euler_tangent), or with
     * sync the synchronisation estimate, q bisected in 0..q_max */
    int samples, gs;
    bool euler_tangent, sync, own_delay;
    double q_max;
    const char *csv, *png;
    int width, height; /* 0, 0: 900x500 */
} exp_args;

/* The command's defaults: chip-4d; flows 100 time units after 10 of
 * transient, renormalised every 0.1; maps 10000 iterates after 100;
 * chip-bue 20 samples a delay, Gram-Schmidt every 10 steps, q up to 20;
 * the figure's size 0 (900x500). */
exp_args exponents_defaults(void);

/* One row of the running estimates. */
typedef struct exp_row {
    double t; /* the time (flows) or iterates (maps) averaged over */
    double lambda[CM_MAX_DIM];
} exp_row;

typedef struct exp_result {
    cm_model m;
    cm_spectrum s;
    bool of_map, delay; /* delay: chip-bue's (m describes it, it has no map) */
    double sync_q;      /* the synchronisation estimate; NAN unless asked */
    long farmer_dim;    /* Farmer's map's dimension (0: not used) */
    double mean_flight; /* a flow's map: the mean time between iterates; NAN otherwise */
    exp_row *rows;      /* at most about 10000, evenly thinned, the last always */
    size_t n_rows, cap_rows;
    long stride, seen;
} exp_result;

/* Checks the request (the start's dimension, the settings) and computes.
 * r is freed by exponents_result_free whatever the status; CM_EMODEL when
 * the orbit is lost. */
cm_status exponents_compute(const exp_args *a, exp_result *r, char *msg, size_t msg_size);

/* The running estimates as CSV at a->csv (NULL: nothing): t (time or
 * iterates), lambda_1..lambda_k (decreasing), kaplan_yorke, and for a
 * flow's map flow_time; and as a chart against t at a->png. */
cm_status exponents_write(const exp_args *a, const exp_result *r, char *msg, size_t msg_size);

/* The result as text (the exponents, their sum, the Kaplan-Yorke
 * dimension, per unit time for a flow's map) and as the JSON document of
 * `cellmap exponents --json` (docs/cellmap.schema.json), to f. */
void exponents_report(FILE *f, const exp_result *r);
void exponents_json(FILE *f, const exp_result *r);

void exponents_result_free(exp_result *r);

#endif
