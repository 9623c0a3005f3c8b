/* Lyapunov exponents of delay equations (models/dde_lyapunov.h). */
#include "models/dde_lyapunov.h"

#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/ode_flow.h"
#include "models/ode_steps.h"

/* ---- the synchronisation estimate ---- */

typedef struct coupled {
    const cm_dde *d;
    double q, offset;
    bool own_delay;
} coupled;

static int coupled_field(const void *ctx, double t, const double *x, const double *xd,
                         double *f)
{
    const coupled *c = ctx;
    const int n = c->d->dim;
    /* both halves read the first one's delayed state (3.38)-(3.39) */
    if (c->d->field(c->d->ctx, t, x, xd, f) ||
        c->d->field(c->d->ctx, t, x + n, c->own_delay ? xd + n : xd, f + n))
        return 1;
    for (int i = 0; i < n; i++)
        f[i] += c->q * (x[n + i] - x[i]);
    return 0;
}

static void coupled_history(const void *ctx, double t, double *x)
{
    const coupled *c = ctx;
    const int n = c->d->dim;
    c->d->history(c->d->ctx, t, x);
    for (int i = 0; i < n; i++)
        x[n + i] = x[i] + c->offset;
}

static double coupled_break(const void *ctx, double t)
{
    const coupled *c = ctx;
    return c->d->next_break ? c->d->next_break(c->d->ctx, t) : INFINITY;
}

typedef struct gap {
    int n;
    double from, largest;
} gap;

static int watch_gap(void *user, double t, const double *x)
{
    gap *g = user;
    if (t >= g->from)
        for (int i = 0; i < g->n; i++)
            g->largest = fmax(g->largest, fabs(x[g->n + i] - x[i]));
    return 0;
}

/* Whether the copies synchronise at coupling q. */
static cm_status synchronises(const cm_dde *d, const cm_sync_options *o, double q, bool *yes,
                              char *msg, size_t msg_size)
{
    const coupled c = {d, q, o->offset, o->own_delay};
    cm_dde both = *d;
    both.dim = 2 * d->dim;
    both.field = coupled_field, both.history = coupled_history, both.ctx = &c;
    both.next_break = coupled_break;
    gap g = {d->dim, o->t1 - 0.1 * (o->t1 - o->t0), 0};
    const cm_status st = cm_dde_solve(&both, o->t0, o->t1, (o->t1 - o->t0) / 1000, watch_gap, &g,
                                      NULL, msg, msg_size);
    *yes = st == CM_OK && g.largest < 1e-3 * o->offset;
    return st;
}

cm_status cm_dde_sync_estimate(const cm_dde *d, const cm_sync_options *o, double *q_sync,
                               char *msg, size_t msg_size)
{
    if (d->dim > CM_DDE_MAX_DIM / 2)
        return cm_fail(CM_EINVAL, msg, msg_size, "the coupled copies need 2 x %d coordinates: "
                       "at most %d", d->dim, CM_DDE_MAX_DIM);
    if (!(o->offset > 0 && o->lo >= 0 && o->hi > o->lo && o->q_tol > 0))
        return cm_fail(CM_EINVAL, msg, msg_size, "the estimate needs offset > 0, 0 <= lo < hi "
                       "and q_tol > 0");
    double lo = o->lo, hi = o->hi;
    bool yes;
    cm_status st = synchronises(d, o, lo, &yes, msg, msg_size);
    if (st == CM_OK && yes)
        return cm_fail(CM_ERANGE, msg, msg_size, "the copies synchronise already at q = %g: "
                       "lower lo (the largest exponent is below it)", lo);
    if (st == CM_OK)
        st = synchronises(d, o, hi, &yes, msg, msg_size);
    if (st == CM_OK && !yes)
        return cm_fail(CM_ERANGE, msg, msg_size, "the copies do not synchronise even at q = %g: "
                       "raise hi or lengthen the run", hi);
    while (st == CM_OK && hi - lo > o->q_tol) {
        const double mid = 0.5 * (lo + hi);
        st = synchronises(d, o, mid, &yes, msg, msg_size);
        *(yes ? &hi : &lo) = mid;
    }
    *q_sync = 0.5 * (lo + hi);
    return st;
}

/* ---- Farmer's discretised map ---- */

/* One step of the discretised map: the state and k tangent heads over
 * [ta, ta + D] with the delayed input (state and tangents) linear between
 * the samples at its ends. */
