/* models/ode_flow.h - the maps of ODE flows (cm_flow in cellmap/model.h),
 * integrated with GSL's gsl_odeiv2: stroboscopic and Poincare maps. */
#ifndef CM_MODELS_ODE_FLOW_H
#define CM_MODELS_ODE_FLOW_H

#include "cellmap/model.h"

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
