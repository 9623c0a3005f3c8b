/* models/flow_equilibria.c - equilibria of flows, their eigenvalues and
 * branches (models/flow_equilibria.h). */
#include "models/flow_equilibria.h"
#include "models/ode_flow.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The largest augmented system: the state and the parameter. */
enum { NMAX = CM_MAX_DIM + 1 };

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

/* Solves the n x n system a z = b (a is overwritten); false when singular. */
static bool solve(int n, double *a, const double *b, double *z)
{
    gsl_matrix_view A = gsl_matrix_view_array(a, (size_t)n, (size_t)n);
    gsl_vector_const_view B = gsl_vector_const_view_array(b, (size_t)n);
    gsl_vector_view Z = gsl_vector_view_array(z, (size_t)n);
    gsl_permutation *perm = gsl_permutation_alloc((size_t)n);
    int sign = 0;
    bool ok = perm && gsl_linalg_LU_decomp(&A.matrix, perm, &sign) == GSL_SUCCESS &&
              gsl_linalg_LU_solve(&A.matrix, perm, &B.vector, &Z.vector) == GSL_SUCCESS;
    for (int i = 0; ok && i < n; i++)
        ok = isfinite(z[i]);
    gsl_permutation_free(perm);
    return ok;
}

static bool converged(int n, const double *f, const double *x)
{
    return norm(n, f) <= 1e-10 * (1 + norm(n, x));
}

cm_status cm_flow_equilibrium(const cm_model *m, double p, double *x, cm_equilibrium *e,
                              char *msg, size_t msg_size)
{
    gsl_set_error_handler_off();
    const int n = cm_flow_dim(m);
    double f[CM_MAX_DIM], J[CM_MAX_DIM * CM_MAX_DIM], dx[CM_MAX_DIM], xt[CM_MAX_DIM],
        ft[CM_MAX_DIM], start[CM_MAX_DIM];
    memcpy(start, x, (size_t)n * sizeof *x);
    if (field_at(m, x, f))
        return cm_fail(CM_EMODEL, msg, msg_size, "the field of %s is not defined at the start",
                       m->name);
    for (int it = 0; it < 50 && !converged(n, f, x); it++) {
        double minus_f[CM_MAX_DIM];
        for (int i = 0; i < n; i++)
            minus_f[i] = -f[i];
        if (cm_flow_jacobian(m, x, J) != CM_OK || !solve(n, J, minus_f, dx))
            break;
        /* damped: the step halved until the residual falls */
        double lambda = 1, r = norm(n, f);
        int k = 0;
        for (; k < 40; k++, lambda /= 2) {
            for (int i = 0; i < n; i++)
                xt[i] = x[i] + lambda * dx[i];
            if (!field_at(m, xt, ft) && norm(n, ft) < r)
                break;
        }
        if (k == 40)
            break;
        memcpy(x, xt, (size_t)n * sizeof *x);
        memcpy(f, ft, (size_t)n * sizeof *f);
    }
    if (!converged(n, f, x))
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "Newton's method finds no equilibrium of %s from (%.6g, %.6g%s) at %.9g "
                       "(residual %.3g): start nearer one",
                       m->name, start[0], n > 1 ? start[1] : 0, n > 2 ? ", ..." : "", p,
                       norm(n, f));
    const cm_status st = e ? classify(m, p, x, e) : CM_OK;
    return st == CM_OK ? CM_OK
                       : cm_fail(st, msg, msg_size, "the eigenvalues at %.9g cannot be found", p);
}

/* ---- branches ---------------------------------------------------------------- */

/* A branch under way: the builder, and the dimension of the state. */
typedef struct branch {
    cm_model_at_fn at;
    void *at_user;
    int n;
    char *msg;
    size_t msg_size;
} branch;

/* The augmented Jacobian [df/dx, df/dp; t^T] at y = (x, p) into a (N x N)
 * and f(x, p) into f. */
static cm_status augmented(const branch *b, const double *y, const double *t, double *a,
                           double *f)
{
    const int n = b->n, N = n + 1;
    const double p = y[n], hp = 1e-7 * fmax(1, fabs(p));
    double J[CM_MAX_DIM * CM_MAX_DIM], fp[CM_MAX_DIM], fm[CM_MAX_DIM];
    cm_model m;
    cm_status st = b->at(b->at_user, p, &m, b->msg, b->msg_size);
    if (st != CM_OK)
        return st;
    st = field_at(&m, y, f) ? CM_EMODEL : cm_flow_jacobian(&m, y, J);
    cm_model_release(&m);
    for (int k = 0; k < 2 && st == CM_OK; k++) {
        st = b->at(b->at_user, k ? p - hp : p + hp, &m, b->msg, b->msg_size);
        if (st == CM_OK) {
            st = field_at(&m, y, k ? fm : fp) ? CM_EMODEL : CM_OK;
            cm_model_release(&m);
        }
    }
    if (st != CM_OK)
        return st;
    for (int i = 0; i < n; i++) {
        memcpy(a + i * N, J + i * n, (size_t)n * sizeof *J);
        a[i * N + n] = (fp[i] - fm[i]) / (2 * hp);
    }
    memcpy(a + n * N, t, (size_t)N * sizeof *t);
    return CM_OK;
}

