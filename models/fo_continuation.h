/* models/fo_continuation.h - continuation of the friction oscillator's
 * periodic solutions (thesis 2.5, docs/models.md 9.9): period-k fixed
 * points of the Poincare map P followed in one parameter by
 * pseudo-arclength continuation with Newton on P^k(z) - z (the exact
 * monodromy of cm_fo_monodromy), their Floquet multipliers, and the
 * events along a branch: folds (SN), period doublings (PD), Neimark-Sacker
 * points (NS) and changes of the solution's signature (the order of its
 * slip and stick segments), each located on the branch. Pure functions. */
#ifndef CM_MODELS_FO_CONTINUATION_H
#define CM_MODELS_FO_CONTINUATION_H

#include <stdbool.h>

#include "models/friction_oscillator.h"

/* The parameters a branch can follow. */
enum cm_fo_param { CM_FO_P_S = 0, CM_FO_P_S0, CM_FO_P_OMEGA, CM_FO_P_PHI };

/* The parameter named "S", "S0", "Omega" or "phi", or -1. */
int cm_fo_param_of(const char *name);
const char *cm_fo_param_name(int param);

/* The oscillator o with parameter `param` set to p. */
void cm_fo_with(const cm_fo *o, int param, double p, cm_fo *out);

enum { CM_FO_SIGNATURE = 96, CM_FO_MAX_STOPS = 16 };

/* A periodic solution: z = (x, v) at the section of phase phi, a fixed
 * point of P^period there. */
typedef struct cm_fo_solution {
    double p;          /* the parameter's value */
    double phi;        /* the section's forcing phase */
    double z[2];
    int period;        /* excitation periods */
    double mult[2][2]; /* Floquet multipliers (re, im), |first| >= |second| */
    bool stable;       /* both multipliers inside the unit circle */
    double x_max, x_min;
    double psi;        /* the sum of x at the velocity zeros over the period (thesis 2.6.1;
                          signed: mirror images have opposite signs) */
    double asymmetry;  /* the thesis' Psi (2.90): |(x_max + x_min) / (x_max - x_min)| */
    int n_stick;       /* sticking segments per period */
    int n_stops;
    double stops[CM_FO_MAX_STOPS]; /* x where the block sticks, in time order */
    bool symmetric;    /* |psi| below 1e-6 */
    /* the modes in time order, u (up), d (down), s (stuck), as a cycle:
     * the rotation that comes first alphabetically, so that it does not
     * depend on the section's phase */
    char signature[CM_FO_SIGNATURE];
} cm_fo_solution;

/* Evaluates the solution at o (parameter already set), z and period:
 * everything but p. false where P^period cannot be followed. */
bool cm_fo_solution_at(const cm_fo *o, const double z[2], int period, cm_fo_solution *out);

/* A fixed point of P^period near z (in place) by Newton's method with the
 * exact monodromy; false if it does not converge to 1e-11. */
bool cm_fo_periodic_point(const cm_fo *o, double z[2], int period);

/* The smallest d dividing k for which the fixed point z of P^k is a fixed
 * point of P^d (to 1e-9): its true period; 0 where P cannot be followed. */
int cm_fo_minimal_period(const cm_fo *o, const double z[2], int k);

/* The smallest period 1..max_period of the orbit that a simulation of
 * `settle` periods from z settles on, and a point of it in z (in place);
 * 0 if none (chaotic, or the motion was lost). */
int cm_fo_find_periodic(const cm_fo *o, double z[2], int settle, int max_period);

/* The kinds of events on a branch. */
enum cm_fo_event_type {
    CM_FO_EVENT_SN = 0, /* a real multiplier through +1 (a fold where the branch turns back,
                           else a branch point, as the thesis' SN_2s) */
    CM_FO_EVENT_PD,     /* a multiplier through -1 */
    CM_FO_EVENT_NS,     /* a complex pair through the unit circle */
    CM_FO_EVENT_CS,     /* sticking segments appear, vanish or change neighbours
                           (crossing-sliding and the like) */
    CM_FO_EVENT_T,      /* only slip segments appear or vanish, or (at a branch's
                           end, jump set) a slip segment grazes v = 0 */
    CM_FO_EVENT_SS      /* a pause appears or vanishes: a stick between two slips
                           the same way (switching sliding, the thesis' SS_a) */
};
/* "SN", "PD", "NS", "CS", "T", "SS". */
const char *cm_fo_event_name(int type);

typedef struct cm_fo_branch_event {
    int type;
    bool fold;                    /* SN: the branch turns back in the parameter */
    bool touch;                   /* SN: the multiplier only touches +1 there (the side
                                     branch of a branch point, which turns back at it) */
    bool jump;                    /* CS, T at a branch's end: P^period jumps just past
                                     it (a slip segment grazes v = 0 in the stick band) */
    /* the located point, described by the solution before it: SN, PD, NS
     * at the test function's zero (interpolated), CS and T at the last
     * point with the signature before */
    cm_fo_solution at;
    cm_fo_solution other; /* the nearest point found on the other side; at a
                             branch's end (CM_FO_STOP_SIGNATURE) none was
                             found, and other is at */
    double width;         /* |at.p - other.p|: how far the bracket closed */
    char before[CM_FO_SIGNATURE]; /* signatures on either side (CS, T) */
    char after[CM_FO_SIGNATURE];
} cm_fo_branch_event;

