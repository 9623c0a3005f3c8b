/* models/friction_oscillator.h - the harmonically excited oscillator with
 * Coulomb friction and different static and kinetic coefficients (thesis
 * Chapter 2, eq. (2.3) with alpha = 0; docs/models.md 9):
 *
 *     x'' + x = cos(Omega t) - S f(x'),   f = sgn(x'), or in [-S0/S, S0/S] at rest.
 *
 * Between events the motion is known in closed form; only the velocity
 * zeros are found numerically (docs/models.md 9.4). Time inside the integrator
 * is local: s is measured from a section instant at which the forcing phase
 * is phi, so cos(Omega t) is evaluated as cos(phi + Omega s) and never loses
 * digits to a large t. All functions are pure; S0 >= S > 0, Omega > 0. */
#ifndef CM_MODELS_FRICTION_OSCILLATOR_H
#define CM_MODELS_FRICTION_OSCILLATOR_H

#include <stdbool.h>

typedef struct cm_fo {
    double S, S0, Omega;
    double phi;  /* forcing phase at s = 0: the section phase of the Poincare map */
    double T;    /* forcing period 2 pi/Omega */
    double step; /* velocity sampling step (2 pi/96)/max(1, Omega) (docs/models.md 9.4) */
} cm_fo;

void cm_fo_init(cm_fo *o, double S, double S0, double Omega, double phi);

/* Modes: sliding up (+1), sliding down (-1) or stuck (0). */
enum { CM_FO_STICK = 0, CM_FO_UP = 1, CM_FO_DOWN = -1 };

typedef struct cm_fo_state {
    double s, x, v; /* local time, displacement, velocity */
    int mode;
} cm_fo_state;

/* The mode of a state by docs/models.md 9.1: the sign of v, or at rest stuck
 * iff |cos(phi + Omega s) - x| < S0, else sliding along the net force. */
int cm_fo_mode_of(const cm_fo *o, double s, double x, double v);

enum cm_fo_event_kind {
    CM_FO_EV_STICK = 1, /* the velocity reaches zero and static friction holds */
    CM_FO_EV_TURN,      /* the velocity reaches zero and the block slides back */
    CM_FO_EV_BREAK      /* a stuck block starts to slide */
};

typedef struct cm_fo_event {
    double s, x; /* local time and place; the velocity there is 0 */
    int kind;    /* enum cm_fo_event_kind */
    int mode;    /* the mode after the event */
} cm_fo_event;

/* What happened during a propagation (docs/models.md 9.6). */
typedef struct cm_fo_tally {
    int n_stick, n_turn, n_break;
    double x_max, x_min; /* over the start, the events and the end */
    double x_zero_sum;   /* sum of x at the velocity zeros (stick and turn): Psi */
} cm_fo_tally;

/* Starts a tally at displacement x. */
void cm_fo_tally_start(cm_fo_tally *t, double x);

/* Called for every event, in time order; may be NULL. */
typedef void (*cm_fo_event_fn)(void *user, const cm_fo_event *e);

/* More events than this in one propagation: the run is given up. */
#define CM_FO_MAX_EVENTS 100000

/* Propagates *st (which keeps its mode) to local time s_end >= st->s,
 * tallying into *tally (may be NULL). Returns false when the motion cannot
 * be followed: a non-finite state or more than CM_FO_MAX_EVENTS events. */
bool cm_fo_propagate(const cm_fo *o, cm_fo_state *st, double s_end, cm_fo_tally *tally,
                     cm_fo_event_fn on_event, void *user);

/* The stroboscopic Poincare map P_phi: (x, v) at a section instant to
 * (x, v) one forcing period later; the mode is recomputed by
 * cm_fo_mode_of. tally and on_event may be NULL. */
bool cm_fo_poincare(const cm_fo *o, const double z[2], double out[2], cm_fo_tally *tally,
                    cm_fo_event_fn on_event, void *user);

/* A simulation on the thesis' time axis t, on which the forcing is
 * cos(Omega t): the state in the local time of the current forcing period,
 * which began at the section instant t_section = (phi + 2 pi k)/Omega.
 * Restarting local time every period keeps the phase exact over any
 * number of periods. */
typedef struct cm_fo_run {
    cm_fo_state st;
    long k;           /* the period's index */
    double t_section; /* the time at which it began */
} cm_fo_run;

/* Starts a run at time t0 from (x, v); the mode by cm_fo_mode_of. */
void cm_fo_run_start(const cm_fo *o, double t0, double x, double v, cm_fo_run *r);

/* Follows the run to the end of its period (the next section instant) and
 * starts the next period; events as for cm_fo_propagate, with times local
 * to the period that ends. Returns false when the motion is lost. */
bool cm_fo_run_period(const cm_fo *o, cm_fo_run *r, cm_fo_tally *tally, cm_fo_event_fn on_event,
                      void *user);

/* The Jacobian of P_phi at z (row-major) from the events of one period:
 * the free-flight rotations and the saltation matrices of turns, sticks and
 * breakaways (docs/models.md 9.7), and P_phi(z) itself into image (may be
 * NULL): the same propagation gives both. Returns false where P_phi is not
 * followed. */
bool cm_fo_monodromy(const cm_fo *o, const double z[2], double J[4], double image[2]);

/* A fixed point of P_phi by Newton's method from z (in place), with
 * central-difference Jacobians (step 1e-7) as docs/models.md 9.6 prescribes.
 * *residual receives |P(z) - z|. Returns false if it did not converge to
 * 1e-10 within max_iter iterations. */
bool cm_fo_fixed_point(const cm_fo *o, double z[2], int max_iter, double *residual);

/* The symmetric non-sticking solution (2.22)-(2.25): the turnaround
 * amplitude x0 and the phase Omega t0 of the turnaround (x0, 0). Returns
 * false where (2.25) has no real value (or Omega = 1). It is a solution only
 * where the slipping conditions (2.27), (2.29) hold; this does not check them. */
bool cm_fo_symmetric_amplitude(double S, double Omega, double *x0, double *phase);

/* The largest Lyapunov exponent by the renormalised two-trajectory
 * estimator of docs/models.md 9.8: separation d0 in x from (x0, v0) at local
 * time 0, samples every T/32 for `periods` periods. Returns false if no
 * sample was accepted or the motion was lost; *lambda may be -INFINITY
 * when the two trajectories merge. */
bool cm_fo_lyapunov(const cm_fo *o, double x0, double v0, double d0, int periods, double *lambda);

/* The oscillator behind a `friction-oscillator` model, or NULL for any
 * other model. */
struct cm_model;
const cm_fo *cm_fo_of_model(const struct cm_model *m);

#endif
