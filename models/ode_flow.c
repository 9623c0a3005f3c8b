/* The maps of ODE flows: cm_flow integrated with GSL's gsl_odeiv2 evolve
 * framework (docs/models.md 11). One integration per start, from t0 with
 * the same first step, so step and step_n agree bit for bit and a cell's
 * image never depends on the cells integrated before it. */
#include "models/ode_flow.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <math.h>
#include <string.h>

#include "models/params.h"

/* What one thread integrates with: GSL's driver, which owns the stepper
 * (driver->s), error control (->c) and evolution (->e) (the implicit
 * steppers reach the control through it), allocated once per step_n
 * batch. w->sys must stay where work_open put it: the driver points to
 * it. */
typedef struct flow_work {
    gsl_odeiv2_driver *driver;
    gsl_odeiv2_system sys;
    const cm_model *m;
    int n; /* the flow's dimension */
    long steps;
} flow_work;

static int field_gsl(double t, const double y[], double f[], void *params)
{
    const cm_model *m = params;
    /* GSL_EBADFUNC ends the integration at once (any other error would
     * make GSL retry with a smaller step) */
    return m->flow.field(m, t, y, f) == 0 ? GSL_SUCCESS : GSL_EBADFUNC;
}

static bool finite_state(int n, const double *y)
{
    for (int d = 0; d < n; d++)
        if (!isfinite(y[d]))
            return false;
    return true;
}

/* f at (t, x) with x_j moved by h (x unchanged on return); nonzero where
 * the field fails or is not finite. */
static int field_moved(const cm_model *m, double t, double *x, int j, double h, double *f)
{
    const double keep = x[j];
    x[j] = keep + h;
    const int rc = m->flow.field(m, t, x, f);
    x[j] = keep;
    return rc || !finite_state(cm_flow_dim(m), f);
}

cm_status cm_flow_jacobian_at(const cm_model *m, double t, const double *x, double *J)
{
    const int n = cm_flow_dim(m);
    double xs[CM_MAX_DIM], fp[CM_MAX_DIM], fm[CM_MAX_DIM];
    memcpy(xs, x, (size_t)n * sizeof *x);
    for (int j = 0; j < n; j++) {
        const double h = 1e-7 * fmax(1, fabs(x[j]));
        if (field_moved(m, t, xs, j, h, fp) || field_moved(m, t, xs, j, -h, fm))
            return CM_EMODEL;
        for (int i = 0; i < n; i++)
            J[i * n + j] = (fp[i] - fm[i]) / (2 * h);
    }
    return CM_OK;
}

/* The implicit steppers' Jacobian df/dx and df/dt, by central differences. */
static int jacobian_gsl(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
    const cm_model *m = params;
    const int n = cm_flow_dim(m);
    if (cm_flow_jacobian_at(m, t, y, dfdy) != CM_OK)
        return GSL_EBADFUNC;
    double fp[CM_MAX_DIM], fm[CM_MAX_DIM];
    const double h = 1e-7 * fmax(1, fabs(t));
    if (m->flow.field(m, t + h, y, fp) || m->flow.field(m, t - h, y, fm))
        return GSL_EBADFUNC;
    for (int i = 0; i < n; i++)
        dfdt[i] = (fp[i] - fm[i]) / (2 * h);
    return GSL_SUCCESS;
}

const gsl_odeiv2_step_type *cm_flow_stepper(int method)
{
    switch (method) {
    case CM_FLOW_RKF45: return gsl_odeiv2_step_rkf45;
    case CM_FLOW_RKCK: return gsl_odeiv2_step_rkck;
    case CM_FLOW_RK4: return gsl_odeiv2_step_rk4;
    case CM_FLOW_MSBDF: return gsl_odeiv2_step_msbdf;
    case CM_FLOW_RK4IMP: return gsl_odeiv2_step_rk4imp;
    case CM_FLOW_BSIMP: return gsl_odeiv2_step_bsimp;
    default: return gsl_odeiv2_step_rk8pd;
    }
}

static void work_close(flow_work *w)
{
    if (w->driver)
        gsl_odeiv2_driver_free(w->driver);
}

static bool work_open(flow_work *w, const cm_model *m)
{
    memset(w, 0, sizeof *w);
    w->m = m;
    w->n = cm_flow_dim(m);
    w->sys = (gsl_odeiv2_system){field_gsl, jacobian_gsl, (size_t)w->n, (void *)m};
    /* the first step is set per integration (first_step) */
    w->driver = gsl_odeiv2_driver_alloc_y_new(&w->sys, cm_flow_stepper(m->flow.method), 1e-3,
                                              m->flow.abs_tol, m->flow.rel_tol);
    return w->driver != NULL;
}

