/* models/lyapunov_spectrum.h - Lyapunov spectra (Benettin et al. 1980):
 * k tangent vectors carried along an orbit and re-orthonormalised by
 * modified Gram-Schmidt, each exponent the mean log stretching of its
 * vector; the Kaplan-Yorke dimension of the result (thesis (3.37)).
 *
 * Flows by their variational equations v' = Df(t, x) v, integrated with
 * the state by the flow's own GSL method and tolerances (Df v by central
 * differences of the field along v, steps 1e-7 max(1, |x|)); maps (a
 * flow's section or stroboscopic map included) by QR of DP, P's
 * Jacobian by central differences (models/map_periodic.h), each iterate.
 * Pure: nothing is shared between calls, so calls may run on several
 * threads. */
#ifndef CM_MODELS_LYAPUNOV_SPECTRUM_H
#define CM_MODELS_LYAPUNOV_SPECTRUM_H

#include <stddef.h>

#include "cellmap/model.h"

/* v: k vectors of length n, vector j at v[j n .. j n + n - 1], made
 * orthonormal in place by modified Gram-Schmidt; log_norm[j] gets the log
 * of vector j's length after the projections (the diagonal of R in
 * v = Q R). False when a vector vanishes or is not finite (the spectrum is
 * then undefined). */
bool cm_gram_schmidt(int n, int k, double *v, double *log_norm);

/* The first k exponents into decreasing order (Gram-Schmidt gives them
 * so in the limit; a finite run may not). */
void cm_sort_decreasing(double *lambda, int k);

/* The Kaplan-Yorke dimension j + (l_1 + ... + l_j) / |l_{j+1}| of k
 * exponents in decreasing order, j the largest with l_1 + ... + l_j >= 0;
 * 0 when l_1 < 0, NAN when all k sum to >= 0 (more exponents needed). */
double cm_kaplan_yorke(const double *lambda, int k);

/* How long, how often, and how many exponents. */
typedef struct cm_spectrum_options {
    int count;         /* exponents, 1..n (0: all n) */
    double transient;  /* flows: time before the sums start (vectors align meanwhile) */
    double time;       /* flows: the time the exponents are averaged over, > 0 */
    double renorm;     /* flows: time between Gram-Schmidt steps, > 0 */
    long iterations;   /* maps: iterates averaged over, > 0 */
    long skip;         /* maps: iterates of transient */
} cm_spectrum_options;

typedef struct cm_spectrum {
    int n, count;             /* the state's dimension, the exponents computed */
    double lambda[CM_MAX_DIM]; /* decreasing; flows per unit time, maps per iterate */
    double kaplan_yorke;      /* cm_kaplan_yorke of lambda */
    double time;              /* flows: the time averaged over; maps: the flow's time the
                                 iterates took (0 for a map that is not a flow's) */
    double x[CM_MAX_DIM];     /* the state at the end */
} cm_spectrum;

/* Called at every Gram-Schmidt step (flows) or every iterate (maps) after
 * the transient with the time (or iterate count) so far and the running
 * estimates (count of them, in the order of the vectors); nonzero stops
 * the run with CM_ECANCELED. */
typedef int (*cm_spectrum_trace)(void *user, double t, const double *lambda, int count);

/* The spectrum of m's flow (x0: cm_flow_dim(m) entries at time
 * m->flow.t0). CM_EINVAL for bad options, CM_EMODEL when the orbit is
 * lost (the field fails, leaves the world, the vectors collapse); msg
 * says which and when. */
cm_status cm_flow_spectrum(const cm_model *m, const double *x0, const cm_spectrum_options *o,
                           cm_spectrum_trace trace, void *user, cm_spectrum *out, char *msg,
                           size_t msg_size);

/* The spectrum of m's map (x0: m->dim entries), per iterate; for a flow's
 * map out->time is the flow's time the iterates took, so lambda / (time
 * / iterations) is per unit of it. Errors as cm_flow_spectrum's. */
cm_status cm_map_spectrum(const cm_model *m, const double *x0, const cm_spectrum_options *o,
                          cm_spectrum_trace trace, void *user, cm_spectrum *out, char *msg,
                          size_t msg_size);

#endif
