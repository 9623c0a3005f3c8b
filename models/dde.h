/* models/dde.h - delay differential equations x'(t) = f(t, x(t),
 * x(t - delay)) with one constant delay, by the method of steps: GSL's
 * Runge-Kutta steppers (cm_flow's methods) with adaptive steps no longer
 * than the delay, so that every delayed value a stage needs lies in the
 * solution already accepted, read from its continuous extension (the
 * cubic Hermite interpolant of the accepted steps' states and rates,
 * O(h^4)). Steps land on the breakpoints where the solution's derivative
 * jumps: the start plus multiples of the delay (the history's end
 * propagating), and the model's own (a forcing with jumps, a phase that
 * ends). Pure: a run owns its memory, so runs may go on several threads. */
#ifndef CM_MODELS_DDE_H
#define CM_MODELS_DDE_H

#include <stddef.h>

#include "cellmap/model.h"

/* The history's breakpoints followed: jumps of x^(k) for k <= this many
 * delays after the start are stepped on (the solution is smoother after). */
enum { CM_DDE_BREAKS = 8 };

typedef struct cm_dde {
    int dim;      /* 1..CM_MAX_DIM * 2 */
    double delay; /* > 0 */
    /* dxdt = f(t, x, xd) with xd = x(t - delay); 0, or nonzero where not
     * defined (the run stops). */
    int (*field)(const void *ctx, double t, const double *x, const double *xd, double *dxdt);
    /* x(t) for t <= t0 (the history, continuous up to t0) */
    void (*history)(const void *ctx, double t, double *x);
    /* optional: the first time > t where the field jumps in t (else INFINITY) */
    double (*next_break)(const void *ctx, double t);
    const void *ctx;
    int method;              /* CM_FLOW_RK8PD ... explicit ones only (CM_FLOW_RK4 at most) */
    double abs_tol, rel_tol; /* per step; 0: 1e-9 */
} cm_dde;

enum { CM_DDE_MAX_DIM = 2 * CM_MAX_DIM };

/* Follows d from t0 (x(t0) from the history) to t1 > t0, calling
 * observe(user, t, x) at t0, t0 + dt, ..., t1 (exactly those times, from
 * which steps land on) unless observe is NULL; a nonzero return
 * stops the run with CM_ECANCELED. x1 (may be NULL) gets x(t1). CM_EINVAL
 * for a bad request (msg says which), CM_EMODEL when the field fails or
 * the state is not finite (msg: at which time), CM_ENOMEM. */
typedef int (*cm_dde_observer)(void *user, double t, const double *x);
cm_status cm_dde_solve(const cm_dde *d, double t0, double t1, double dt, cm_dde_observer observe,
                       void *user, double *x1, char *msg, size_t msg_size);

#endif