/* The unit tangent at y, oriented along `along`. */
static cm_status tangent(const branch *b, const double *y, const double *along, double *t)
{
    const int N = b->n + 1;
    double a[NMAX * NMAX], f[CM_MAX_DIM], rhs[NMAX] = {0};
    cm_status st = augmented(b, y, along, a, f);
    rhs[b->n] = 1;
    if (st == CM_OK && !solve(N, a, rhs, t))
        st = CM_ERANGE;
    if (st != CM_OK)
        return st;
    const double len = norm(N, t);
    double dot = 0;
    for (int i = 0; i < N; i++)
        dot += t[i] * along[i];
    for (int i = 0; i < N; i++)
        t[i] /= dot < 0 ? -len : len;
    return CM_OK;
}

/* Newton on f(x, p) = 0, u . (y - y0) = 0 from y0; *iters: the
 * iterations. False when it does not converge in 8. */
static bool correct(const branch *b, const double *y0, const double *u, double *y, int *iters)
{
    const int n = b->n, N = n + 1;
    double a[NMAX * NMAX], f[CM_MAX_DIM], rhs[NMAX], dy[NMAX];
    memcpy(y, y0, (size_t)N * sizeof *y);
    for (*iters = 1; *iters <= 8; ++*iters) {
        if (augmented(b, y, u, a, f) != CM_OK)
            return false;
        double along = 0;
        for (int i = 0; i < N; i++)
            along += u[i] * (y[i] - y0[i]);
        for (int i = 0; i < n; i++)
            rhs[i] = -f[i];
        rhs[n] = -along;
        if (!solve(N, a, rhs, dy))
            return false;
        for (int i = 0; i < N; i++)
            y[i] += dy[i];
        if (norm(N, dy) <= 1e-11 * (1 + norm(N, y)) && converged(n, f, y))
            return true;
    }
    return false;
}

static cm_status classify_at(const branch *b, const double *y, cm_equilibrium *e)
{
    cm_model m;
    cm_status st = b->at(b->at_user, y[b->n], &m, b->msg, b->msg_size);
    if (st != CM_OK)
        return st;
    st = classify(&m, y[b->n], y, e);
    cm_model_release(&m);
    return st;
}

/* The test an event changes: det's sign for a fold, the unstable count
 * for a Hopf point (a pair through the axis leaves det's sign). */
static int test_of(int kind, const cm_equilibrium *e)
{
    return kind == CM_EQ_FOLD ? e->det_sign : e->unstable;
}

/* Locates the event of kind between ya (whose test gives e_a) and yb by
 * bisection along the chord, each point corrected onto the branch in the
 * plane normal to the chord, to 1e-10 of the chord. */
static cm_status locate(const branch *b, int kind, const double *ya, const cm_equilibrium *ea,
                        const double *yb, cm_eq_event *ev)
{
    const int N = b->n + 1;
    double u[NMAX], lo = 0, hi = 1, ym[NMAX], y[NMAX];
    for (int i = 0; i < N; i++)
        u[i] = yb[i] - ya[i];
    const double chord = norm(N, u);
    for (int i = 0; i < N; i++)
        u[i] /= chord;
    cm_equilibrium e = *ea;
    for (int k = 0; k < 60 && (hi - lo) * chord > 1e-10 * (1 + fabs(ya[b->n])); k++) {
        const double mid = 0.5 * (lo + hi);
        for (int i = 0; i < N; i++)
            ym[i] = ya[i] + mid * chord * u[i];
        int iters;
        if (!correct(b, ym, u, y, &iters) || classify_at(b, y, &e) != CM_OK)
            return cm_fail(CM_ERANGE, b->msg, b->msg_size,
                           "the branch cannot be followed near %.9g to locate a %s", ym[b->n],
                           kind == CM_EQ_FOLD ? "fold" : "Hopf point");
        if (test_of(kind, &e) == test_of(kind, ea))
            lo = mid;
        else
            hi = mid;
    }
    ev->kind = kind;
    ev->at = e;
    ev->omega = 0;
    if (kind == CM_EQ_HOPF) { /* the pair nearest the imaginary axis */
        double best = INFINITY;
        for (int i = 0; i < e.dim; i++)
            if (e.im[i] > 0 && fabs(e.re[i]) < best)
                best = fabs(e.re[i]), ev->omega = e.im[i];
    }
    return CM_OK;
}

/* The events between two points, in order along the branch (a fold and a
 * Hopf point in one step: the nearer first, by where each is located). */
