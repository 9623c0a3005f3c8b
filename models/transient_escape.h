/* models/transient_escape.h - the transient chaos of the 1-D micro-chaos
 * map with Coulomb friction (thesis 4.3, docs/models.md 4.1):
 *
 *     f(x) = a x - b Int(x) - c  (x > c/a),  0 on the dead zone,  (4.23)
 *
 * in the case of one positive fixed point x0* = c/(a - 1) < 1. Its chaotic
 * repeller lies in I_rep = [x0*, a - c]; a point escapes when an iterate
 * falls below x0* (into I0 = [a - b - c, x0*), from where the dead zone and
 * the rest at 0 follow). The mean number of steps to escape, over points
 * spread evenly on I_rep, four ways:
 *
 * - bounds from the repeller's fractal dimension (4.28)-(4.33): kappa =
 *   (1 - D0) ln a and N = 1/(1 - exp(-kappa)) (4.3), which assume the
 *   survivors decay exponentially from the first step;
 * - exactly, on the Markov partition that the orbit of a - c cuts I_rep
 *   into (our form of the thesis' recursive method, which it does not
 *   spell out): on each interval f is affine and its image a union of
 *   intervals, so the integrals of the escape number over the intervals
 *   solve a linear system;
 * - by an ensemble: kappa from the decay of survivors, and their mean;
 * - by cell mapping (in the command: step numbers of the sink cells).
 *
 * Pure functions. */
#ifndef CM_MODELS_TRANSIENT_ESCAPE_H
#define CM_MODELS_TRANSIENT_ESCAPE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct cm_te {
    double a, b, c;
    double I0;           /* |I0| (4.27) */
    double x0;           /* the fixed point c/(a - 1), I_rep's left end */
    double rep_hi;       /* a - c, I_rep's right end */
    double rep_len;      /* |I_rep| = b - |I0| */
    double F;            /* |F| (4.28); <= 0: the border state */
    double C[2];         /* the scaling factors C1, C2 (4.29) */
    double D0[2];        /* the roots of (4.32) for C1, C2 (D0[0] >= D0[1]); NaN: none */
    double kappa[2];     /* (1 - D0) ln a (4.33) */
    double n_esc[2];     /* 1/(1 - exp(-kappa)) (4.3): N from C1 >= N from C2 */
    double a_crit;       /* b/|I_rep| (4.34) */
    bool border;         /* |F| <= 0: D0 = 0 and N = a/(a - 1) (4.35) */
} cm_te;

/* c from |I0| (4.27): (|I0| + a - b)(a - 1)/a. */
double cm_te_c_of_I0(double a, double b, double I0);

/* The repeller's quantities at a, b, c; false, with the reason in why,
 * outside the case of 4.3 (a > 1, b > 0, c > 0, |I0| > 0, |I_rep| > 0,
 * x0* < 1, a - c < 2, and f maps I_rep into itself: no other fixed point
 * in it). */
bool cm_te_setup(double a, double b, double c, cm_te *t, char *why, size_t why_size);

/* f(x) of (4.23). */
double cm_te_map(const cm_te *t, double x);

/* The escape number of x: the applications of f until an iterate falls
 * below x0* (0 if x does already); -1 if it has not after cap. */
long cm_te_escape_number(const cm_te *t, double x, long cap);

/* The exact mean escape number over I_rep, and the number of intervals of
 * the Markov partition; false if the orbit of a - c stays in I_rep for
 * more than max_partition steps (a - c on the repeller, or nearly). */
bool cm_te_exact_mean(const cm_te *t, long max_partition, double *mean, long *partition);

/* The mean escape number of the midpoints of n equal cells of I_rep. */
double cm_te_grid_mean(const cm_te *t, long n);

typedef struct cm_te_ensemble {
    long points;
    double mean;         /* mean escape number */
    double kappa;        /* -slope of ln(survivors) against the step */
    int fit_from, fit_to; /* the steps of the fit: survivors from N/e down to 1000 */
} cm_te_ensemble;

/* An ensemble of n points uniformly at random in I_rep (a fixed generator
 * from seed: the same numbers on every machine). */
void cm_te_ensemble_run(const cm_te *t, long n, uint64_t seed, cm_te_ensemble *out);

#endif
