/* models/map_periodic.h - periodic points of any map model (a flow's
 * section map included) and their branches in one parameter: Newton on
 * P^k(x) - x = 0, the multipliers (the eigenvalues of DP^k), and
 * pseudo-arclength continuation (models/arclength.h) with its folds,
 * period doublings and Neimark-Sacker points located; and the switch at
 * a period doubling to the branch of twice the period (thesis 3.2, Table
 * 3.1: chip-4d's cascades).
 *
 * DP^k is taken by central differences of P^k (steps 1e-6 max(1, |x_j|)),
 * so its error is about the map's own error over 1e-6: a flow's section
 * map needs tolerances near 1e-12 (abs_tol, rel_tol) for multipliers good
 * to 1e-5. Periodic points are solutions to 1e-9 (1 + |x|). Pure: the
 * caller's builder is called from the calling thread only. */
#ifndef CM_MODELS_MAP_PERIODIC_H
#define CM_MODELS_MAP_PERIODIC_H

#include "models/arclength.h"

typedef struct cm_periodic_point {
    int dim, period;
    double p;
    double x[CM_MAX_DIM];
    double re[CM_MAX_DIM], im[CM_MAX_DIM]; /* the multipliers, by decreasing modulus */
    int outside;   /* multipliers of modulus above 1 */
    int fold_sign; /* the sign of det(DP^k - I): a multiplier through +1 changes it */
    int flip_sign; /* the sign of det(DP^k + I): a multiplier through -1 changes it */
} cm_periodic_point;

/* J (dim x dim, row-major) = DP^period at x. CM_EMODEL where P^period
 * has no image near x. */
cm_status cm_map_jacobian(const cm_model *m, int period, const double *x, double *J);

/* Newton's method on P^period(x) - x from x (in place) for m at parameter
 * value p (recorded in pt); pt (may be NULL) gets the point and its
 * multipliers. CM_ENOTFOUND (msg says from where) when it does not
 * converge. */
cm_status cm_map_periodic_point(const cm_model *m, double p, int period, double *x,
                                cm_periodic_point *pt, char *msg, size_t msg_size);

/* What a branch of periodic points finds between two of its points. */
enum { CM_PO_FOLD = 1, CM_PO_PD, CM_PO_NS };
typedef struct cm_po_event {
    int kind;              /* CM_PO_FOLD (a multiplier through +1), CM_PO_PD (through -1) or
                              CM_PO_NS (a complex pair through the unit circle) */
    cm_periodic_point at;  /* located to 1e-10 of the step */
} cm_po_event;

/* Follows the branch of period-`period` points through the one near x0
 * at p0 (in lo..hi), calling point for each point and event for each
 * fold, period doubling and Neimark-Sacker point, in order along the
 * branch; either returning nonzero stops it (CM_BRANCH_CALLER). *why:
 * CM_BRANCH_*. */
cm_status cm_map_periodic_branch(cm_model_at_fn at, void *at_user, int period, double p0,
                                 const double *x0, const cm_branch_options *o,
                                 int (*point)(void *user, const cm_periodic_point *pt),
                                 int (*event)(void *user, const cm_po_event *ev), void *user,
                                 int *why, char *msg, size_t msg_size);

/* A point of the orbit of twice the period born at the period doubling
 * pd: at p = pd->at.p + dp (either sign: the side where it exists is
 * found by trying), Newton on P^2k from the doubling point moved along
 * the eigenvector of the multiplier -1 by +-sqrt(|dp|) (the new orbit's
 * size grows so); the result must be a period-2k point that is no period-k
 * point. Into x and *p. CM_ENOTFOUND when neither side gives one. */
cm_status cm_map_period_doubled(cm_model_at_fn at, void *at_user, const cm_po_event *pd,
                                double dp, double *x, double *p, char *msg, size_t msg_size);

/* A point of the periodic orbit born at a Hopf point of a flow (hopf:
 * the equilibrium, its parameter value and the pair +-i omega on the
 * axis), on the map of the flow's section plane x_k = hopf->x[k] (at
 * builds the section maps; the plane through the equilibrium, crossed
 * one way, as at's models take it). The small orbit near the Hopf point
 * is the equilibrium plus eps Re(v e^(i omega t)) (v the eigenvector of
 * i omega), and it crosses the plane where that is tangent to it; from
 * there, at p = hopf->p +- dp (the side where the orbit exists is found
 * by trying) with eps = sqrt(|dp|) x (0.3, 1, 3) times the state's scale,
 * Newton on P(x) - x; the result must lie off the equilibrium. Into x (the
 * map's coordinates) and *p. CM_ENOTFOUND when no side gives one. */
struct cm_equilibrium;
cm_status cm_map_hopf_orbit(cm_model_at_fn at, void *at_user, const struct cm_equilibrium *hopf,
                            double omega, double dp, double *x, double *p, char *msg,
                            size_t msg_size);

#endif