static cm_status events_between(const branch *b, const double *ya, const cm_equilibrium *ea,
                                const double *yb, const cm_equilibrium *eb,
                                int (*event)(void *, const cm_eq_event *), void *user,
                                int *stopped)
{
    cm_eq_event found[2];
    int n = 0;
    for (int kind = CM_EQ_FOLD; kind <= CM_EQ_HOPF; kind++) {
        const bool changed = kind == CM_EQ_FOLD
                                 ? ea->det_sign != eb->det_sign
                                 : ea->unstable != eb->unstable && ea->det_sign == eb->det_sign;
        if (!changed)
            continue;
        const cm_status st = locate(b, kind, ya, ea, yb, &found[n]);
        if (st != CM_OK)
            return st;
        n++;
    }
    const int dir = yb[b->n] >= ya[b->n] ? 1 : -1;
    if (n == 2 && (found[1].at.p - found[0].at.p) * dir < 0) {
        const cm_eq_event t = found[0];
        found[0] = found[1];
        found[1] = t;
    }
    for (int k = 0; k < n && !*stopped; k++)
        *stopped = event && event(user, &found[k]);
    return CM_OK;
}

/* The branch's point at the end of the range that the step from y to yn
 * (beyond it) crosses, into yn: Newton at that parameter value from the
 * state interpolated there. False where it does not converge. */
static bool end_point(const branch *b, const cm_eq_branch_options *o, const double *y,
                      double *yn)
{
    const int n = b->n;
    const double bound = yn[n] > o->hi ? o->hi : o->lo, s = (bound - y[n]) / (yn[n] - y[n]);
    for (int i = 0; i < n; i++)
        yn[i] = y[i] + s * (yn[i] - y[i]);
    yn[n] = bound;
    cm_model m;
    if (b->at(b->at_user, bound, &m, b->msg, b->msg_size) != CM_OK)
        return false;
    const bool ok = cm_flow_equilibrium(&m, bound, yn, NULL, b->msg, b->msg_size) == CM_OK;
    cm_model_release(&m);
    return ok;
}

cm_status cm_flow_equilibrium_branch(cm_model_at_fn at, void *at_user, double p0,
                                     const double *x0, const cm_eq_branch_options *o,
                                     int (*point)(void *user, const cm_equilibrium *e),
                                     int (*event)(void *user, const cm_eq_event *ev),
                                     void *user, int *why, char *msg, size_t msg_size)
{
    *why = 0;
    if (!(o->lo < o->hi) || !(p0 >= o->lo && p0 <= o->hi) || (o->direction != 1 && o->direction != -1))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a branch needs LO < HI, a start inside them and a direction of +1 or -1");
    cm_model m;
    cm_status st = at(at_user, p0, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const branch b = {at, at_user, cm_flow_dim(&m), msg, msg_size};
    const int n = cm_flow_dim(&m), N = n + 1;
    double y[NMAX], t[NMAX], along[NMAX] = {0}, yp[NMAX], yn[NMAX], tn[NMAX];
    memcpy(y, x0, (size_t)n * sizeof *x0);
    y[n] = p0;
    cm_equilibrium e, en;
    st = cm_flow_equilibrium(&m, p0, y, &e, msg, msg_size);
    cm_model_release(&m);
    along[n] = o->direction;
    if (st == CM_OK)
        st = tangent(&b, y, along, t);
    if (st != CM_OK)
        return st;
    const double span = o->hi - o->lo, ds_max = o->ds_max > 0 ? o->ds_max : span / 50;
    double ds = o->ds > 0 ? o->ds : span / 200;
    const int max_points = o->max_points > 0 ? o->max_points : 10000;
    int stopped = point && point(user, &e), points = 1;
    while (!stopped && st == CM_OK) {
        if (points == max_points) {
            *why = CM_EQ_MAX_POINTS;
            break;
        }
        for (int i = 0; i < N; i++)
            yp[i] = y[i] + ds * t[i];
        int iters = 0;
        if (!correct(&b, yp, t, yn, &iters)) {
            ds /= 2;
            if (ds < 1e-9 * span) {
                *why = CM_EQ_LOST;
                break;
            }
            continue;
        }
        const bool last = !(yn[n] >= o->lo && yn[n] <= o->hi);
        if (last && !end_point(&b, o, y, yn)) {
            *why = CM_EQ_LEFT_RANGE; /* the range's end cannot be reached: stop short */
            break;
        }
        st = classify_at(&b, yn, &en);
        if (st == CM_OK && !last)
            st = tangent(&b, yn, t, tn);
        if (st == CM_OK)
            st = events_between(&b, y, &e, yn, &en, event, user, &stopped);
        if (st != CM_OK || stopped)
            break;
        stopped = point && point(user, &en);
        points++;
        if (last && !stopped) {
            *why = CM_EQ_LEFT_RANGE;
            break;
        }
        memcpy(y, yn, sizeof y);
        memcpy(t, tn, sizeof t);
        e = en;
        if (iters <= 3)
            ds = fmin(1.5 * ds, ds_max);
    }
    if (stopped)
        *why = CM_EQ_CALLER;
    return st;
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
                             const double *q, int n, const cm_eq_branch_options *o,
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
        if (why == CM_EQ_CALLER)
            break;
    }
    return st;
}
