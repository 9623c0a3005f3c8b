/* models/ode_flow.h - the maps of ODE flows (cm_flow in cellmap/model.h),
 * integrated with GSL's gsl_odeiv2: stroboscopic and Poincare maps. */
#ifndef CM_MODELS_ODE_FLOW_H
#define CM_MODELS_ODE_FLOW_H

#include "cellmap/model.h"

/* The integrator settings a flow model takes as parameters, spelt the
 * same for built-in models and plugins: put CM_FLOW_PARAM_SPECS at the end
 * of a spec (before its terminator) and cm_flow_attach reads them. */
#define CM_FLOW_PARAM_SPECS                                                                    \
    {"method", "rk8pd", 0, 3, 1, "rk8pd|rkf45|rkck|rk4",                                       \
     "integrator: GSL's Runge-Kutta Prince-Dormand 8(9), Fehlberg 4(5), Cash-Karp 4(5), RK4"},  \
        {"abs_tol", "1e-9", 1e-15, 1e-2, 1, NULL, "absolute error per integration step"},       \
        {"rel_tol", "1e-9", 0, 1e-2, 1, NULL, "relative error per integration step"},           \
        {"world", "1e6", 1e-6, 1e300, 1, NULL, "|x_i| beyond this: the orbit has no image"}

/* Makes m, whose create() filled m->flow and left step NULL, a map:
 * checks the flow, takes the settings of CM_FLOW_PARAM_SPECS from m's
 * parameters where it has them, fills the defaults, and sets step and
 * step_n. */
cm_status cm_flow_attach(cm_model *m, char *msg, size_t msg_size);

/* The flow's map from x at time t0 into y, as step gives it; *t_end (if
 * not NULL) gets the time the image was taken at and *steps the
 * integration steps taken. */
int cm_flow_map(const cm_model *m, const double *x, double *y, double *t_end, long *steps);

/* Whether m is the map of a flow. */
static inline bool cm_model_is_flow(const cm_model *m) { return m->flow.field != NULL; }

#endif
