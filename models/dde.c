/* Delay differential equations by the method of steps over GSL's
 * Runge-Kutta steppers (models/dde.h). */
#include "models/dde.h"

#include <float.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/ode_flow.h"
#include "models/ode_steps.h"

/* One accepted point of the solution: time, state and rate. */
typedef struct knot {
    double t;
    double x[CM_DDE_MAX_DIM], f[CM_DDE_MAX_DIM];
} knot;

/* The solution accepted so far (the knots covering at least the last
 * delay) and what the GSL system's field needs to read it. */
typedef struct run {
    const cm_dde *d;
    double t0;
    knot *k;
    size_t n, cap, first; /* knots first..n-1 are live */
} run;

/* x(t) for t within the live knots or before t0, by the cubic Hermite
 * interpolant of the knots around t. */
static void value_at(run *r, double t, double *x)
{
    const int dim = r->d->dim;
    if (t <= r->t0 || r->n == 0) {
        r->d->history(r->d->ctx, fmin(t, r->t0), x);
        return;
    }
    /* the last knot at or before t (binary search over the live ones) */
    size_t lo = r->first, hi = r->n - 1;
    if (t >= r->k[hi].t) {
        memcpy(x, r->k[hi].x, (size_t)dim * sizeof *x);
        return;
    }
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (r->k[mid].t <= t)
            lo = mid;
        else
            hi = mid;
    }
    const knot *a = &r->k[lo], *b = &r->k[hi];
    const double h = b->t - a->t, s = (t - a->t) / h, s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2,
                 h11 = s3 - s2;
    for (int i = 0; i < dim; i++)
        x[i] = h00 * a->x[i] + h10 * h * a->f[i] + h01 * b->x[i] + h11 * h * b->f[i];
}

static int field_gsl(double t, const double y[], double f[], void *params)
{
    run *r = params;
    double xd[CM_DDE_MAX_DIM];
    value_at(r, t - r->d->delay, xd);
    /* a failure is cm_ode_step's to handle: it tries a shorter step */
    return r->d->field(r->d->ctx, t, y, xd, f) ? GSL_EBADFUNC : GSL_SUCCESS;
}

/* Appends the knot (t, x) with its rate, dropping the knots more than a
 * delay (and one knot) behind: CM_ENOMEM, or CM_EMODEL where the field
 * fails. */
static cm_status add_knot(run *r, double t, const double *x)
{
    const cm_dde *d = r->d;
    while (r->first + 1 < r->n && r->k[r->first + 1].t < t - d->delay)
        r->first++;
    if (r->n == r->cap) {
        if (r->first > r->n / 2) { /* slide the live knots down rather than grow */
            memmove(r->k, r->k + r->first, (r->n - r->first) * sizeof *r->k);
            r->n -= r->first, r->first = 0;
        } else {
            const size_t cap = r->cap ? 2 * r->cap : 1024;
            knot *k = realloc(r->k, cap * sizeof *k);
            if (!k)
                return CM_ENOMEM;
            r->k = k, r->cap = cap;
        }
    }
    knot *k = &r->k[r->n];
    k->t = t;
    memcpy(k->x, x, (size_t)d->dim * sizeof *x);
    double xd[CM_DDE_MAX_DIM];
    value_at(r, t - d->delay, xd);
    if (d->field(d->ctx, t, x, xd, k->f))
        return CM_EMODEL;
    r->n++;
    return CM_OK;
}