typedef struct farmer_step {
    const cm_dde *d;
    int k;
    double ta, D;
    const double *xa, *xb;             /* x(t - N D), x(t - (N - 1) D) */
    const double *wa[CM_FARMER_MAX], *wb[CM_FARMER_MAX]; /* the tangents' same samples */
} farmer_step;

/* The delayed input at s: a + theta (b - a). */
static void between(int n, const double *a, const double *b, double theta, double *out)
{
    for (int i = 0; i < n; i++)
        out[i] = a[i] + theta * (b[i] - a[i]);
}

static int farmer_field(double s, const double y[], double f[], void *params)
{
    const farmer_step *p = params;
    const cm_dde *d = p->d;
    const int n = d->dim;
    const double theta = (s - p->ta) / p->D;
    double u[CM_DDE_MAX_DIM];
    between(n, p->xa, p->xb, theta, u);
    if (d->field(d->ctx, s, y, u, f))
        return GSL_EBADFUNC;
    for (int j = 0; j < p->k; j++) {
        /* Df (v, w) by central differences along the tangent's head v and its delayed part w */
        const double *v = y + (size_t)(j + 1) * n;
        double w[CM_DDE_MAX_DIM], xp[CM_DDE_MAX_DIM], xm[CM_DDE_MAX_DIM], up[CM_DDE_MAX_DIM],
            um[CM_DDE_MAX_DIM], fp[CM_DDE_MAX_DIM], fm[CM_DDE_MAX_DIM];
        between(n, p->wa[j], p->wb[j], theta, w);
        double norm = 0, scale = 1;
        for (int i = 0; i < n; i++) {
            norm = fmax(norm, fmax(fabs(v[i]), fabs(w[i])));
            scale = fmax(scale, fmax(fabs(y[i]), fabs(u[i])));
        }
        double *out = f + (size_t)(j + 1) * n;
        if (norm == 0) {
            memset(out, 0, (size_t)n * sizeof *out);
            continue;
        }
        const double h = 1e-7 * scale / norm;
        for (int i = 0; i < n; i++) {
            xp[i] = y[i] + h * v[i], xm[i] = y[i] - h * v[i];
            up[i] = u[i] + h * w[i], um[i] = u[i] - h * w[i];
        }
        if (d->field(d->ctx, s, xp, up, fp) || d->field(d->ctx, s, xm, um, fm))
            return GSL_EBADFUNC;
        for (int i = 0; i < n; i++)
            out[i] = (fp[i] - fm[i]) / (2 * h);
    }
    return GSL_SUCCESS;
}

/* The last N + 1 samples of the delay equation, every D, newest first. */
typedef struct sampler {
    int n, N;
    double *ring; /* (N + 1) x n, slot i % (N + 1) for sample i */
    long count;
} sampler;

static int take_sample(void *user, double t, const double *x)
{
    (void)t;
    sampler *s = user;
    memcpy(s->ring + (size_t)(s->count % (s->N + 1)) * s->n, x, (size_t)s->n * sizeof *x);
    s->count++;
    return 0;
}

static cm_status check_farmer(const cm_dde *d, const cm_farmer_options *o, char *msg,
                              size_t msg_size)
{
    if (!(d->delay > 0))
        return cm_fail(CM_EINVAL, msg, msg_size, "the delay must be positive: give delay > 0");
    if (o->samples < 1 || o->samples > CM_FARMER_MAX_SAMPLES || o->gs < 1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "Farmer's map needs 1..%d samples per delay and a Gram-Schmidt step every "
                       "gs >= 1 steps",
                       CM_FARMER_MAX_SAMPLES);
    const long dim = (long)d->dim * (o->samples + 1);
    if (o->count < 1 || o->count > CM_FARMER_MAX || o->count > dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d exponents asked: give 1..%d (and at most the map's %ld)", o->count,
                       CM_FARMER_MAX, dim);
    if (!(o->transient >= d->delay && o->time > 0 && o->time / (d->delay / o->samples) <= 1e9))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "Farmer's map needs a transient of at least the delay (%g) and a time > 0 "
                       "of at most 1e9 steps",
                       d->delay);
    return CM_OK;
}

/* The map's memory: the samples (newest first) and the k tangents, each
 * dim (N + 1) long, and the step's GSL system of the state and k heads. */
