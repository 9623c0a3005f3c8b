/* models/dde_lyapunov.h - Lyapunov exponents of delay equations
 * (models/dde.h), whose state is a function over the last delay:
 *
 * - Farmer's method (thesis 3.4.2, Table 3.2): the equation discretised on
 *   N samples per delay into a map of the dim (N + 1) samples
 *   x(t), x(t - D), ..., x(t - N D), D = delay / N, whose step integrates
 *   x' = f(t, x, u) over D with the delayed input u taken linearly between
 *   the samples x(t - N D) and x(t - (N - 1) D) (GSL's stepper, to the
 *   equation's tolerances), the tangent map likewise (Df along each
 *   vector by central differences); k vectors re-orthonormalised by
 *   Gram-Schmidt every `gs` steps. Converges to the delay equation's
 *   spectrum as N grows (the input's error is O(D^2)). The thesis' variant
 *   (euler_tangent) steps the tangents by Euler's method instead,
 *   v <- v + D Df(x, x(t - N D)) (v, v(t - N D)), which is not the
 *   integrated map's tangent: where the flow contracts faster than 2/D it
 *   stretches (|1 + D mu| > 1), so it overstates the exponents at coarse
 *   N (docs/models.md 12.3).
 * - The synchronisation estimate of the largest exponent (Stefanski,
 *   Kapitaniak and Dabrowski; thesis (3.38)-(3.39)).
 *
 * Pure: a call owns its memory. */
#ifndef CM_MODELS_DDE_LYAPUNOV_H
#define CM_MODELS_DDE_LYAPUNOV_H

#include "models/dde.h"
#include "models/lyapunov_spectrum.h"

enum { CM_FARMER_MAX = 16, CM_FARMER_MAX_SAMPLES = 2000 };

typedef struct cm_farmer_options {
    int samples;      /* N, 1..CM_FARMER_MAX_SAMPLES */
    int gs;           /* map steps between Gram-Schmidt steps, >= 1 */
    int count;        /* exponents, 1..CM_FARMER_MAX (and <= dim (N + 1)) */
    double transient; /* the delay equation followed before the map starts, >= the delay */
    double time;      /* the time averaged over, > 0 */
    bool euler_tangent; /* the thesis' variant: the tangent map by one Euler step of the
                           variational equation per D (the state as above) */
} cm_farmer_options;

typedef struct cm_farmer_result {
    int count;
    long dim; /* the map's: dim (N + 1) */
    double lambda[CM_FARMER_MAX]; /* decreasing, per unit time */
    double kaplan_yorke;          /* of these (NAN: more are needed) */
    double time;
} cm_farmer_result;

/* The spectrum by Farmer's method; trace (may be NULL) as
 * cm_flow_spectrum's, at each Gram-Schmidt step. CM_EINVAL for bad
 * options, CM_EMODEL when the orbit is lost, CM_ECANCELED when trace
 * stops it; msg says which. */
cm_status cm_dde_farmer(const cm_dde *d, const cm_farmer_options *o, cm_spectrum_trace trace,
                        void *user, cm_farmer_result *out, char *msg, size_t msg_size);

/* The synchronisation estimate of the largest Lyapunov exponent
 * (Stefanski, Kapitaniak and Dabrowski; thesis (3.38)-(3.39)): the system
 * x' = f(x, x_d) + q (y - x) coupled to its copy y' = f(y, x_d), y
 * started `offset` away in every coordinate (over the whole history); the
 * two synchronise when q exceeds the largest exponent. As printed both
 * read x's delayed state, so their difference does not see the delayed
 * terms; own_delay makes the copy read its own, y' = f(y, y_d). Over t0..t1 a run
 * counts as synchronised when max |x - y| over its last tenth is below
 * 1e-3 offset; q is bisected in lo..hi (lo not synchronising, hi
 * synchronising, else CM_ERANGE) to within q_tol. *q_sync gets the
 * threshold. */
typedef struct cm_sync_options {
    double t0, t1, offset, lo, hi, q_tol;
    bool own_delay;
} cm_sync_options;
cm_status cm_dde_sync_estimate(const cm_dde *d, const cm_sync_options *o, double *q_sync,
                               char *msg, size_t msg_size);


#endif