static cm_status check(const cm_dde *d, double t0, double t1, double dt, char *msg,
                       size_t msg_size)
{
    if (!(d->delay > 0) || !isfinite(d->delay))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the delay must be a positive number (it is %g): give delay > 0", d->delay);
    if (d->dim < 1 || d->dim > CM_DDE_MAX_DIM || !d->field || !d->history)
        return cm_fail(CM_EINVAL, msg, msg_size, "a delay equation needs 1..%d coordinates, a "
                       "field and a history", CM_DDE_MAX_DIM);
    if (!(t1 > t0) || !isfinite(t0) || !isfinite(t1) || !(dt > 0) || (t1 - t0) / dt > 1e9)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the run needs t1 > t0 and a sample interval dt > 0 with at most 1e9 "
                       "samples (t0 %g, t1 %g, dt %g)",
                       t0, t1, dt);
    if (d->method > CM_FLOW_RK4)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "delay equations take the explicit methods (rk8pd, rkf45, rkck, rk4)");
    return CM_OK;
}

/* The next time a step must land on after t: a propagated breakpoint of
 * the history, the model's own, the next sample, t1. */
static double next_stop(const cm_dde *d, double t0, double t, double sample)
{
    double stop = sample;
    const double j = floor((t - t0) / d->delay + 1e-9) + 1;
    if (j <= CM_DDE_BREAKS)
        stop = fmin(stop, t0 + j * d->delay);
    if (d->next_break)
        stop = fmin(stop, d->next_break(d->ctx, t));
    return stop;
}

cm_status cm_dde_solve(const cm_dde *d, double t0, double t1, double dt, cm_dde_observer observe,
                       void *user, double *x1, char *msg, size_t msg_size)
{
    cm_status st = check(d, t0, t1, dt, msg, msg_size);
    if (st != CM_OK)
        return st;
    run r = {.d = d, .t0 = t0};
    const int dim = d->dim;
    gsl_odeiv2_system sys = {field_gsl, NULL, (size_t)dim, &r};
    const double abs_tol = d->abs_tol > 0 ? d->abs_tol : 1e-9,
                 rel_tol = d->rel_tol > 0 ? d->rel_tol : 1e-9;
    gsl_odeiv2_driver *drv = gsl_odeiv2_driver_alloc_y_new(&sys, cm_flow_stepper(d->method),
                                                           fmin(1e-3, d->delay / 8), abs_tol,
                                                           rel_tol);
    double x[CM_DDE_MAX_DIM], saved[CM_DDE_MAX_DIM], t = t0, h = fmin(1e-3, d->delay / 8);
    d->history(d->ctx, t0, x);
    int rc = 0;
    st = drv ? add_knot(&r, t, x) : CM_ENOMEM;
    if (st == CM_OK && observe)
        rc = observe(user, t, x);
    for (long s = 1; st == CM_OK && rc == 0 && t < t1; s++) {
        const double sample = fmin(t0 + (double)s * dt, t1);
        while (st == CM_OK && t < sample) {
            /* a step no longer than the delay, landing on the next stop */
            const double stop = fmin(next_stop(d, t0, t, sample), t + d->delay);
            if (stop - t <= 8 * DBL_EPSILON * fabs(stop)) {
                t = stop;
                continue;
            }
            if (!cm_ode_step(drv, (size_t)dim, &t, stop, &h, x, saved)) {
                st = CM_EMODEL;
                break;
            }
            st = add_knot(&r, t, x);
            if (t == stop && st == CM_OK)
                cm_ode_restart(drv); /* a jump may follow: start the next step afresh */
        }
        if (st == CM_OK && observe)
            rc = observe(user, t, x);
    }
    if (st == CM_OK && x1)
        memcpy(x1, x, (size_t)dim * sizeof *x);
    if (st == CM_EMODEL)
        cm_fail(st, msg, msg_size,
                "the delay equation's solution was lost at t = %.9g (the field failed or the "
                "state is not finite): tighten the tolerances or shorten the run",
                t);
    else if (st == CM_ENOMEM)
        cm_fail(st, msg, msg_size, "out of memory for the delay equation's history");
    if (drv)
        gsl_odeiv2_driver_free(drv);
    free(r.k);
    if (st == CM_OK && rc)
        st = cm_fail(CM_ECANCELED, msg, msg_size, "stopped at t = %.9g", t);
    return st;
}