typedef struct farmer_run {
    int n, N, k;
    bool euler;
    size_t len; /* n (N + 1) */
    double *x, *v, *y, *saved;
    gsl_odeiv2_driver *drv;
    farmer_step step;
    gsl_odeiv2_system sys;
} farmer_run;

static void farmer_close(farmer_run *r)
{
    if (r->drv)
        gsl_odeiv2_driver_free(r->drv);
    free(r->x);
}

static bool farmer_open(farmer_run *r, const cm_dde *d, const cm_farmer_options *o)
{
    memset(r, 0, sizeof *r);
    r->n = d->dim, r->N = o->samples, r->k = o->count;
    r->len = (size_t)r->n * (size_t)(r->N + 1);
    const size_t heads = (size_t)r->n * (size_t)(r->k + 1);
    r->x = malloc((r->len * (size_t)(r->k + 1) + 2 * heads) * sizeof *r->x);
    if (!r->x)
        return false;
    r->v = r->x + r->len;
    r->y = r->v + r->len * (size_t)r->k;
    r->saved = r->y + heads;
    /* Euler's tangents are no part of the integrated system */
    const int integrated = o->euler_tangent ? 0 : r->k;
    r->euler = o->euler_tangent;
    r->step = (farmer_step){.d = d, .k = integrated, .D = d->delay / r->N};
    r->sys = (gsl_odeiv2_system){farmer_field, NULL, (size_t)r->n * (size_t)(integrated + 1),
                                 &r->step};
    const double abs_tol = d->abs_tol > 0 ? d->abs_tol : 1e-9,
                 rel_tol = d->rel_tol > 0 ? d->rel_tol : 1e-9;
    /* the tangents' error held to max(abs_tol, 1e-8), as cm_flow_spectrum's */
    double *scale = r->saved; /* used before any step needs it as scratch */
    for (size_t i = 0; i < r->sys.dimension; i++)
        scale[i] = i < (size_t)r->n ? 1 : fmax(1, 1e-8 / abs_tol);
    r->drv = gsl_odeiv2_driver_alloc_scaled_new(&r->sys, cm_flow_stepper(d->method),
                                                fmin(1e-3, r->step.D), abs_tol, rel_tol, 1, 0,
                                                scale);
    return r->drv != NULL;
}

/* One step of the map from time t: integrate the state and the tangents'
 * heads over D (in pieces at the equation's own breakpoints) and shift
 * every sample back by one. */
static bool farmer_advance(farmer_run *r, double t, double *h)
{
    const int n = r->n, N = r->N;
    farmer_step *p = &r->step;
    const cm_dde *d = p->d;
    p->ta = t;
    p->xa = r->x + (size_t)N * n;
    p->xb = r->x + (size_t)(N - 1) * n;
    memcpy(r->y, r->x, (size_t)n * sizeof *r->y);
    for (int j = 0; j < r->k; j++) {
        const double *vj = r->v + r->len * (size_t)j;
        p->wa[j] = vj + (size_t)N * n;
        p->wb[j] = vj + (size_t)(N - 1) * n;
        if (r->euler) { /* v + D Df(x, x(t - N D)) (v, v(t - N D)), at the step's start */
            double *head = r->y + (size_t)(j + 1) * n, f[CM_DDE_MAX_DIM];
            memcpy(head, vj, (size_t)n * sizeof *head);
            farmer_step at = *p;
            at.k = 1, at.wa[0] = p->wa[j], at.wb[0] = p->wa[j];
            double pair[2 * CM_DDE_MAX_DIM], rates[2 * CM_DDE_MAX_DIM];
            memcpy(pair, r->x, (size_t)n * sizeof *pair);
            memcpy(pair + n, vj, (size_t)n * sizeof *pair);
            if (farmer_field(t, pair, rates, &at) != GSL_SUCCESS)
                return false;
            memcpy(f, rates + n, (size_t)n * sizeof *f);
            for (int i = 0; i < n; i++)
                head[i] += p->D * f[i];
        } else {
            memcpy(r->y + (size_t)(j + 1) * n, vj, (size_t)n * sizeof *r->y);
        }
    }
    const size_t size = r->sys.dimension;
    double s = t;
    const double end = t + p->D;
    while (s < end) {
        const double brk = d->next_break ? d->next_break(d->ctx, s) : INFINITY;
        const double stop = fmin(brk, end);
        if (!cm_ode_advance(r->drv, size, &s, stop, h, r->y, r->saved))
            return false;
        if (stop == brk)
            cm_ode_restart(r->drv);
    }
    memmove(r->x + n, r->x, (size_t)N * n * sizeof *r->x);
    memcpy(r->x, r->y, (size_t)n * sizeof *r->x);
    for (int j = 0; j < r->k; j++) {
        double *vj = r->v + r->len * (size_t)j;
        memmove(vj + n, vj, (size_t)N * n * sizeof *vj);
        memcpy(vj, r->y + (size_t)(j + 1) * n, (size_t)n * sizeof *vj);
    }
    return true;
}

