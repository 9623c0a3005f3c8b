/* lib/amplitude.h - the friction oscillator's amplitude-frequency diagram
 * (thesis 2.2, Figs. 2.3-2.4) over models/fo_continuation.h, written as
 * CSV and as the diagram. Nothing is printed: a failed write returns
 * false with the problem in msg. */
#ifndef CM_LIB_AMPLITUDE_H
#define CM_LIB_AMPLITUDE_H

#include <stdbool.h>

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
} amp_args;

/* The diagram's points (a->omega.n of them) as CSV at a->out.csv. */
bool amplitude_write_csv(const amp_args *a, const cm_fo_amplitude *v, char *msg,
                         size_t msg_size);

/* The diagram at a->out.png. */
bool amplitude_write_png(const amp_args *a, const cm_params *p, const cm_fo_amplitude *v,
                         char *msg, size_t msg_size);

#endif
