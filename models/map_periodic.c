/* models/map_periodic.c - periodic points of maps, their multipliers and
 * branches (models/map_periodic.h). */
#include "models/map_periodic.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/flow_equilibria.h" /* cm_eigenvalues */
#include "models/ode_flow.h"

/* P^period(x) into y; false where an iterate has no image. */
static bool iterate(const cm_model *m, int period, const double *x, double *y)
{
    /* step() need not take its image in place */
    double z[CM_MAX_DIM];
    memcpy(y, x, (size_t)m->dim * sizeof *x);
    for (int k = 0; k < period; k++) {
        memcpy(z, y, (size_t)m->dim * sizeof *y);
        if (m->step(m, z, y) != CM_STEP_OK)
            return false;
    }
    for (int d = 0; d < m->dim; d++)
        if (!isfinite(y[d]))
            return false;
    return true;
}

cm_status cm_map_jacobian(const cm_model *m, int period, const double *x, double *J)
{
    const int n = m->dim;
    double xs[CM_MAX_DIM], yp[CM_MAX_DIM], ym[CM_MAX_DIM];
    memcpy(xs, x, (size_t)n * sizeof *x);
    for (int j = 0; j < n; j++) {
        const double h = 1e-6 * fmax(1, fabs(x[j]));
        xs[j] = x[j] + h;
        const bool up = iterate(m, period, xs, yp);
        xs[j] = x[j] - h;
        const bool down = iterate(m, period, xs, ym);
        xs[j] = x[j];
        if (!up || !down)
            return CM_EMODEL;
        for (int i = 0; i < n; i++)
            J[i * n + j] = (yp[i] - ym[i]) / (2 * h);
    }
    return CM_OK;
}

typedef struct mult {
    double re, im;
} mult;

static int by_modulus(const void *a, const void *b)
{
    const mult *x = a, *y = b;
    const double mx = hypot(x->re, x->im), my = hypot(y->re, y->im);
    if (mx != my)
        return mx < my ? 1 : -1;
    return (x->im < y->im) - (x->im > y->im);
}

/* x, p into pt with its multipliers, the count outside the unit circle
 * and the signs of det(DP^k -+ I). */
static cm_status classify(const cm_model *m, int period, double p, const double *x,
                          cm_periodic_point *pt)
{
    const int n = m->dim;
    double J[CM_MAX_DIM * CM_MAX_DIM];
    memset(pt, 0, sizeof *pt);
    pt->dim = n, pt->period = period, pt->p = p;
    memcpy(pt->x, x, (size_t)n * sizeof *x);
    cm_status st = cm_map_jacobian(m, period, x, J);
    if (st == CM_OK)
        st = cm_eigenvalues(n, J, pt->re, pt->im);
    if (st != CM_OK)
        return st;
    mult mu[CM_MAX_DIM];
    for (int i = 0; i < n; i++)
        mu[i] = (mult){pt->re[i], pt->im[i]};
    qsort(mu, (size_t)n, sizeof *mu, by_modulus);
    pt->fold_sign = pt->flip_sign = 1;
    for (int i = 0; i < n; i++) {
        pt->re[i] = mu[i].re, pt->im[i] = mu[i].im;
        pt->outside += hypot(mu[i].re, mu[i].im) > 1;
        if (mu[i].im == 0) { /* a complex pair's product is positive */
            pt->fold_sign *= mu[i].re > 1 ? 1 : mu[i].re < 1 ? -1 : 0;
            pt->flip_sign *= mu[i].re > -1 ? 1 : mu[i].re < -1 ? -1 : 0;
        }
    }
    return CM_OK;
}

/* The problem of period-k points: f = P^k(x) - x of the model at p. */
typedef struct po_problem {
    cm_model_source src;
    int period;
    char *msg;
    size_t msg_size;
} po_problem;

static cm_status po_eval(void *ctx, double p, const double *x, double *f, double *J)
{
    const po_problem *q = ctx;
    const cm_model *m;
    cm_model own;
    cm_status st = cm_model_source_at(&q->src, p, &own, &m, q->msg, q->msg_size);
    if (st != CM_OK)
        return st;
    const int n = m->dim;
    st = iterate(m, q->period, x, f) ? CM_OK : CM_EMODEL;
    for (int i = 0; st == CM_OK && i < n; i++)
        f[i] -= x[i];
    if (st == CM_OK && J)
        st = cm_map_jacobian(m, q->period, x, J);
    for (int i = 0; J && st == CM_OK && i < n; i++)
        J[i * n + i] -= 1;
    cm_model_source_done(&q->src, &own);
    return st;
}

