/* models/arclength.c - pseudo-arclength continuation and its events
 * (models/arclength.h). */
#include "models/arclength.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdalign.h>
#include <stdlib.h>
#include <string.h>

/* The largest augmented system: the state and the parameter. */
enum { NMAX = CM_MAX_DIM + 1 };

/* A point's classification, aligned for any type the problem keeps. */
typedef struct state_buf {
    alignas(max_align_t) unsigned char b[CM_ARC_STATE_MAX];
} state_buf;

cm_status cm_model_source_at(const cm_model_source *s, double p, cm_model *own,
                             const cm_model **m, char *msg, size_t msg_size)
{
    if (s->fixed) {
        *m = s->fixed;
        return CM_OK;
    }
    const cm_status st = s->at(s->at_user, p, own, msg, msg_size);
    *m = own;
    return st;
}

void cm_model_source_done(const cm_model_source *s, cm_model *own)
{
    if (!s->fixed)
        cm_model_release(own);
}

static double norm(int n, const double *v)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

bool cm_solve_linear(int n, double *a, const double *b, double *z)
{
    gsl_set_error_handler_off(); /* statuses are read, not aborted on */
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

static bool solved(const cm_arc_problem *pr, const double *f, const double *x)
{
    return norm(pr->n, f) <= pr->tol * (1 + norm(pr->n, x));
}

/* f at (x, p), finite, or not CM_OK. */
static cm_status eval_f(const cm_arc_problem *pr, double p, const double *x, double *f)
{
    cm_status st = pr->eval(pr->ctx, p, x, f, NULL);
    for (int i = 0; st == CM_OK && i < pr->n; i++)
        if (!isfinite(f[i]))
            st = CM_EMODEL;
    return st;
}

cm_status cm_arc_newton(const cm_arc_problem *pr, double p, double *x)
{
    const int n = pr->n;
    double f[CM_MAX_DIM], J[CM_MAX_DIM * CM_MAX_DIM], dx[CM_MAX_DIM], xt[CM_MAX_DIM],
        ft[CM_MAX_DIM], minus_f[CM_MAX_DIM];
    cm_status st = eval_f(pr, p, x, f);
    for (int it = 0; st == CM_OK && it < 50 && !solved(pr, f, x); it++) {
        for (int i = 0; i < n; i++)
            minus_f[i] = -f[i];
        if (pr->eval(pr->ctx, p, x, f, J) != CM_OK || !cm_solve_linear(n, J, minus_f, dx))
            break;
        /* damped: the step halved until the residual falls */
        double lambda = 1;
        const double r = norm(n, f);
        int k = 0;
        for (; k < 40; k++, lambda /= 2) {
            for (int i = 0; i < n; i++)
                xt[i] = x[i] + lambda * dx[i];
            if (eval_f(pr, p, xt, ft) == CM_OK && norm(n, ft) < r)
                break;
        }
        if (k == 40)
            break;
        memcpy(x, xt, (size_t)n * sizeof *x);
        memcpy(f, ft, (size_t)n * sizeof *f);
    }
    if (st != CM_OK)
        return st;
    return solved(pr, f, x) ? CM_OK : CM_ENOTFOUND;
}

/* The augmented Jacobian [df/dx, df/dp; t^T] at y = (x, p) into a (N x N)
 * and f(x, p) into f. */
static cm_status augmented(const cm_arc_problem *pr, const double *y, const double *t,
                           double *a, double *f)
{
    const int n = pr->n, N = n + 1;
    const double p = y[n], hp = 1e-7 * fmax(1, fabs(p));
    double J[CM_MAX_DIM * CM_MAX_DIM], fp[CM_MAX_DIM], fm[CM_MAX_DIM];
    cm_status st = pr->eval(pr->ctx, p, y, f, J);
    if (st == CM_OK)
        st = eval_f(pr, p + hp, y, fp);
    if (st == CM_OK)
        st = eval_f(pr, p - hp, y, fm);
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
static cm_status tangent(const cm_arc_problem *pr, const double *y, const double *along,
                         double *t)
{
    const int N = pr->n + 1;
    double a[NMAX * NMAX], f[CM_MAX_DIM], rhs[NMAX] = {0};
    cm_status st = augmented(pr, y, along, a, f);
    rhs[pr->n] = 1;
    if (st == CM_OK && !cm_solve_linear(N, a, rhs, t))
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
static bool correct(const cm_arc_problem *pr, const double *y0, const double *u, double *y,
                    int *iters)
{
    const int n = pr->n, N = n + 1;
    double a[NMAX * NMAX], f[CM_MAX_DIM], rhs[NMAX], dy[NMAX];
    memcpy(y, y0, (size_t)N * sizeof *y);
    for (*iters = 1; *iters <= 8; ++*iters) {
        if (augmented(pr, y, u, a, f) != CM_OK)
            return false;
        double along = 0;
        for (int i = 0; i < N; i++)
            along += u[i] * (y[i] - y0[i]);
        for (int i = 0; i < n; i++)
            rhs[i] = -f[i];
        rhs[n] = -along;
        if (!cm_solve_linear(N, a, rhs, dy))
            return false;
        for (int i = 0; i < N; i++)
            y[i] += dy[i];
        if (norm(N, dy) <= 1e-11 * (1 + norm(N, y)) && solved(pr, f, y))
            return true;
    }
    return false;
}

/* A located event: the test, where along the chord (0..1) and the state. */
typedef struct found {
    int test;
    double at;
    state_buf state;
} found;

/* Locates where test k changes between ya (tests ta) and yb by bisection
 * along the chord, each point corrected onto the branch in the plane
 * normal to the chord, to 1e-10 of the chord. */
static cm_status locate(const cm_arc_problem *pr, int k, const double *ya, const int *ta,
                        const double *yb, found *out)
{
    const int N = pr->n + 1;
    double u[NMAX], lo = 0, hi = 1, ym[NMAX], y[NMAX];
    for (int i = 0; i < N; i++)
        u[i] = yb[i] - ya[i];
    const double chord = norm(N, u);
    for (int i = 0; i < N; i++)
        u[i] /= chord;
    int tests[CM_ARC_TESTS];
    bool have = false;
    for (int it = 0; it < 60 && (hi - lo) * chord > 1e-10 * (1 + fabs(ya[pr->n])); it++) {
        const double mid = 0.5 * (lo + hi);
        for (int i = 0; i < N; i++)
            ym[i] = ya[i] + mid * chord * u[i];
        int iters;
        if (!correct(pr, ym, u, y, &iters) ||
            pr->classify(pr->ctx, y[pr->n], y, out->state.b, tests) != CM_OK)
            return cm_fail(CM_ERANGE, pr->msg, pr->msg_size,
                           "the branch cannot be followed near %.9g to locate where a test "
                           "changes",
                           ym[pr->n]);
        have = true;
        if (tests[k] == ta[k])
            lo = mid;
        else
            hi = mid;
    }
    out->test = k;
    out->at = hi;
    /* a chord already that short: its far end */
    return have ? CM_OK : pr->classify(pr->ctx, yb[pr->n], yb, out->state.b, tests);
}

static int by_place(const void *a, const void *b)
{
    const double x = ((const found *)a)->at, y = ((const found *)b)->at;
    return (x > y) - (x < y);
}

/* The events between two points, in order along the branch. */
static cm_status events_between(const cm_arc_problem *pr, const double *ya, const int *ta,
                                const double *yb, const int *tb,
                                int (*event)(void *, int, const void *), void *user,
                                int *stopped)
{
    found f[CM_ARC_TESTS];
    int n = 0;
    bool other = false;
    for (int k = 0; k < pr->n_tests; k++)
        other |= k != pr->count_test && ta[k] != tb[k];
    for (int k = 0; k < pr->n_tests; k++) {
        if (ta[k] == tb[k] || (k == pr->count_test && other))
            continue;
        f[n].test = k;
        const cm_status st = locate(pr, k, ya, ta, yb, &f[n]);
        if (st != CM_OK)
            return st;
        n++;
    }
    qsort(f, (size_t)n, sizeof *f, by_place);
    for (int k = 0; k < n && !*stopped; k++)
        *stopped = event && event(user, f[k].test, f[k].state.b);
    return CM_OK;
}

/* The branch's point at the end of the range that the step from y to yn
 * (beyond it) crosses, into yn: Newton at that parameter value from the
 * state interpolated there. False where it does not converge. */
static bool end_point(const cm_arc_problem *pr, const cm_branch_options *o, const double *y,
                      double *yn)
{
    const int n = pr->n;
    const double bound = yn[n] > o->hi ? o->hi : o->lo, s = (bound - y[n]) / (yn[n] - y[n]);
    for (int i = 0; i < n; i++)
        yn[i] = y[i] + s * (yn[i] - y[i]);
    yn[n] = bound;
    return cm_arc_newton(pr, bound, yn) == CM_OK;
}

cm_status cm_arc_follow(const cm_arc_problem *pr, double p0, const double *x0,
                        const cm_branch_options *o, int (*point)(void *user, const void *state),
                        int (*event)(void *user, int test, const void *state), void *user,
                        int *why)
{
    *why = 0;
    if (!(o->lo < o->hi) || !(p0 >= o->lo && p0 <= o->hi) ||
        (o->direction != 1 && o->direction != -1) || pr->n < 1 || pr->n > CM_MAX_DIM ||
        pr->state_size > CM_ARC_STATE_MAX || pr->n_tests < 0 || pr->n_tests > CM_ARC_TESTS)
        return cm_fail(CM_EINVAL, pr->msg, pr->msg_size,
                       "a branch needs LO < HI, a start inside them and a direction of +1 or -1");
    const int n = pr->n, N = n + 1;
    double y[NMAX], t[NMAX], along[NMAX] = {0}, yp[NMAX], yn[NMAX], tn[NMAX];
    int tests[CM_ARC_TESTS], tests_n[CM_ARC_TESTS];
    state_buf s;
    memcpy(y, x0, (size_t)n * sizeof *x0);
    y[n] = p0;
    along[n] = o->direction;
    cm_status st = cm_arc_newton(pr, p0, y);
    if (st == CM_OK)
        st = pr->classify(pr->ctx, p0, y, s.b, tests);
    if (st == CM_OK)
        st = tangent(pr, y, along, t);
    if (st != CM_OK)
        return st;
    const double span = o->hi - o->lo, ds_max = o->ds_max > 0 ? o->ds_max : span / 50;
    double ds = o->ds > 0 ? o->ds : span / 200;
    const int max_points = o->max_points > 0 ? o->max_points : 10000;
    int stopped = point && point(user, s.b), points = 1;
    while (!stopped && st == CM_OK) {
        if (points == max_points) {
            *why = CM_BRANCH_MAX_POINTS;
            break;
        }
        for (int i = 0; i < N; i++)
            yp[i] = y[i] + ds * t[i];
        int iters = 0;
        if (!correct(pr, yp, t, yn, &iters)) {
            ds /= 2;
            if (ds < 1e-9 * span) {
                *why = CM_BRANCH_LOST;
                break;
            }
            continue;
        }
        const bool last = !(yn[n] >= o->lo && yn[n] <= o->hi);
        if (last && !end_point(pr, o, y, yn)) {
            *why = CM_BRANCH_LEFT_RANGE; /* the range's end cannot be reached: stop short */
            break;
        }
        st = pr->classify(pr->ctx, yn[n], yn, s.b, tests_n);
        if (st == CM_OK && !last)
            st = tangent(pr, yn, t, tn);
        if (st == CM_OK)
            st = events_between(pr, y, tests, yn, tests_n, event, user, &stopped);
        if (st != CM_OK || stopped)
            break;
        stopped = point && point(user, s.b);
        points++;
        if (last && !stopped) {
            *why = CM_BRANCH_LEFT_RANGE;
            break;
        }
        memcpy(y, yn, sizeof y);
        memcpy(t, tn, sizeof t);
        memcpy(tests, tests_n, sizeof tests);
        if (iters <= 3)
            ds = fmin(1.5 * ds, ds_max);
    }
    if (stopped)
        *why = CM_BRANCH_CALLER;
    return st;
}
