/* models/fo_transients.c - perturbations of periodic solutions of the
 * friction oscillator (models/fo_transients.h). */
#include "models/fo_transients.h"

#include <complex.h>
#include <math.h>
#include <stddef.h>

/* The events of a run: the first stick after a turnaround. */
typedef struct stick_after_turn {
    bool turned, done;
    double x;
} stick_after_turn;

static void on_event(void *user, const cm_fo_event *e)
{
    stick_after_turn *s = user;
    if (s->done)
        return;
    if (e->kind == CM_FO_EV_TURN)
        s->turned = true;
    else if (e->kind == CM_FO_EV_STICK && s->turned)
        s->done = true, s->x = e->x;
}

double cm_fo_extremal_next(const cm_fo *o, double eps)
{
    cm_fo at_max; /* the section at the forcing's maximum, t = 0 */
    cm_fo_init(&at_max, o->S, o->S0, o->Omega, 0);
    cm_fo_run r;
    cm_fo_run_start(&at_max, 0, 1 + o->S - eps, 0, &r);
    stick_after_turn s = {false, false, NAN};
    for (int k = 0; k < 2 && !s.done; k++)
        if (!cm_fo_run_period(&at_max, &r, NULL, on_event, &s))
            return NAN;
    return s.done ? 1 + o->S - s.x : NAN;
}

bool cm_fo_converge(const cm_fo *o, const double z0[2], int settle, int periods, double *err,
                    cm_fo_convergence *out)
{
    double z[2] = {z0[0], z0[1]}, res;
    for (int k = 0; k < settle; k++)
        if (!cm_fo_poincare(o, z, z, NULL, NULL, NULL))
            return false;
    double J[4];
    if (!cm_fo_fixed_point(o, z, 50, &res) || !cm_fo_monodromy(o, z, J, NULL))
        return false;
    out->z_star[0] = z[0], out->z_star[1] = z[1];
    const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2];
    const double complex root = csqrt(tr * tr / 4 - det);
    const double complex l1 = tr / 2 + root, l2 = tr / 2 - root;
    const double complex lead = cabs(l1) >= cabs(l2) ? l1 : l2;
    out->mult_max = cabs(lead), out->mult_arg = fabs(carg(lead));
    const double scale = hypot(z[0], z[1]);
    double y[2] = {z0[0], z0[1]};
    for (int n = 0; n <= periods; n++) {
        err[n] = hypot(y[0] - z[0], y[1] - z[1]) / scale;
        if (n < periods && !cm_fo_poincare(o, y, y, NULL, NULL, NULL))
            return false;
    }
    return true;
}
