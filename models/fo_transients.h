/* models/fo_transients.h - how the friction oscillator's solutions approach
 * periodic ones (thesis 2.3.3-2.4; docs/models.md 9.11): the map of a
 * perturbation that pushes the extremal asymmetric solution into the
 * sticking region (Fig. 2.10: the thesis' second-order expansion gives
 * eps -> eps - 2 eps^2), and the relative error of a simulation converging
 * to the symmetric non-sticking solution against its leading
 * characteristic multiplier (Fig. 2.11). Pure functions, any thread. */
#ifndef CM_MODELS_FO_TRANSIENTS_H
#define CM_MODELS_FO_TRANSIENTS_H

#include <stdbool.h>

#include "models/friction_oscillator.h"

/* From (t = 0, x = 1 + S - eps, v = 0), the forcing at its maximum, to the
 * first stick after the turnaround: eps' = 1 + S - x there, the next
 * perturbation (the stick fixes everything after it). NaN when the motion
 * does not stick after one turnaround within two periods. */
double cm_fo_extremal_next(const cm_fo *o, double eps);

/* The convergence of a simulation from z0 (at the section phase of o) to
 * the periodic solution it settles on: that solution's point z_star on the
 * section (the simulation's end after `settle` periods, refined by
 * Newton), its characteristic multipliers' largest modulus, and the
 * relative error |z_n - z_star|/|z_star| after n = 0..periods periods into
 * err (periods + 1 values). False when the motion is lost or Newton fails. */
typedef struct cm_fo_convergence {
    double z_star[2];
    double mult_max; /* |lambda_max| of the exact monodromy at z_star */
    double mult_arg; /* its argument (0 or pi when real) */
} cm_fo_convergence;

bool cm_fo_converge(const cm_fo *o, const double z0[2], int settle, int periods, double *err,
                    cm_fo_convergence *out);

#endif