static bool in_world(const cm_model *m, const double *y)
{
    for (int d = 0; d < cm_flow_dim(m); d++)
        if (!(y[d] >= -m->flow.world && y[d] <= m->flow.world)) /* NaN fails too */
            return false;
    return true;
}

/* The first step GSL tries: a fraction of the period (or of a time unit
 * for an autonomous section), and at most a hundredth of the time the
 * field takes to change the state by its own size (|y| + 1), so that a
 * long period (omega = 0.001: 98 time units) does not start with a step
 * over which the state overflows; the error control adapts it from there. */
static double first_step(const cm_model *m, double t, const double *y, double span)
{
    const cm_flow *f = &m->flow;
    double h = (f->period > 0 ? f->period : 1.0) / 64;
    double dydt[CM_MAX_DIM], scale = 0, rate = 0;
    if (f->field(m, t, y, dydt) == 0)
        for (int d = 0; d < cm_flow_dim(m); d++) {
            scale = fmax(scale, fabs(y[d]) + 1);
            rate = fmax(rate, fabs(dydt[d]));
        }
    if (rate > 0 && isfinite(rate))
        h = fmin(h, 0.01 * scale / rate);
    return h < span ? h : span;
}

/* Forgets the steps taken: the next one starts a new integration. */
static void restart(flow_work *w)
{
    gsl_odeiv2_evolve_reset(w->driver->e);
    gsl_odeiv2_step_reset(w->driver->s);
}

/* One accepted step towards t1 from (*t, y); false when the orbit has no
 * image (the field failed, the world was left, too many steps). A step
 * GSL accepts with a non-finite state (its error estimate NaN, which its
 * control takes as small) is taken back and tried again ten times
 * shorter: only a state beyond the world, or non-finite at steps below
 * 1e-12 of the period, is a blow-up. */
static bool advance(flow_work *w, double *t, double t1, double *h, double *y)
{
    const int dim = w->n;
    const double t0 = *t, shortest = 1e-12 * (w->m->flow.period > 0 ? w->m->flow.period : 1.0);
    double y0[CM_MAX_DIM];
    memcpy(y0, y, (size_t)dim * sizeof *y);
    for (;;) {
        if (gsl_odeiv2_evolve_apply(w->driver->e, w->driver->c, w->driver->s, &w->sys, t, t1, h,
                                    y) != GSL_SUCCESS)
            return false;
        if (++w->steps > CM_FLOW_MAX_STEPS)
            return false;
        if (finite_state(dim, y))
            return in_world(w->m, y);
        const double tried = *t - t0;
        if (!(tried > shortest))
            return false;
        *t = t0;
        *h = 0.1 * tried;
        memcpy(y, y0, (size_t)dim * sizeof *y);
        restart(w);
    }
}

/* y from time *t on to t1 (> *t) with steps from *h, as a run goes on. */
static bool integrate_on(flow_work *w, double *t, double t1, double *h, double *y)
{
    while (*t < t1)
        if (!advance(w, t, t1, h, y))
            return false;
    return true;
}

/* y from time t to time t1 (> t), afresh. */
static bool integrate(flow_work *w, double t, double t1, double *y)
{
    restart(w);
    double h = first_step(w->m, t, y, t1 - t);
    return integrate_on(w, &t, t1, &h, y);
}

/* g(t, y): the section function, or x_k - level for a plane. */
static double section_value(const cm_model *m, double t, const double *y)
{
    const cm_flow *f = &m->flow;
    return f->plane ? y[f->plane - 1] - f->level : f->section(m, t, y);
}

static bool has_section(const cm_flow *f) { return f->section || f->plane; }

/* Whether g went from a to b across the section in the flow's direction
 * (to >= 0 going up, to <= 0 going down). */
static bool crossed(int direction, double a, double b)
{
    const bool up = a < 0 && b >= 0, down = a > 0 && b <= 0;
    return direction > 0 ? up : direction < 0 ? down : up || down;
}

/* The crossing between (ta, ya) and (tb, yb) located to event_tol in time
 * by the Illinois variant of regula falsi, each trial point integrated
 * from ta; the point on the far side of the section goes to y. */