/* Tests: det(DP^k - I)'s sign (a fold), det(DP^k + I)'s (a period
 * doubling), the count outside the circle (Neimark-Sacker, where neither
 * sign changes). */
static cm_status po_classify(void *ctx, double p, const double *x, void *state, int *tests)
{
    const po_problem *q = ctx;
    cm_periodic_point *pt = state;
    const cm_model *m;
    cm_model own;
    cm_status st = cm_model_source_at(&q->src, p, &own, &m, q->msg, q->msg_size);
    if (st != CM_OK)
        return st;
    st = classify(m, q->period, p, x, pt);
    cm_model_source_done(&q->src, &own);
    tests[0] = pt->fold_sign;
    tests[1] = pt->flip_sign;
    tests[2] = pt->outside;
    return st;
}

static cm_arc_problem po_arc(po_problem *q, int n)
{
    return (cm_arc_problem){.n = n,
                            .tol = 1e-9,
                            .eval = po_eval,
                            .classify = po_classify,
                            .state_size = sizeof(cm_periodic_point),
                            .n_tests = 3,
                            .count_test = 2,
                            .ctx = q,
                            .msg = q->msg,
                            .msg_size = q->msg_size};
}

cm_status cm_map_periodic_point(const cm_model *m, double p, int period, double *x,
                                cm_periodic_point *pt, char *msg, size_t msg_size)
{
    if (period < 1 || period > 1000000)
        return cm_fail(CM_EINVAL, msg, msg_size, "a period of %d: give 1..1000000", period);
    double start[CM_MAX_DIM];
    memcpy(start, x, (size_t)m->dim * sizeof *x);
    po_problem q = {{m, NULL, NULL}, period, msg, msg_size};
    const cm_arc_problem pr = po_arc(&q, m->dim);
    if (cm_arc_newton(&pr, p, x) != CM_OK) {
        char at[48] = ""; /* p is NAN where no parameter is varied */
        if (isfinite(p))
            snprintf(at, sizeof at, " at %.9g", p);
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "Newton's method finds no period-%d point of %s from (%.6g%s)%s: start "
                       "nearer one (e.g. a point the orbit settles on)",
                       period, m->name, start[0], m->dim > 1 ? ", ..." : "", at);
    }
    const cm_status st = pt ? classify(m, period, p, x, pt) : CM_OK;
    return st == CM_OK
               ? CM_OK
               : cm_fail(st, msg, msg_size, "the multipliers at %.9g cannot be found", p);
}

typedef struct po_follow {
    int (*point)(void *user, const cm_periodic_point *pt);
    int (*event)(void *user, const cm_po_event *ev);
    void *user;
} po_follow;

static int po_point(void *user, const void *state)
{
    const po_follow *f = user;
    return f->point && f->point(f->user, state);
}

static int po_event(void *user, int test, const void *state)
{
    static const int kinds[] = {CM_PO_FOLD, CM_PO_PD, CM_PO_NS};
    const po_follow *f = user;
    const cm_po_event ev = {kinds[test], *(const cm_periodic_point *)state};
    return f->event && f->event(f->user, &ev);
}

