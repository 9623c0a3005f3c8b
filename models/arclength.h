/* models/arclength.h - one-parameter continuation of the solutions of
 * f(x, p) = 0 (x of n <= CM_MAX_DIM coordinates) by pseudo-arclength:
 * a tangent predictor, Newton's corrector in the plane normal to it, the
 * step halved where Newton fails and grown where it converges fast; and
 * the events between two points, where an integer test of the caller's
 * changes sign or count, located by bisection along the chord to 1e-10.
 * The equilibria of flows (models/flow_equilibria.h: f the field) and the
 * periodic points of maps (models/map_periodic.h: f = P^k(x) - x) are its
 * problems. df/dp is taken by central differences of f; df/dx is the
 * problem's. Pure: no global state, the calling thread only. */
#ifndef CM_MODELS_ARCLENGTH_H
#define CM_MODELS_ARCLENGTH_H

#include <stdbool.h>
#include <stddef.h>

#include "cellmap/model.h"

/* The model at parameter value p, built by the caller; the kernel
 * releases it (cm_model_release). Nonzero status: p is outside the
 * model's range. */
typedef cm_status (*cm_model_at_fn)(void *user, double p, cm_model *m, char *msg,
                                    size_t msg_size);

/* Where a problem's model comes from: one fixed model (fixed not NULL),
 * or the caller's builder at each parameter value. */
typedef struct cm_model_source {
    const cm_model *fixed;
    cm_model_at_fn at;
    void *at_user;
} cm_model_source;

/* The model at p into *m: the fixed one, or one built into *own, which
 * cm_model_source_done releases (call it after a CM_OK only). */
cm_status cm_model_source_at(const cm_model_source *s, double p, cm_model *own,
                             const cm_model **m, char *msg, size_t msg_size);
void cm_model_source_done(const cm_model_source *s, cm_model *own);

/* The most bytes a problem keeps of a point (its classification). */
#define CM_ARC_STATE_MAX 1024
/* The most tests a problem has. */
#define CM_ARC_TESTS 4

typedef struct cm_arc_problem {
    int n;      /* unknowns besides the parameter, 1..CM_MAX_DIM */
    double tol; /* a solution: |f| <= tol (1 + |x|) */
    /* f(x, p) into f and, unless J is NULL, df/dx into J (n x n,
     * row-major): CM_OK, else why not (e.g. CM_EMODEL where f is not
     * defined). */
    cm_status (*eval)(void *ctx, double p, const double *x, double *f, double *J);
    /* The point (x, p) as the caller keeps it, into state (state_size
     * bytes), and its tests (n_tests integers): an event lies where one
     * changes. */
    cm_status (*classify)(void *ctx, double p, const double *x, void *state, int *tests);
    size_t state_size;
    int n_tests;
    /* A test that the others' events change too (a count of unstable
     * directions, which a fold also changes): its change is an event only
     * where no other test changed; -1: none. */
    int count_test;
    void *ctx;
    char *msg;
    size_t msg_size;
} cm_arc_problem;

/* Why a branch ended. */
enum { CM_BRANCH_LEFT_RANGE = 1, CM_BRANCH_MAX_POINTS, CM_BRANCH_LOST, CM_BRANCH_CALLER };

typedef struct cm_branch_options {
    double lo, hi;  /* the parameter's range */
    int direction;  /* +1: p increases first; -1: decreases */
    double ds;      /* the first arclength step; 0: (hi - lo) / 200 */
    double ds_max;  /* 0: (hi - lo) / 50 */
    int max_points; /* 0: 10000 */
} cm_branch_options;

/* Damped Newton's method on f(., p) = 0 from x (in place): each step
 * halved until the residual falls, at most 50 steps. CM_OK with x a
 * solution, CM_ENOTFOUND when it does not converge, or eval's status. */
cm_status cm_arc_newton(const cm_arc_problem *pr, double p, double *x);

/* Follows the branch through the solution x0 at p0 (in lo..hi; Newton
 * makes x0 one first), calling point with each point's state (the first
 * included; the last one on the range's end where the branch leaves it)
 * and event with the test that changed and the state where it changes,
 * in order along the branch; either returning nonzero stops the branch
 * (CM_BRANCH_CALLER). *why: CM_BRANCH_*. */
cm_status cm_arc_follow(const cm_arc_problem *pr, double p0, const double *x0,
                        const cm_branch_options *o, int (*point)(void *user, const void *state),
                        int (*event)(void *user, int test, const void *state), void *user,
                        int *why);

/* Solves the n x n system a z = b (a is overwritten); false when singular
 * or the solution is not finite. */
bool cm_solve_linear(int n, double *a, const double *b, double *z);

#endif