static bool locate(flow_work *w, double ta, const double *ya, double tb, const double *yb,
                   double *y, double *t_end)
{
    const cm_model *m = w->m;
    const size_t bytes = (size_t)w->n * sizeof(double);
    double a[CM_MAX_DIM], b[CM_MAX_DIM], trial[CM_MAX_DIM];
    memcpy(a, ya, bytes);
    memcpy(b, yb, bytes);
    double ga = section_value(m, ta, a), gb = section_value(m, tb, b);
    int kept = 0; /* which end stayed last time: -1 a, +1 b */
    for (int it = 0; it < 200 && tb - ta > m->flow.event_tol; it++) {
        double tm = gb != ga ? (ta * gb - tb * ga) / (gb - ga) : 0.5 * (ta + tb);
        if (!(tm > ta && tm < tb))
            tm = 0.5 * (ta + tb);
        memcpy(trial, a, bytes);
        if (!integrate(w, ta, tm, trial))
            return false;
        const double gm = section_value(m, tm, trial);
        if (crossed(m->flow.direction ? m->flow.direction : (ga < 0 ? 1 : -1), ga, gm)) {
            tb = tm, gb = gm;
            memcpy(b, trial, bytes);
            if (kept == -1)
                ga *= 0.5; /* Illinois: the end that stays twice counts half */
            kept = -1;
        } else {
            ta = tm, ga = gm;
            memcpy(a, trial, bytes);
            if (kept == 1)
                gb *= 0.5;
            kept = 1;
        }
    }
    memcpy(y, b, bytes);
    *t_end = tb;
    return true;
}

void cm_flow_lift(const cm_model *m, const double *x, double *y)
{
    const int k = m->flow.plane - 1;
    for (int d = 0, i = 0; d < cm_flow_dim(m); d++)
        y[d] = d == k ? m->flow.level : x[i++];
}

/* The reverse: the map's state of the flow's state y. */
static void drop(const cm_model *m, const double *y, double *x)
{
    const int k = m->flow.plane - 1;
    for (int d = 0, i = 0; d < cm_flow_dim(m); d++)
        if (d != k)
            x[i++] = y[d];
}

/* dg/dt along the flow at (t, y): the plane's coordinate's rate, or a
 * central difference of the section function along the field; NAN where
 * the field fails. */
static double section_rate(const cm_model *m, double t, const double *y)
{
    const int n = cm_flow_dim(m);
    double f[CM_MAX_DIM], ahead[CM_MAX_DIM], back[CM_MAX_DIM];
    if (m->flow.field(m, t, y, f))
        return NAN;
    if (m->flow.plane)
        return f[m->flow.plane - 1];
    const double d = 1e-7 * fmax(1, fabs(t));
    for (int i = 0; i < n; i++)
        ahead[i] = y[i] + d * f[i], back[i] = y[i] - d * f[i];
    return (m->flow.section(m, t + d, ahead) - m->flow.section(m, t - d, back)) / (2 * d);
}

/* g at one end of a step: the time, the state, g and its rate. */
typedef struct step_end {
    double t, g, rate;
    double y[CM_MAX_DIM];
} step_end;

static void step_end_at(const cm_model *m, double t, const double *y, step_end *e)
{
    e->t = t;
    memcpy(e->y, y, (size_t)cm_flow_dim(m) * sizeof *y);
    e->g = section_value(m, t, y);
    e->rate = section_rate(m, t, y);
}

/* The times inside (a.t, b.t) where the cubic Hermite interpolant of g
 * over the step (its values and rates at both ends) turns and has a sign
 * other than an end's: where the orbit may cross the section twice within
 * one step (a dip through the plane and back), which g's values at the
 * ends do not show. At most 2, in order, into ts. */
static int turning_times(const step_end *a, const step_end *b, double *ts)
{
    const double h = b->t - a->t, dg = a->g - b->g, ra = h * a->rate, rb = h * b->rate;
    if (!isfinite(ra) || !isfinite(rb))
        return 0;
    /* p'(s) = A s^2 + B s + C on s in (0, 1) */
    const double A = 6 * dg + 3 * (ra + rb), B = -6 * dg - 4 * ra - 2 * rb, C = ra;
    double roots[2];
    int n = 0;
    if (fabs(A) < 1e-300) {
        if (B != 0)
            roots[n++] = -C / B;
    } else {
        const double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            const double q = -0.5 * (B + copysign(sqrt(disc), B));
            roots[n++] = q / A;
            if (q != 0)
                roots[n++] = C / q;
        }
    }
    if (n == 2 && roots[0] > roots[1]) {
        const double r = roots[0];
        roots[0] = roots[1], roots[1] = r;
    }
    int kept = 0;
    for (int i = 0; i < n; i++) {
        const double s = roots[i];
        if (!(s > 0 && s < 1))
            continue;
        const double s2 = s * s, s3 = s2 * s;
        const double p = (2 * s3 - 3 * s2 + 1) * a->g + (s3 - 2 * s2 + s) * ra +
                         (-2 * s3 + 3 * s2) * b->g + (s3 - s2) * rb;
        if (p * a->g <= 0 || p * b->g <= 0)
            ts[kept++] = a->t + s * h;
    }
    return kept;
}