/* Why a branch ended. */
enum cm_fo_stop {
    CM_FO_STOP_BOUND = 0, /* the parameter left [lo, hi] */
    CM_FO_STOP_POINTS,    /* max_points reached */
    CM_FO_STOP_STEP,      /* the corrector failed down to the smallest step, or
                             took 200 steps in a row no longer than 1e-6 */
    CM_FO_STOP_LOST,      /* P^period cannot be followed (motion lost) */
    CM_FO_STOP_SIGNATURE, /* the corrector fails where the signature changes
                             or the map jumps just ahead: a segment grazes a
                             boundary and no smooth continuation exists
                             (reported as an event at the last point) */
    CM_FO_STOP_LOOP       /* the branch came back to its start, in the parameter
                             and x range: a closed loop (an isola), all of it
                             followed; or, on a branch from a period doubling,
                             the other point of the same orbit */
};
const char *cm_fo_stop_name(int stop);

typedef struct cm_fo_continue_options {
    int param;
    double lo, hi;    /* the parameter's range */
    double direction; /* +1: the parameter grows first, -1: it shrinks */
    double h0, h_min, h_max; /* arclength steps (0: 1e-3, 1e-9, 2e-2) */
    int max_points;   /* 0: 5000 */
} cm_fo_continue_options;

/* Called for each branch point and each event, in branch order; nonzero
 * stops the continuation (returned as CM_FO_STOP_POINTS). */
typedef int (*cm_fo_point_fn)(void *user, const cm_fo_solution *s);
typedef int (*cm_fo_event_fn2)(void *user, const cm_fo_branch_event *e);

/* The amplitude-frequency analysis of thesis 2.2 (Figs. 2.4, 2.6, 2.7,
 * 2.12-2.14) at one frequency, for the oscillator o (its Omega): */
typedef struct cm_fo_amplitude {
    double x0;         /* (2.25); NaN where it is imaginary */
    double slip_limit; /* S0/Omega^2: (2.27) wants x0 at least this */
    double turn_limit; /* S H_max (2.29): two turnarounds want x0 at least this */
    bool valid;        /* x0 real and both conditions hold */
    /* where valid: the symmetric non-sticking solution's multipliers by
     * the exact monodromy, and whether it is stable; else NaN, false */
    double mult_max;   /* the largest modulus */
    bool stable;
    /* a simulation from the thesis' start (1 + 0.9 S0, 0): the half range
     * of x and the sticking segments per period over the last `record` of
     * `periods` periods (NaN if the motion was lost) */
    double sim_amplitude, sim_sticks;
} cm_fo_amplitude;

/* H_max of (2.29): max over t in (0, pi/Omega) of H(t, Omega), 1/Omega^2 at
 * t -> 0 included; sampled finely enough for the figures (4000 points). */
double cm_fo_turn_hmax(double Omega);

/* H(t, Omega) of (2.29) itself (Fig. 2.5; NaN or infinite where its
 * denominator vanishes), and H_max with the t where it is taken (0: the
 * limit 1/Omega^2 at t -> 0). */
double cm_fo_turn_h(double t, double Omega);
double cm_fo_turn_hmax_at(double Omega, double *t_max);

void cm_fo_amplitude_at(const cm_fo *o, int periods, int record, cm_fo_amplitude *out);

/* Two-parameter continuation of an SN, PD, CS or SS event e (located on
 * a branch in `param`): the curve in the plane of `param` and `param2` on
 * which the period-k solution keeps a multiplier +1 (SN) or -1 (PD), or
 * keeps a velocity zero on the stick-slip boundary |cos - x| = S0 (CS, SS:
 * where a stick is born or dies; an event that is a grazing of v = 0
 * instead gives no curve). Unknowns x, v, p, p2; equations P^k(z) - z = 0
 * and det(M -+ I) = 0 or the boundary's gap = 0; pseudo-arclength with a
 * Jacobian by central differences, from e both ways (direction +1: param2
 * grows first) until either parameter leaves its range or max_points are
 * made. on_point gets (p, p2, z) in order; returns the number of points
 * (0 where e gives no curve). */
typedef int (*cm_fo_curve_fn)(void *user, double p, double p2, const double z[2]);
int cm_fo_continue_curve(const cm_fo *o, const cm_fo_branch_event *e, int param, int param2,
                         const double lo[2], const double hi[2], int direction, int max_points,
                         cm_fo_curve_fn on_point, void *user);

/* Branch switching at a period doubling e (of a period-k branch in
 * `param`): a period-2k solution near it, off the period-k one along the
 * eigenvector of the multiplier -1, at a parameter value just past the
 * event on whichever side has one. Its state goes to z, its parameter value
 * to *p; false if none is found. */
bool cm_fo_period_doubled(const cm_fo *o, int param, const cm_fo_branch_event *e, double z[2],
                          double *p);

/* Continues the period-k solution through z at parameter value p0 (z
 * must be a fixed point of P^period to 1e-9: cm_fo_periodic_point). The
 * section's phase moves (unless it is the parameter) to where the solution
 * slides fastest, at the start and wherever the corrector fails: a
 * section inside a sticking segment makes P non-smooth there. The stop
 * reason goes to *stop. Returns the number of points. */
int cm_fo_continue(const cm_fo *o, const cm_fo_continue_options *opt, double p0,
                   const double z[2], int period, cm_fo_point_fn on_point,
                   cm_fo_event_fn2 on_event, void *user, int *stop);

#endif
