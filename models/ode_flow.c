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

/* What one thread integrates with: GSL's stepper, error control and
 * evolution, allocated once per step_n batch. */
typedef struct flow_work {
    gsl_odeiv2_step *step;
    gsl_odeiv2_control *control;
    gsl_odeiv2_evolve *evolve;
    gsl_odeiv2_system sys;
    const cm_model *m;
    long steps;
} flow_work;

static int field_gsl(double t, const double y[], double f[], void *params)
{
    const cm_model *m = params;
    /* GSL_EBADFUNC ends the integration at once (any other error would
     * make GSL retry with a smaller step) */
    return m->flow.field(m, t, y, f) == 0 ? GSL_SUCCESS : GSL_EBADFUNC;
}

static const gsl_odeiv2_step_type *step_type(int method)
{
    switch (method) {
    case CM_FLOW_RKF45: return gsl_odeiv2_step_rkf45;
    case CM_FLOW_RKCK: return gsl_odeiv2_step_rkck;
    case CM_FLOW_RK4: return gsl_odeiv2_step_rk4;
    default: return gsl_odeiv2_step_rk8pd;
    }
}

static void work_close(flow_work *w)
{
    if (w->evolve)
        gsl_odeiv2_evolve_free(w->evolve);
    if (w->control)
        gsl_odeiv2_control_free(w->control);
    if (w->step)
        gsl_odeiv2_step_free(w->step);
}

static bool work_open(flow_work *w, const cm_model *m)
{
    const size_t dim = (size_t)m->dim;
    memset(w, 0, sizeof *w);
    w->m = m;
    w->sys = (gsl_odeiv2_system){field_gsl, NULL, dim, (void *)m};
    w->step = gsl_odeiv2_step_alloc(step_type(m->flow.method), dim);
    w->control = gsl_odeiv2_control_y_new(m->flow.abs_tol, m->flow.rel_tol);
    w->evolve = gsl_odeiv2_evolve_alloc(dim);
    if (w->step && w->control && w->evolve)
        return true;
    work_close(w);
    return false;
}

static bool in_world(const cm_model *m, const double *y)
{
    for (int d = 0; d < m->dim; d++)
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
        for (int d = 0; d < m->dim; d++) {
            scale = fmax(scale, fabs(y[d]) + 1);
            rate = fmax(rate, fabs(dydt[d]));
        }
    if (rate > 0 && isfinite(rate))
        h = fmin(h, 0.01 * scale / rate);
    return h < span ? h : span;
}

static bool finite_state(int dim, const double *y)
{
    for (int d = 0; d < dim; d++)
        if (!isfinite(y[d]))
            return false;
    return true;
}

/* One accepted step towards t1 from (*t, y); false when the orbit has no
 * image (the field failed, the world was left, too many steps). A step
 * GSL accepts with a non-finite state (its error estimate NaN, which its
 * control takes as small) is taken back and tried again ten times
 * shorter: only a state beyond the world, or non-finite at steps below
 * 1e-12 of the period, is a blow-up. */
static bool advance(flow_work *w, double *t, double t1, double *h, double *y)
{
    const int dim = w->m->dim;
    const double t0 = *t, shortest = 1e-12 * (w->m->flow.period > 0 ? w->m->flow.period : 1.0);
    double y0[CM_MAX_DIM];
    memcpy(y0, y, (size_t)dim * sizeof *y);
    for (;;) {
        if (gsl_odeiv2_evolve_apply(w->evolve, w->control, w->step, &w->sys, t, t1, h, y) !=
            GSL_SUCCESS)
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
        gsl_odeiv2_evolve_reset(w->evolve);
        gsl_odeiv2_step_reset(w->step);
    }
}

/* y from time t to time t1 (> t). */
static bool integrate(flow_work *w, double t, double t1, double *y)
{
    gsl_odeiv2_evolve_reset(w->evolve);
    gsl_odeiv2_step_reset(w->step);
    double h = first_step(w->m, t, y, t1 - t);
    while (t < t1)
        if (!advance(w, &t, t1, &h, y))
            return false;
    return true;
}

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
    const size_t bytes = (size_t)m->dim * sizeof(double);
    double a[CM_MAX_DIM], b[CM_MAX_DIM], trial[CM_MAX_DIM];
    memcpy(a, ya, bytes);
    memcpy(b, yb, bytes);
    double ga = m->flow.section(m, ta, a), gb = m->flow.section(m, tb, b);
    int kept = 0; /* which end stayed last time: -1 a, +1 b */
    for (int it = 0; it < 200 && tb - ta > m->flow.event_tol; it++) {
        double tm = gb != ga ? (ta * gb - tb * ga) / (gb - ga) : 0.5 * (ta + tb);
        if (!(tm > ta && tm < tb))
            tm = 0.5 * (ta + tb);
        memcpy(trial, a, bytes);
        if (!integrate(w, ta, tm, trial))
            return false;
        const double gm = m->flow.section(m, tm, trial);
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

/* The image of x: the state at t0 + period, or at the next crossing of the
 * section. */
static int map_one(flow_work *w, const double *x, double *y, double *t_end)
{
    const cm_model *m = w->m;
    const cm_flow *f = &m->flow;
    w->steps = 0;
    memcpy(y, x, (size_t)m->dim * sizeof *y);
    if (!in_world(m, y))
        return CM_STEP_NO_IMAGE;
    if (!f->section) {
        *t_end = f->t0 + f->period;
        return integrate(w, f->t0, *t_end, y) ? CM_STEP_OK : CM_STEP_NO_IMAGE;
    }
    gsl_odeiv2_evolve_reset(w->evolve);
    gsl_odeiv2_step_reset(w->step);
    const double t1 = f->t0 + f->t_max;
    double t = f->t0, h = first_step(m, f->t0, y, f->t_max), before[CM_MAX_DIM];
    double g = f->section(m, t, y);
    while (t < t1) {
        const double t_before = t, g_before = g;
        memcpy(before, y, (size_t)m->dim * sizeof *y);
        if (!advance(w, &t, t1, &h, y))
            return CM_STEP_NO_IMAGE;
        g = f->section(m, t, y);
        if (crossed(f->direction, g_before, g))
            return locate(w, t_before, before, t, y, y, t_end) ? CM_STEP_OK : CM_STEP_NO_IMAGE;
    }
    return CM_STEP_NO_IMAGE; /* the section was not reached in time */
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
    const char *problem = !f->field                                      ? "no vector field"
                          : m->step                                      ? "both step and flow"
                          : f->method < CM_FLOW_RK8PD || f->method > CM_FLOW_RK4 ? "an unknown method"
                          : f->direction < -1 || f->direction > 1        ? "a direction not in -1..1"
                          : !f->section && !(f->period > 0 && f->period < 1e12) ? "no period > 0"
                          : !(f->t0 > -1e12 && f->t0 < 1e12)            ? "a t0 that is not finite"
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
