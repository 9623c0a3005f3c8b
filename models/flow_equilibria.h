/* models/flow_equilibria.h - equilibria of an autonomous flow x' = f(x)
 * (a model's cm_flow.field, evaluated at its t0, in cm_flow_dim(m)
 * coordinates), their eigenvalues, and a branch of them followed in one
 * parameter by pseudo-arclength continuation (models/arclength.h) with
 * its folds and Hopf points located (thesis 3.2: the chip formation
 * flow's Hopf points at xi = 4.42808 and 11.8039).
 *
 * Jacobians are central differences of the field (steps 1e-7 relative to
 * the coordinate, at least 1e-7), good to about 1e-8 relative for fields
 * whose second derivatives are of the order of the first: a located point
 * is checked by its residual and eigenvalues, which the caller can
 * recompute. Dimensions up to CM_MAX_DIM. Pure: no global state; the
 * model builder of a branch is called from the calling thread only. */
#ifndef CM_MODELS_FLOW_EQUILIBRIA_H
#define CM_MODELS_FLOW_EQUILIBRIA_H

#include <stdbool.h>

#include "cellmap/model.h"
#include "models/arclength.h"

/* An equilibrium at parameter value p and its linearisation's
 * eigenvalues, by decreasing real part (a complex pair: +im first). */
typedef struct cm_equilibrium {
    int dim;
    double p;
    double x[CM_MAX_DIM];
    double re[CM_MAX_DIM], im[CM_MAX_DIM];
    int unstable; /* eigenvalues with re > 0 (a pair counts twice) */
    int det_sign; /* the sign of det df/dx: a real eigenvalue through 0 changes it */
} cm_equilibrium;

/* J (dim x dim, row-major) = df/dx at x. CM_EMODEL where the field is not
 * defined at x or near it. */
cm_status cm_flow_jacobian(const cm_model *m, const double *x, double *J);

/* The eigenvalues of J (n x n), by decreasing real part. */
cm_status cm_eigenvalues(int n, const double *J, double *re, double *im);

/* Newton's method (damped: a step is halved until the residual falls)
 * from x: on success x is an equilibrium, |f(x)| <= 1e-10 (1 + |x|), and
 * e (may be NULL) holds it with its eigenvalues at p. CM_ENOTFOUND when
 * Newton does not converge in 50 iterations (msg says from where). */
cm_status cm_flow_equilibrium(const cm_model *m, double p, double *x, cm_equilibrium *e,
                              char *msg, size_t msg_size);

/* What a branch finds between two of its points. */
enum { CM_EQ_FOLD = 1, CM_EQ_HOPF = 2 };
typedef struct cm_eq_event {
    int kind;          /* CM_EQ_FOLD (det df/dx changes sign: a fold, or a branch
                        * point) or CM_EQ_HOPF (a complex pair through the axis) */
    cm_equilibrium at; /* located to 1e-10 in p */
    double omega;     /* Hopf: the imaginary part of the pair on the axis */
} cm_eq_event;

/* Follows the branch through the equilibrium near x0 at p0 (in lo..hi),
 * calling point for each point (the first included; the last one on the
 * range's end where the branch leaves it) and event for each fold and
 * Hopf point between two, in order; either returning nonzero stops the
 * branch (CM_BRANCH_CALLER). *why: CM_BRANCH_*. */
cm_status cm_flow_equilibrium_branch(cm_model_at_fn at, void *at_user, double p0,
                                     const double *x0, const cm_branch_options *o,
                                     int (*point)(void *user, const cm_equilibrium *e),
                                     int (*event)(void *user, const cm_eq_event *ev),
                                     void *user, int *why, char *msg, size_t msg_size);

/* The model at parameters (p, q), built by the caller; the kernel
 * releases it. */
typedef cm_status (*cm_model_at2_fn)(void *user, double p, double q, cm_model *m, char *msg,
                                     size_t msg_size);

/* A Hopf curve in the plane (p, q), as points: at each q[k] (n values,
 * in order) the branch in p over o's range from p0 (its equilibrium found
 * from x0 at the first q, then from the previous q's), calling hopf for
 * each Hopf point on it; hopf returning nonzero stops. Folds are passed
 * over. CM_ENOTFOUND when the start is lost at some q (msg says which). */
cm_status cm_flow_hopf_curve(cm_model_at2_fn at, void *at_user, double p0, const double *x0,
                             const double *q, int n, const cm_branch_options *o,
                             int (*hopf)(void *user, double q, const cm_eq_event *ev), void *user,
                             char *msg, size_t msg_size);

#endif
