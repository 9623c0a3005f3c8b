/* models/fo_sync.h - the synchronisation estimate of the largest Lyapunov
 * exponent of the dry friction oscillator (Stefanski and Kapitaniak 2003;
 * thesis 2.6.1, Fig. 2.23): the oscillator (x1, x2) drives a copy
 * (x3, x4) through a one-way coupling q,
 *
 *     x1' = x2,                  x2' = -x1 + cos(Omega t) - S f(x2),
 *     x3' = x4 + q (x1 - x3),    x4' = -x3 + cos(Omega t) - S f(x4) + q (x2 - x4),
 *
 * f the set-valued Coulomb law of each block's own velocity (the thesis
 * prints f(x1), f(x3): friction acts on velocities), a block at rest
 * staying at rest while its net force is within S0. The smallest q at
 * which the copy falls onto the oscillator (x1 - x3 -> 0) bounds the
 * largest exponent from above.
 *
 * The pair is integrated together by RK4 in steps of T/steps, each event
 * (a velocity zero: rest or turn; a block at rest sliding off) located by
 * bisection on the step to 1e-13 and both blocks switched there, so that
 * a copy that has synchronised stays exactly on the oscillator; event
 * times, not a fixed grid, carry the sensitivity to initial states (a
 * first-order grid that rests a block for a whole step contracts nearby
 * orbits: no chaos left to measure). The
 * forcing's phase is 0 at t = 0. Pure; thread-safe. */
#ifndef CM_MODELS_FO_SYNC_H
#define CM_MODELS_FO_SYNC_H

#include <stdbool.h>

typedef struct cm_fo_sync {
    double S, S0, Omega;
    int steps;                /* time steps per excitation period (>= 100) */
    int transient, record;    /* periods left to settle, then watched */
    double start[2];          /* the oscillator's (x, v) at t = 0 */
    double copy_offset[2];    /* the copy's start minus the oscillator's */
} cm_fo_sync;

/* One run at coupling q: x1 - x3 at the end of each recorded period into
 * gaps[0..record) (may be NULL), and the largest |x1 - x3| and |x2 - x4|
 * over every step of the recorded periods, returned. */
double cm_fo_sync_run(const cm_fo_sync *c, double q, double *gaps);

/* A copy counts as synchronised when that largest difference is below
 * this (the attractor spans about 1). */
#define CM_FO_SYNC_TOL 1e-8

#endif