/* The samples of the delay equation at t_start, t_start - D, ...,
 * t_start - N D into r->x; k orthonormal start vectors into r->v. */
static cm_status farmer_start(farmer_run *r, const cm_dde *d, double t_start, char *msg,
                              size_t msg_size)
{
    sampler s = {r->n, r->N, r->v, 0}; /* the tangents' memory holds the ring for now */
    const cm_status st =
        cm_dde_solve(d, 0, t_start, r->step.D, take_sample, &s, NULL, msg, msg_size);
    if (st != CM_OK)
        return st;
    for (int i = 0; i <= r->N; i++) /* newest first */
        memcpy(r->x + (size_t)i * r->n, s.ring + (size_t)((s.count - 1 - i) % (r->N + 1)) * r->n,
               (size_t)r->n * sizeof *r->x);
    for (int j = 0; j < r->k; j++)
        for (size_t i = 0; i < r->len; i++)
            r->v[r->len * (size_t)j + i] =
                (i == (size_t)j ? 1.0 : 0.0) + 1e-3 * (double)((i + 2 * (size_t)j) % 7 + 1);
    double unused[CM_FARMER_MAX];
    cm_gram_schmidt((int)r->len, r->k, r->v, unused);
    return CM_OK;
}

cm_status cm_dde_farmer(const cm_dde *d, const cm_farmer_options *o, cm_spectrum_trace trace,
                        void *user, cm_farmer_result *out, char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    cm_status st = check_farmer(d, o, msg, msg_size);
    if (st != CM_OK)
        return st;
    farmer_run r;
    if (!farmer_open(&r, d, o)) {
        farmer_close(&r);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for Farmer's map");
    }
    /* the equation itself up to the first delay (the map's first state),
     * then the map through the transient, its vectors aligning, then the sums */
    const double D = r.step.D, t_map = r.N * D;
    const long skip = (long)ceil((o->transient - t_map) / D - 1e-9);
    const long steps = (long)ceil(o->time / D - 1e-9);
    st = farmer_start(&r, d, t_map, msg, msg_size);
    double sum[CM_FARMER_MAX] = {0}, logs[CM_FARMER_MAX], running[CM_FARMER_MAX];
    double h = fmin(1e-3, D), t = t_map;
    for (long s = -skip; st == CM_OK && s < steps; s++) {
        t = t_map + (double)(s + skip) * D;
        if (!farmer_advance(&r, t, &h)) {
            st = cm_fail(CM_EMODEL, msg, msg_size,
                         "Farmer's map lost the orbit at t = %.9g: tighten the tolerances", t);
            break;
        }
        const bool last = s + 1 == steps;
        if ((s + 1) % o->gs && !last && s + 1 != 0)
            continue;
        if (!cm_gram_schmidt((int)r.len, r.k, r.v, logs)) {
            st = cm_fail(CM_EMODEL, msg, msg_size,
                         "Farmer's map's tangent vectors collapsed at t = %.9g", t + D);
            break;
        }
        if (s < 0)
            continue; /* the transient: aligning only */
        const double span = (double)(s + 1) * D;
        for (int j = 0; j < r.k; j++) {
            sum[j] += logs[j];
            running[j] = sum[j] / span;
        }
        if (trace && trace(user, span, running, r.k))
            st = cm_fail(CM_ECANCELED, msg, msg_size, "stopped at t = %.9g", t + D);
    }
    if (st == CM_OK) {
        out->count = r.k;
        out->dim = (long)r.len;
        out->time = (double)steps * D;
        for (int j = 0; j < r.k; j++)
            out->lambda[j] = sum[j] / out->time;
        cm_sort_decreasing(out->lambda, r.k);
        out->kaplan_yorke = cm_kaplan_yorke(out->lambda, r.k);
    }
    farmer_close(&r);
    return st;
}
