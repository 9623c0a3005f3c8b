/* models/flow_equilibria.c - equilibria of flows, their eigenvalues and
 * branches (models/flow_equilibria.h). */
#include "models/flow_equilibria.h"

#include "models/ode_flow.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double norm(int n, const double *v)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

/* f(x) at the model's t0; nonzero where the field is not defined or not finite. */
static int field_at(const cm_model *m, const double *x, double *f)
{
    if (m->flow.field(m, m->flow.t0, x, f))
        return 1;
    for (int i = 0; i < cm_flow_dim(m); i++)
        if (!isfinite(f[i]))
            return 1;
    return 0;
}

cm_status cm_flow_jacobian(const cm_model *m, const double *x, double *J)
{
    return cm_flow_jacobian_at(m, m->flow.t0, x, J);
}

typedef struct eigen {
    double re, im;
} eigen;

static int by_real_part(const void *a, const void *b)
{
    const eigen *x = a, *y = b;
    if (x->re != y->re)
        return x->re < y->re ? 1 : -1;
    return (x->im < y->im) - (x->im > y->im);
}

cm_status cm_eigenvalues(int n, const double *J, double *re, double *im)
{
    gsl_set_error_handler_off(); /* statuses are read, not aborted on */
    gsl_matrix *a = gsl_matrix_alloc((size_t)n, (size_t)n);
    gsl_vector_complex *ev = gsl_vector_complex_alloc((size_t)n);
    gsl_eigen_nonsymm_workspace *w = gsl_eigen_nonsymm_alloc((size_t)n);
    cm_status st = a && ev && w ? CM_OK : CM_ENOMEM;
    if (st == CM_OK) {
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                gsl_matrix_set(a, (size_t)i, (size_t)j, J[i * n + j]);
        st = gsl_eigen_nonsymm(a, ev, w) == GSL_SUCCESS ? CM_OK : CM_ERANGE;
    }
    if (st == CM_OK) {
        eigen e[CM_MAX_DIM];
        for (int i = 0; i < n; i++) {
            const gsl_complex z = gsl_vector_complex_get(ev, (size_t)i);
            e[i] = (eigen){GSL_REAL(z), GSL_IMAG(z)};
        }
        qsort(e, (size_t)n, sizeof *e, by_real_part);
        for (int i = 0; i < n; i++)
            re[i] = e[i].re, im[i] = e[i].im;
    }
    gsl_eigen_nonsymm_free(w);
    gsl_vector_complex_free(ev);
    gsl_matrix_free(a);
    return st;
}

/* x, p into e with its eigenvalues, unstable count and det's sign. */
static cm_status classify(const cm_model *m, double p, const double *x, cm_equilibrium *e)
{
    const int n = cm_flow_dim(m);
    double J[CM_MAX_DIM * CM_MAX_DIM];
    memset(e, 0, sizeof *e);
    e->dim = n;
    e->p = p;
    memcpy(e->x, x, (size_t)n * sizeof *x);
    cm_status st = cm_flow_jacobian(m, x, J);
    if (st == CM_OK)
        st = cm_eigenvalues(n, J, e->re, e->im);
    if (st != CM_OK)
        return st;
    e->det_sign = 1;
    for (int i = 0; i < n; i++) {
        e->unstable += e->re[i] > 0;
        if (e->im[i] == 0 && e->re[i] < 0) /* a pair's product is positive */
            e->det_sign = -e->det_sign;
        else if (e->im[i] == 0 && e->re[i] == 0)
            e->det_sign = 0;
    }
    return CM_OK;
}

/* The problem of equilibria: f the field of the model at p, and the
 * classification. */
typedef struct eq_problem {
    cm_model_source src;
    char *msg;
    size_t msg_size;
} eq_problem;

static cm_status eq_eval(void *ctx, double p, const double *x, double *f, double *J)
{
    const eq_problem *q = ctx;
    const cm_model *m;
    cm_model own;
    cm_status st = cm_model_source_at(&q->src, p, &own, &m, q->msg, q->msg_size);
    if (st != CM_OK)
        return st;
    st = field_at(m, x, f) ? CM_EMODEL : J ? cm_flow_jacobian(m, x, J) : CM_OK;
    cm_model_source_done(&q->src, &own);
    return st;
}

/* Tests: det's sign (a fold), the unstable count (a Hopf point, where
 * det's sign stays: a pair through the axis). */
static cm_status eq_classify(void *ctx, double p, const double *x, void *state, int *tests)
{
    const eq_problem *q = ctx;
    cm_equilibrium *e = state;
    const cm_model *m;
    cm_model own;
    cm_status st = cm_model_source_at(&q->src, p, &own, &m, q->msg, q->msg_size);
    if (st != CM_OK)
        return st;
    st = classify(m, p, x, e);
    cm_model_source_done(&q->src, &own);
    tests[0] = e->det_sign;
    tests[1] = e->unstable;
    return st;
}

static cm_arc_problem eq_arc(eq_problem *q, int n)
{
    return (cm_arc_problem){.n = n,
                            .tol = 1e-10,
                            .eval = eq_eval,
                            .classify = eq_classify,
                            .state_size = sizeof(cm_equilibrium),
                            .n_tests = 2,
                            .count_test = 1,
                            .ctx = q,
                            .msg = q->msg,
                            .msg_size = q->msg_size};
}

