/* GSL's evolution with retries on overflow (models/ode_steps.h). */
#include "models/ode_steps.h"

#include <float.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <string.h>

void cm_ode_restart(gsl_odeiv2_driver *d)
{
    gsl_odeiv2_evolve_reset(d->e);
    gsl_odeiv2_step_reset(d->s);
}

bool cm_ode_step(gsl_odeiv2_driver *d, size_t size, double *t, double t1, double *h, double *y,
                 double *saved)
{
    memcpy(saved, y, size * sizeof *y);
    const double t_was = *t;
    for (;;) {
        const double h_was = *h;
        bool ok = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, d->sys, t, t1, h, y) == GSL_SUCCESS;
        for (size_t i = 0; i < size && ok; i++)
            ok = isfinite(y[i]);
        if (ok) {
            if (*t == t1 && *h < h_was)
                *h = h_was;
            return true;
        }
        const double tried = fmin(h_was, t1 - t_was);
        if (!(tried > 1e-12))
            return false;
        *t = t_was;
        *h = 0.1 * tried;
        memcpy(y, saved, size * sizeof *y);
        cm_ode_restart(d);
    }
}

bool cm_ode_advance(gsl_odeiv2_driver *d, size_t size, double *t, double t1, double *h, double *y,
                    double *saved)
{
    while (*t < t1) {
        if (t1 - *t <= 8 * DBL_EPSILON * fabs(t1)) {
            *t = t1;
            break;
        }
        if (!cm_ode_step(d, size, t, t1, h, y, saved))
            return false;
    }
    return true;
}