cm_status cm_map_periodic_branch(cm_model_at_fn at, void *at_user, int period, double p0,
                                 const double *x0, const cm_branch_options *o,
                                 int (*point)(void *user, const cm_periodic_point *pt),
                                 int (*event)(void *user, const cm_po_event *ev), void *user,
                                 int *why, char *msg, size_t msg_size)
{
    cm_model m;
    cm_status st = at(at_user, p0, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = m.dim;
    double x[CM_MAX_DIM];
    memcpy(x, x0, (size_t)n * sizeof *x0);
    st = cm_map_periodic_point(&m, p0, period, x, NULL, msg, msg_size);
    cm_model_release(&m);
    if (st != CM_OK)
        return st;
    po_problem q = {{NULL, at, at_user}, period, msg, msg_size};
    const cm_arc_problem pr = po_arc(&q, n);
    po_follow f = {point, event, user};
    return cm_arc_follow(&pr, p0, x, o, po_point, po_event, &f, why);
}

/* The eigenvector vr + i vi of J (n x n, overwritten) for its eigenvalue
 * nearest re + i im. */
static cm_status nearest_eigenvector(int n, double *J, double re, double im, double *vr,
                                     double *vi)
{
    gsl_set_error_handler_off();
    gsl_matrix_view A = gsl_matrix_view_array(J, (size_t)n, (size_t)n);
    gsl_vector_complex *val = gsl_vector_complex_alloc((size_t)n);
    gsl_matrix_complex *vec = gsl_matrix_complex_alloc((size_t)n, (size_t)n);
    gsl_eigen_nonsymmv_workspace *w = gsl_eigen_nonsymmv_alloc((size_t)n);
    cm_status st = val && vec && w ? CM_OK : CM_ENOMEM;
    if (st == CM_OK && gsl_eigen_nonsymmv(&A.matrix, val, vec, w) != GSL_SUCCESS)
        st = CM_ERANGE;
    if (st == CM_OK) {
        size_t best = 0;
        double gap = INFINITY;
        for (size_t i = 0; i < (size_t)n; i++) {
            const gsl_complex z = gsl_vector_complex_get(val, i);
            const double d = hypot(GSL_REAL(z) - re, GSL_IMAG(z) - im);
            if (d < gap)
                gap = d, best = i;
        }
        for (int i = 0; i < n; i++) {
            const gsl_complex z = gsl_matrix_complex_get(vec, (size_t)i, best);
            vr[i] = GSL_REAL(z), vi[i] = GSL_IMAG(z);
        }
    }
    gsl_eigen_nonsymmv_free(w);
    gsl_matrix_complex_free(vec);
    gsl_vector_complex_free(val);
    return st;
}

/* The unit eigenvector of DP^k at the doubling point for its real
 * multiplier nearest -1, into v. */
static cm_status flip_vector(const cm_model *m, const cm_periodic_point *pt, double *v)
{
    const int n = pt->dim;
    double J[CM_MAX_DIM * CM_MAX_DIM], unused[CM_MAX_DIM];
    cm_status st = cm_map_jacobian(m, pt->period, pt->x, J);
    if (st == CM_OK)
        st = nearest_eigenvector(n, J, -1, 0, v, unused);
    double len = 0;
    for (int i = 0; i < n && st == CM_OK; i++)
        len += v[i] * v[i];
    len = sqrt(len);
    for (int i = 0; i < n && st == CM_OK; i++)
        v[i] = len > 0 ? v[i] / len : 0;
    return st == CM_OK && !(len > 0) ? CM_ERANGE : st;
}

/* Whether x is a period-2k point of m and no period-k point. */
static bool doubled_point(const cm_model *m, int k, double p, double *x, char *msg,
                          size_t msg_size)
{
    double y[CM_MAX_DIM], gap = 0;
    if (cm_map_periodic_point(m, p, 2 * k, x, NULL, msg, msg_size) != CM_OK ||
        !iterate(m, k, x, y))
        return false;
    for (int i = 0; i < m->dim; i++)
        gap = fmax(gap, fabs(y[i] - x[i]));
    return gap > 1e-6 * (1 + fabs(x[0]));
}

cm_status cm_map_period_doubled(cm_model_at_fn at, void *at_user, const cm_po_event *pd,
                                double dp, double *x, double *p, char *msg, size_t msg_size)
{
    const cm_periodic_point *pt = &pd->at;
    double v[CM_MAX_DIM];
    cm_model m;
    cm_status st = at(at_user, pt->p, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    st = flip_vector(&m, pt, v);
    cm_model_release(&m);
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "the eigenvector of -1 at %.9g cannot be found", pt->p);
    const double eps = sqrt(fabs(dp));
    for (int side = 0; side < 2; side++) {
        *p = pt->p + (side ? -dp : dp);
        if (at(at_user, *p, &m, msg, msg_size) != CM_OK)
            continue;
        bool found = false;
        for (int sign = -1; sign <= 1 && !found; sign += 2) {
            for (int i = 0; i < pt->dim; i++)
                x[i] = pt->x[i] + sign * eps * v[i];
            found = doubled_point(&m, pt->period, *p, x, msg, msg_size);
        }
        cm_model_release(&m);
        if (found)
            return CM_OK;
    }
    return cm_fail(CM_ENOTFOUND, msg, msg_size,
                   "no orbit of period %d found next to the period doubling at %.9g (steps "
                   "+-%g): try another step",
                   2 * pt->period, pt->p, dp);
}

/* Where eq + eps Re(v e^(i theta)) crosses the plane x_k = eq_k the way
 * direction asks (-1 down, +1 up, 0 either): the direction w in the flow's
 * coordinates (w_k = 0). The orbit moves with theta (theta = omega t). */
static void crossing_direction(int n, int k, int direction, const double *vr, const double *vi,
                               double *w)
{
    /* x_k - eq_k = eps (vr_k cos theta - vi_k sin theta) = 0 */
    double theta = atan2(vr[k], vi[k]);
    /* its rate: -eps omega (vr_k sin theta + vi_k cos theta) */
    const double rate = -(vr[k] * sin(theta) + vi[k] * cos(theta));
    if ((direction < 0 && rate > 0) || (direction > 0 && rate < 0))
        theta += 3.14159265358979323846;
    for (int i = 0; i < n; i++)
        w[i] = i == k ? 0 : vr[i] * cos(theta) - vi[i] * sin(theta);
    double norm = 0;
    for (int i = 0; i < n; i++)
        norm = fmax(norm, fabs(w[i]));
    for (int i = 0; i < n && norm > 0; i++)
        w[i] /= norm;
}

cm_status cm_map_hopf_orbit(cm_model_at_fn at, void *at_user, const struct cm_equilibrium *hopf,
                            double omega, double dp, double *x, double *p, char *msg,
                            size_t msg_size)
{
    cm_model m;
    cm_status st = at(at_user, hopf->p, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = cm_flow_dim(&m), k = m.flow.plane - 1, direction = m.flow.direction;
    double J[CM_MAX_DIM * CM_MAX_DIM], vr[CM_MAX_DIM], vi[CM_MAX_DIM], w[CM_MAX_DIM];
    if (k < 0 || n != hopf->dim)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "a Hopf start needs the section map of a plane of the flow's %d coordinates",
                     hopf->dim);
    if (st == CM_OK && (cm_flow_jacobian(&m, hopf->x, J) != CM_OK ||
                        nearest_eigenvector(n, J, 0, omega, vr, vi) != CM_OK))
        st = cm_fail(CM_EMODEL, msg, msg_size, "the Hopf point's eigenvector cannot be found");
    cm_model_release(&m);
    if (st != CM_OK)
        return st;
    crossing_direction(n, k, direction, vr, vi, w);
    double scale = 1;
    for (int i = 0; i < n; i++)
        scale = fmax(scale, fabs(hopf->x[i]));
    static const double sizes[] = {0.3, 1, 3};
    for (int side = 0; side < 2; side++) {
        *p = hopf->p + (side ? -dp : dp);
        if (at(at_user, *p, &m, msg, msg_size) != CM_OK)
            continue;
        bool found = false;
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0] && !found; s++) {
            const double eps = sizes[s] * sqrt(fabs(dp)) * scale;
            double y[CM_MAX_DIM];
            for (int i = 0; i < n; i++)
                y[i] = hopf->x[i] + eps * w[i];
            for (int i = 0, j = 0; i < n; i++)
                if (i != k)
                    x[j++] = y[i];
            cm_periodic_point pt;
            if (cm_map_periodic_point(&m, *p, 1, x, &pt, msg, msg_size) != CM_OK)
                continue;
            /* off the equilibrium: at least a tenth of the smallest size tried */
            double off = 0;
            for (int i = 0, j = 0; i < n; i++)
                if (i != k)
                    off = fmax(off, fabs(x[j++] - hopf->x[i]));
            found = off > 0.03 * sqrt(fabs(dp)) * scale;
        }
        cm_model_release(&m);
        if (found)
            return CM_OK;
    }
    return cm_fail(CM_ENOTFOUND, msg, msg_size,
                   "no periodic orbit found next to the Hopf point at %.9g (steps +-%g): try "
                   "another step",
                   hopf->p, dp);
}
