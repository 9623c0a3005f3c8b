/* models/ode_flow.h - the maps of ODE flows (cm_flow in cellmap/model.h),
 * integrated with GSL's gsl_odeiv2: stroboscopic and Poincare maps. */
#ifndef CM_MODELS_ODE_FLOW_H
#define CM_MODELS_ODE_FLOW_H

#include <gsl/gsl_odeiv2.h>

#include "cellmap/model.h"

/* Makes m, whose create() filled m->flow and left step NULL, a map:
 * checks the flow, takes the settings of CM_FLOW_PARAM_SPECS from m's
 * parameters where it has them, fills the defaults, and sets step and
 * step_n. */
cm_status cm_flow_attach(cm_model *m, char *msg, size_t msg_size);

/* The flow's map from x at time t0 into y, as step gives it; *t_end (if
 * not NULL) gets the time the image was taken at (for a Poincare map:
 * t0 plus the return time) or, without an image, the time the orbit was
 * followed to (t0 + t_max: the section was not reached; earlier: the
 * orbit was lost), and *steps the integration steps taken. */
int cm_flow_map(const cm_model *m, const double *x, double *y, double *t_end, long *steps);

/* Follows m's flow from x (cm_flow_dim(m) entries) at time t0 to t1 > t0
 * with m's integrator, calling observe(user, CM_FLOW_SAMPLE, t, y) at t0,
 * t0 + dt, ... and t1, and observe(user, CM_FLOW_CROSSING, t, y) at each
 * crossing of m's section (a Poincare map's, located as the map locates
 * it; none for a stroboscopic map), in the order of t. Returns CM_STEP_OK,
 * CM_STEP_NO_IMAGE when the orbit is lost (as the map would lose it),
 * CM_STEP_ABORT when out of memory, or what observe returned when nonzero
 * (which stops the run); *t_reached (may be NULL) gets the time reached.
 * Each sample interval may take CM_FLOW_MAX_STEPS steps. */
enum { CM_FLOW_SAMPLE = 0, CM_FLOW_CROSSING = 1 };
typedef int (*cm_flow_observer)(void *user, int kind, double t, const double *y);
int cm_flow_follow(const cm_model *m, const double *x, double t0, double t1, double dt,
                   cm_flow_observer observe, void *user, double *t_reached);

/* J (n x n, row-major, n = cm_flow_dim(m)) = df/dx at (t, x), by central
 * differences (steps 1e-7 max(1, |x_j|)): CM_EMODEL where the field fails
 * or is not finite there. The implicit integrators' Jacobian. */
cm_status cm_flow_jacobian_at(const cm_model *m, double t, const double *x, double *J);

/* GSL's stepper for a cm_flow.method. */
const gsl_odeiv2_step_type *cm_flow_stepper(int method);

/* The flow's state y (cm_flow_dim(m) entries) of the map's state x (m->dim
 * entries): x itself, or for a section on a plane x with x_k = level put
 * in. */
void cm_flow_lift(const cm_model *m, const double *x, double *y);

/* Whether m is the map of a flow. */
static inline bool cm_model_is_flow(const cm_model *m) { return m->flow.field != NULL; }

#endif