/* The step from a to b, with no crossing between its ends: split at the
 * interpolant's turning times (each state integrated afresh from a) and
 * the first piece whose ends cross the section located; true with the
 * point beyond it in out and its time in *t_cross. *lost where an
 * integration fails. */
static bool crossing_within(flow_work *w, const step_end *a, const step_end *b, double *out,
                            double *t_cross, bool *lost)
{
    const cm_model *m = w->m;
    double ts[2];
    const int n = turning_times(a, b, ts);
    step_end from = *a, to;
    for (int i = 0; i <= n; i++) {
        if (i == n) {
            to = *b;
        } else {
            double y[CM_MAX_DIM];
            memcpy(y, a->y, (size_t)w->n * sizeof *y);
            if (!integrate(w, a->t, ts[i], y)) {
                *lost = true;
                return false;
            }
            step_end_at(m, ts[i], y, &to);
        }
        if (crossed(m->flow.direction, from.g, to.g)) {
            *lost = !locate(w, from.t, from.y, to.t, to.y, out, t_cross);
            return !*lost;
        }
        from = to;
    }
    return false;
}

/* The first crossing of the section after (t, y) and before t1, stepping
 * with *h: true with the point on its far side in out and its time in
 * *t_cross, y and *t advanced past it; false at t1 or where the orbit is
 * lost (*lost then true). A crossing and its return within one step are
 * found by the cubic interpolant of g (turning_times). */
static bool next_crossing(flow_work *w, double *t, double t1, double *h, double *y, double *out,
                          double *t_cross, bool *lost)
{
    const cm_model *m = w->m;
    step_end a, b;
    step_end_at(m, *t, y, &a);
    *lost = false;
    while (*t < t1) {
        if (!advance(w, t, t1, h, y)) {
            *lost = true;
            return false;
        }
        step_end_at(m, *t, y, &b);
        if (crossed(m->flow.direction, a.g, b.g)) {
            *lost = !locate(w, a.t, a.y, b.t, b.y, out, t_cross);
            return !*lost;
        }
        const bool found = crossing_within(w, &a, &b, out, t_cross, lost);
        if (found || *lost)
            return found;
        a = b;
    }
    return false;
}

/* The image of x: the state at t0 + period, or at the next crossing of the
 * section. */
static int map_one(flow_work *w, const double *x, double *y, double *t_end)
{
    const cm_model *m = w->m;
    const cm_flow *f = &m->flow;
    double z[CM_MAX_DIM];
    w->steps = 0;
    cm_flow_lift(m, x, z);
    *t_end = f->t0;
    if (!in_world(m, z))
        return CM_STEP_NO_IMAGE;
    if (!has_section(f)) {
        *t_end = f->t0 + f->period;
        if (!integrate(w, f->t0, *t_end, z))
            return CM_STEP_NO_IMAGE;
        drop(m, z, y);
        return CM_STEP_OK;
    }
    restart(w);
    double t = f->t0, h = first_step(m, f->t0, z, f->t_max), image[CM_MAX_DIM];
    bool lost;
    /* not reached in time (t is then t0 + t_max), or lost: no image */
    if (!next_crossing(w, &t, f->t0 + f->t_max, &h, z, image, t_end, &lost)) {
        *t_end = t;
        return CM_STEP_NO_IMAGE;
    }
    drop(m, image, y);
    return CM_STEP_OK;
}

int cm_flow_map(const cm_model *m, const double *x, double *y, double *t_end, long *steps)
{
    flow_work w;
    if (!work_open(&w, m))
        return CM_STEP_ABORT;
    double t = 0;
    const int rc = map_one(&w, x, y, &t);
    if (t_end)
        *t_end = t;
    if (steps)
        *steps = w.steps;
    work_close(&w);
    return rc;
}