cm_status cm_flow_equilibrium(const cm_model *m, double p, double *x, cm_equilibrium *e,
                              char *msg, size_t msg_size)
{
    const int n = cm_flow_dim(m);
    double f[CM_MAX_DIM], start[CM_MAX_DIM];
    memcpy(start, x, (size_t)n * sizeof *x);
    if (field_at(m, x, f))
        return cm_fail(CM_EMODEL, msg, msg_size, "the field of %s is not defined at the start",
                       m->name);
    eq_problem q = {{m, NULL, NULL}, msg, msg_size};
    const cm_arc_problem pr = eq_arc(&q, n);
    if (cm_arc_newton(&pr, p, x) != CM_OK) {
        char at[48] = ""; /* p is NAN where no parameter is varied */
        if (isfinite(p))
            snprintf(at, sizeof at, " at %.9g", p);
        field_at(m, x, f);
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "Newton's method finds no equilibrium of %s from (%.6g, %.6g%s)%s "
                       "(residual %.3g): start nearer one",
                       m->name, start[0], n > 1 ? start[1] : 0, n > 2 ? ", ..." : "", at,
                       norm(n, f));
    }
    const cm_status st = e ? classify(m, p, x, e) : CM_OK;
    return st == CM_OK ? CM_OK
                       : cm_fail(st, msg, msg_size, "the eigenvalues at %.9g cannot be found", p);
}

/* ---- branches ---------------------------------------------------------------- */

typedef struct eq_follow {
    int (*point)(void *user, const cm_equilibrium *e);
    int (*event)(void *user, const cm_eq_event *ev);
    void *user;
} eq_follow;

static int eq_point(void *user, const void *state)
{
    const eq_follow *f = user;
    return f->point && f->point(f->user, state);
}

static int eq_event(void *user, int test, const void *state)
{
    const eq_follow *f = user;
    const cm_equilibrium *e = state;
    cm_eq_event ev = {test == 0 ? CM_EQ_FOLD : CM_EQ_HOPF, *e, 0};
    if (ev.kind == CM_EQ_HOPF) { /* the pair nearest the imaginary axis */
        double best = INFINITY;
        for (int i = 0; i < e->dim; i++)
            if (e->im[i] > 0 && fabs(e->re[i]) < best)
                best = fabs(e->re[i]), ev.omega = e->im[i];
    }
    return f->event && f->event(f->user, &ev);
}

cm_status cm_flow_equilibrium_branch(cm_model_at_fn at, void *at_user, double p0,
                                     const double *x0, const cm_branch_options *o,
                                     int (*point)(void *user, const cm_equilibrium *e),
                                     int (*event)(void *user, const cm_eq_event *ev),
                                     void *user, int *why, char *msg, size_t msg_size)
{
    cm_model m;
    cm_status st = at(at_user, p0, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = cm_flow_dim(&m);
    double x[CM_MAX_DIM];
    memcpy(x, x0, (size_t)n * sizeof *x0);
    st = cm_flow_equilibrium(&m, p0, x, NULL, msg, msg_size);
    cm_model_release(&m);
    if (st != CM_OK)
        return st;
    eq_problem q = {{NULL, at, at_user}, msg, msg_size};
    const cm_arc_problem pr = eq_arc(&q, n);
    eq_follow f = {point, event, user};
    return cm_arc_follow(&pr, p0, x, o, eq_point, eq_event, &f, why);
}

/* ---- Hopf curves ------------------------------------------------------------ */

/* One q of a curve: the two-parameter builder at that q, and the caller's
 * callback. */
typedef struct at_q {
    cm_model_at2_fn at;
    void *at_user;
    double q;
    int (*hopf)(void *user, double q, const cm_eq_event *ev);
    void *user;
} at_q;

static cm_status model_at_q(void *user, double p, cm_model *m, char *msg, size_t msg_size)
{
    const at_q *a = user;
    return a->at(a->at_user, p, a->q, m, msg, msg_size);
}

static int hopf_at_q(void *user, const cm_eq_event *ev)
{
    const at_q *a = user;
    return ev->kind == CM_EQ_HOPF && a->hopf && a->hopf(a->user, a->q, ev);
}

cm_status cm_flow_hopf_curve(cm_model_at2_fn at, void *at_user, double p0, const double *x0,
                             const double *q, int n, const cm_branch_options *o,
                             int (*hopf)(void *user, double q, const cm_eq_event *ev), void *user,
                             char *msg, size_t msg_size)
{
    if (n < 1 || n > 100000)
        return cm_fail(CM_EINVAL, msg, msg_size, "a Hopf curve needs 1..100000 values of q");
    double start[CM_MAX_DIM];
    cm_status st = CM_OK;
    for (int k = 0; k < n && st == CM_OK; k++) {
        at_q a = {at, at_user, q[k], hopf, user};
        cm_model m;
        if ((st = model_at_q(&a, p0, &m, msg, msg_size)) != CM_OK)
            break;
        if (k == 0)
            memcpy(start, x0, (size_t)cm_flow_dim(&m) * sizeof *x0);
        st = cm_flow_equilibrium(&m, p0, start, NULL, msg, msg_size);
        cm_model_release(&m);
        int why = 0;
        if (st == CM_OK)
            st = cm_flow_equilibrium_branch(model_at_q, &a, p0, start, o, NULL, hopf_at_q, &a,
                                            &why, msg, msg_size);
        else
            st = cm_fail(CM_ENOTFOUND, msg, msg_size,
                         "the start equilibrium is lost at q = %.9g: take smaller steps in q",
                         q[k]);
        if (why == CM_BRANCH_CALLER)
            break;
    }
    return st;
}
