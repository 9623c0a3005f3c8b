#include "cellmap/model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char *cm_flow_coord_name(const cm_model *m, int d)
{
    static const char *const generic[CM_MAX_DIM] = {"x0", "x1", "x2", "x3", "x4", "x5"};
    if (d < 0 || d >= CM_MAX_DIM)
        return "?";
    return m->coord_names && d < cm_flow_dim(m) ? m->coord_names[d] : generic[d];
}

const char *cm_model_coord_name(const cm_model *m, int d)
{
    const int k = m->flow.plane - 1;
    if (d >= 0 && d < m->dim && k >= 0 && d >= k)
        d++; /* the map of a section on the plane x_k drops x_k */
    return cm_flow_coord_name(m, d);
}

void cm_param_choice_name(const char *choices, int k, char *buf, size_t size)
{
    const char *c = choices;
    for (int i = 0; i < k && c; i++) {
        c = strchr(c, '|');
        if (c)
            c++;
    }
    if (!c) {
        snprintf(buf, size, "%d", k);
        return;
    }
    const char *end = strchr(c, '|');
    snprintf(buf, size, "%.*s", (int)(end ? (size_t)(end - c) : strlen(c)), c);
}

void cm_model_release(cm_model *m)
{
    if (!m)
        return;
    if (m->destroy && m->ctx)
        m->destroy(m->ctx);
    memset(m, 0, sizeof *m);
}

static double wrap_into(double lo, double period, double x)
{
    const double u = x - lo;
    if (u >= 0 && u < period)
        return x;
    if (!isfinite(u))
        return x; /* not finite: the world's sink sees to it */
    double r = fmod(u, period);
    r += r < 0 ? period : 0;
    return r < period ? lo + r : lo; /* r rounded up to the period is its start */
}

double cm_model_wrap(const cm_model *m, int d, double x)
{
    return cm_model_periodic(m, d) ? wrap_into(m->period_lo[d], m->period[d], x) : x;
}

double cm_period_diff(const double *period, int d, double a, double b)
{
    const double delta = a - b, p = period[d];
    if (!(p > 0) || !isfinite(delta))
        return delta;
    double r = fmod(delta, p); /* in (-p, p) */
    if (r >= 0.5 * p)
        r -= p;
    else if (r < -0.5 * p)
        r += p;
    return r;
}

double cm_model_diff(const cm_model *m, int d, double a, double b)
{
    return cm_period_diff(m->period, d, a, b);
}

/* A step's status as the engine takes it: a code that is none of
 * CM_STEP_OK, CM_STEP_NO_IMAGE and CM_STEP_ABORT (a plugin's mistake)
 * stops the run rather than passing for the sink. */
static int known_status(int rc)
{
    return rc == CM_STEP_OK || rc == CM_STEP_NO_IMAGE ? rc : CM_STEP_ABORT;
}

static int wrapped_step(const cm_model *m, const double *x, double *y)
{
    const int rc = known_status(m->own_step(m, x, y));
    for (int d = 0; rc == CM_STEP_OK && d < m->dim; d++)
        y[d] = cm_model_wrap(m, d, y[d]);
    return rc;
}

static void wrapped_step_n(const cm_model *m, size_t n, const double *const *x, double *const *y,
                           int *rc)
{
    m->own_step_n(m, n, x, y, rc);
    for (size_t i = 0; i < n; i++)
        rc[i] = known_status(rc[i]);
    for (int d = 0; d < m->dim; d++)
        if (cm_model_periodic(m, d))
            for (size_t i = 0; i < n; i++)
                y[d][i] = rc[i] == CM_STEP_OK ? wrap_into(m->period_lo[d], m->period[d], y[d][i])
                                              : y[d][i];
}

cm_status cm_model_wrap_periods(cm_model *m, bool check_status, char *msg, size_t msg_size)
{
    bool any = check_status;
    for (int d = 0; d < m->dim && d < CM_MAX_DIM; d++) {
        const double p = m->period[d], lo = m->period_lo[d];
        if (p == 0 && lo == 0)
            continue;
        if (!(p > 0 && isfinite(p) && isfinite(lo)))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "model %s: coordinate %s is periodic with period %g from %g; a period "
                           "must be above 0 and finite (0: not periodic)",
                           m->name, cm_model_coord_name(m, d), p, lo);
        any = true;
    }
    if (!any || m->own_step)
        return CM_OK;
    m->own_step = m->step;
    m->step = wrapped_step;
    m->own_step_n = m->step_n;
    m->step_n = m->step_n ? wrapped_step_n : NULL;
    return CM_OK;
}

cm_status cm_model_check_box(const cm_model *m, const cm_lattice *lat, const cm_box *box,
                             char *msg, size_t msg_size)
{
    for (int d = 0; d < lat->dim; d++) {
        if (!cm_model_periodic(m, d))
            continue;
        const double w = lat->width[d], slack = 1e-9 * w;
        const double lo = cm_lattice_edge(lat, d, box->lo[d]);
        const double hi = cm_lattice_edge(lat, d, box->hi[d]);
        const double p = m->period[d], from = m->period_lo[d];
        const char *name = cm_model_coord_name(m, d);
        if (hi - lo > p + slack)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the box is %.9g wide in %s, more than its period %.9g (%s is "
                           "periodic, from %.9g to %.9g): give at most one period",
                           hi - lo, name, p, name, from, from + p);
        if (lo < from - slack || hi > from + p + slack)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the box spans %.9g:%.9g in %s, beyond its period %.9g:%.9g (%s is "
                           "periodic): give it within %.9g:%.9g",
                           lo, hi, name, from, from + p, name, from, from + p);
    }
    return CM_OK;
}

/* Whether v is within rounding of a whole number. */
static bool whole(double v) { return fabs(v - nearbyint(v)) < 1e-9 * (fabs(v) + 1); }

cm_status cm_model_check_lattice(const cm_model *m, const cm_lattice *lat, char *msg,
                                 size_t msg_size)
{
    for (int d = 0; d < lat->dim; d++) {
        if (!cm_model_periodic(m, d))
            continue;
        const double w = lat->width[d];
        if (!whole(m->period[d] / w) || !whole((m->period_lo[d] - lat->origin[d]) / w))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s is periodic (period %.9g from %.9g): its cells must tile the "
                           "period, a cell size of the period / N and an origin on a cell "
                           "border of it (e.g. --cell-size %.9g --origin %.9g)",
                           cm_model_coord_name(m, d), m->period[d], m->period_lo[d],
                           m->period[d] / fmax(1.0, nearbyint(m->period[d] / w)),
                           m->period_lo[d]);
    }
    return CM_OK;
}
