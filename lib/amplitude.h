/* lib/amplitude.h - the friction oscillator's amplitude-frequency diagram
 * (thesis 2.2, Figs. 2.3-2.4) over models/fo_continuation.h, written as
 * CSV and as the diagram. Nothing is printed: calls return a status
 * with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_AMPLITUDE_H
#define CM_LIB_AMPLITUDE_H

#include <stdbool.h>

#include "lib/fo_transients.h"
#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/fo_continuation.h"

/* What to compute and write (the command's options). */
typedef struct amp_args {
    model_spec mo;
    param_axis omega;
    int has_omega, periods, threads;
    double ymax;
    chart_outputs out;
    fo_transient_args transient; /* kind 0: the diagram; else lib/fo_transients.h's analysis */
} amp_args;

/* The command's defaults: friction-oscillator, 400 periods, y up to 5,
 * 1000x700 pixels; a->omega must be given. */
amp_args amplitude_defaults(void);

/* The model's parameters and the diagram's points. */
typedef struct amp_result {
    cm_params base;
    cm_fo_amplitude *v; /* a->omega.n of them */
    int valid, stable, lost; /* points where (2.25) is valid, stable; simulations lost */
    bool invalid;            /* some frequencies could not be built (S > S0) */
} amp_result;

/* Checks the request and computes the points on a->threads threads (0:
 * all); r is freed by amplitude_result_free whatever the status. */
cm_status amplitude_compute(const amp_args *a, amp_result *r, char *msg, size_t msg_size);

/* The points as CSV at a->out.csv and the diagram at a->out.png (either
 * may be NULL). */
cm_status amplitude_write(const amp_args *a, const amp_result *r, char *msg, size_t msg_size);

void amplitude_result_free(amp_result *r);

#endif
