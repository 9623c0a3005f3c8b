/* lib/fo_transients.h - the friction oscillator's analyses beside its
 * amplitude-frequency diagram (thesis 2.2-2.4; docs/models.md 9.10-9.11),
 * for `cellmap amplitude --h | --extremal | --converge`: the function H of
 * the two-turnaround condition (2.29) (Fig. 2.5), the map of a perturbation
 * of the extremal asymmetric solution (Fig. 2.10) and a simulation's
 * convergence to the periodic solution it settles on against the leading
 * multiplier (Fig. 2.11); each computed, reported (text or JSON) and
 * written as CSV and a chart. Calls print only to the streams given and
 * return a status with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_FO_TRANSIENTS_H
#define CM_LIB_FO_TRANSIENTS_H

#include <stdio.h>

#include "lib/outfile.h"
#include "models/params.h"

enum fo_transient_kind { FO_H = 1, FO_EXTREMAL, FO_CONVERGE };

enum { FO_H_MAX_CURVES = 6 };

typedef struct fo_transient_args {
    int kind;                        /* 0: none (the diagram) */
    double omegas[FO_H_MAX_CURVES];  /* FO_H: a panel each */
    int n_omegas;
    double eps_max;                  /* FO_EXTREMAL: perturbations 0 < eps <= eps_max */
    int periods;                     /* FO_CONVERGE: periods followed (after settling) */
} fo_transient_args;

/* Computes the analysis t->kind for the friction-oscillator model with
 * parameters base (S, S0, Omega), reports it to report (NULL: nothing) or
 * as JSON on standard output (json), and writes out->csv and out->png
 * (either NULL). */
cm_status fo_transient_run(const fo_transient_args *t, const char *model, const cm_params *base,
                           const chart_outputs *out, FILE *report, char *msg, size_t msg_size);

#endif
