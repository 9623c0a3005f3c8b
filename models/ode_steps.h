/* models/ode_steps.h - GSL's evolution stepped the way cellmap's
 * integrations need it (the Lyapunov spectra's variational equations,
 * the delay equations and their discretised maps): a step whose stages
 * overflow (a stiff exponential rate in a trial stage too long, whose NaN
 * error estimate GSL's control takes as small) or leave the field's
 * domain (the field returned GSL_EBADFUNC) is taken back and tried ten
 * times shorter, and a step cut short to land on the end does not
 * shorten the next one. */
#ifndef CM_MODELS_ODE_STEPS_H
#define CM_MODELS_ODE_STEPS_H

#include <gsl/gsl_odeiv2.h>
#include <stdbool.h>
#include <stddef.h>

/* One accepted step of d's system (size entries in y) from *t towards
 * t1, going on from step *h; saved: size entries of scratch. False when
 * the state is still not finite, or the field still fails, at steps
 * below 1e-12. */
bool cm_ode_step(gsl_odeiv2_driver *d, size_t size, double *t, double t1, double *h, double *y,
                 double *saved);

/* Steps from *t to t1 (a remainder below the times' resolution is no
 * step: *t becomes t1). */
bool cm_ode_advance(gsl_odeiv2_driver *d, size_t size, double *t, double t1, double *h, double *y,
                    double *saved);

/* Forgets the steps taken (a jump of the field follows). */
void cm_ode_restart(gsl_odeiv2_driver *d);

#endif