int cm_flow_follow(const cm_model *m, const double *x, double t0, double t1, double dt,
                   cm_flow_observer observe, void *user, double *t_reached)
{
    flow_work w;
    if (!work_open(&w, m))
        return CM_STEP_ABORT;
    double y[CM_MAX_DIM], cross[CM_MAX_DIM], t = t0, t_cross;
    memcpy(y, x, (size_t)w.n * sizeof *y);
    int rc = in_world(m, y) ? observe(user, CM_FLOW_SAMPLE, t, y) : CM_STEP_NO_IMAGE;
    double h = first_step(m, t, y, fmin(dt, t1 - t));
    for (long k = 1; rc == CM_STEP_OK && t < t1; k++) {
        /* samples at t0 + k dt exactly, not at sums of dt */
        const double next = fmin(t0 + (double)k * dt, t1);
        bool lost = false;
        w.steps = 0;
        while (rc == CM_STEP_OK && has_section(&m->flow) &&
               next_crossing(&w, &t, next, &h, y, cross, &t_cross, &lost))
            rc = observe(user, CM_FLOW_CROSSING, t_cross, cross);
        if (rc == CM_STEP_OK && !lost && t < next)
            lost = !integrate_on(&w, &t, next, &h, y);
        if (rc == CM_STEP_OK)
            rc = lost ? CM_STEP_NO_IMAGE : observe(user, CM_FLOW_SAMPLE, t, y);
    }
    if (t_reached)
        *t_reached = t;
    work_close(&w);
    return rc;
}

static int step_flow(const cm_model *m, const double *x, double *y)
{
    return cm_flow_map(m, x, y, NULL, NULL);
}

static void step_n_flow(const cm_model *m, size_t n, const double *const *x, double *const *y,
                        int *rc)
{
    flow_work w;
    const bool ok = work_open(&w, m);
    for (size_t i = 0; i < n; i++) {
        double in[CM_MAX_DIM], out[CM_MAX_DIM], t;
        for (int d = 0; d < m->dim; d++)
            in[d] = x[d][i];
        rc[i] = ok ? map_one(&w, in, out, &t) : CM_STEP_ABORT;
        for (int d = 0; d < m->dim; d++)
            y[d][i] = rc[i] == CM_STEP_OK ? out[d] : 0;
    }
    if (ok)
        work_close(&w);
}

/* The value of parameter `name` if the model has it, else `def`. */
static double setting(const cm_model *m, const char *name, double def)
{
    const int k = cm_params_find(&m->values, name);
    return k >= 0 ? m->values.value[k].v[0] : def;
}

cm_status cm_flow_attach(cm_model *m, char *msg, size_t msg_size)
{
    cm_flow *f = &m->flow;
    f->method = (int)setting(m, "method", f->method);
    f->abs_tol = setting(m, "abs_tol", f->abs_tol > 0 ? f->abs_tol : 1e-9);
    f->rel_tol = setting(m, "rel_tol", f->rel_tol > 0 ? f->rel_tol : 1e-9);
    f->world = setting(m, "world", f->world > 0 ? f->world : 1e6);
    f->t_max = setting(m, "t_max", f->t_max > 0 ? f->t_max : 1000);
    f->event_tol = setting(m, "event_tol", f->event_tol > 0 ? f->event_tol : 1e-12);
    if (cm_params_find(&m->values, "section") >= 0) {
        /* crossing: up|down|either */
        static const int directions[] = {1, -1, 0};
        f->plane = (int)setting(m, "section", 0) + 1;
        f->level = setting(m, "level", 0);
        f->direction = directions[(int)setting(m, "crossing", 0) % 3];
    }
    const char *problem =
        !f->field                                                     ? "no vector field"
        : m->step                                                     ? "both step and flow"
        : f->method < CM_FLOW_RK8PD || f->method >= CM_FLOW_METHODS   ? "an unknown method"
        : f->direction < -1 || f->direction > 1                      ? "a direction not in -1..1"
        : f->plane < 0 || f->plane > cm_flow_dim(m) || cm_flow_dim(m) > CM_MAX_DIM
            ? "a section plane that is not one of its coordinates"
        : f->plane && f->section                                      ? "both a plane and a section function"
        : f->plane && !isfinite(f->level)                             ? "a level that is not finite"
        : !has_section(f) && !(f->period > 0 && f->period < 1e12)     ? "no period > 0"
        : !(f->t0 > -1e12 && f->t0 < 1e12)                            ? "a t0 that is not finite"
                                                                      : NULL;
    if (problem)
        return cm_fail(CM_EINVAL, msg, msg_size, "model %s: its flow has %s", m->name, problem);
    /* GSL's default handler aborts the process on an error; cellmap reads
     * the status each call returns instead */
    gsl_set_error_handler_off();
    m->step = step_flow;
    m->step_n = step_n_flow;
    return CM_OK;
}
