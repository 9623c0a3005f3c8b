/* Lyapunov spectra of flows (variational equations) and maps (QR of the
 * Jacobian), by Benettin's method with modified Gram-Schmidt. */
#include "models/lyapunov_spectrum.h"

#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/linalg.h"
#include "models/map_periodic.h"
#include "models/ode_flow.h"
#include "models/ode_steps.h"

bool cm_gram_schmidt(int n, int k, double *v, double *log_norm)
{
    for (int j = 0; j < k; j++) {
        double *vj = v + (size_t)j * n;
        for (int i = 0; i < j; i++) {
            const double *vi = v + (size_t)i * n;
            double dot = 0;
            for (int d = 0; d < n; d++)
                dot += vi[d] * vj[d];
            for (int d = 0; d < n; d++)
                vj[d] -= dot * vi[d];
        }
        double norm2 = 0;
        for (int d = 0; d < n; d++)
            norm2 += vj[d] * vj[d];
        const double norm = sqrt(norm2);
        if (!(norm > 0) || !isfinite(norm))
            return false;
        for (int d = 0; d < n; d++)
            vj[d] /= norm;
        log_norm[j] = log(norm);
    }
    return true;
}

double cm_kaplan_yorke(const double *lambda, int k)
{
    double sum = 0;
    for (int j = 0; j < k; j++) {
        if (sum + lambda[j] < 0)
            return j + sum / fabs(lambda[j]);
        sum += lambda[j];
    }
    return NAN;
}

void cm_sort_decreasing(double *lambda, int k)
{
    for (int i = 1; i < k; i++)
        for (int j = i; j > 0 && lambda[j] > lambda[j - 1]; j--) {
            const double t = lambda[j];
            lambda[j] = lambda[j - 1];
            lambda[j - 1] = t;
        }
}

/* k orthonormal start vectors: the first k unit vectors, turned a little
 * so that none starts on an invariant coordinate plane of the flow. */
static void start_vectors(int n, int k, double *v)
{
    for (int j = 0; j < k; j++)
        for (int d = 0; d < n; d++)
            v[(size_t)j * n + d] = (d == j ? 1.0 : 0.0) + 1e-3 * (double)((d + 2 * j) % 5 + 1);
    double unused[CM_MAX_DIM];
    cm_gram_schmidt(n, k, v, unused);
}

static cm_status check_count(int n, const cm_spectrum_options *o, int *count, char *msg,
                             size_t msg_size)
{
    *count = o->count ? o->count : n;
    if (*count < 1 || *count > n) {
        snprintf(msg, msg_size, "%d exponents asked of a %d-dimensional system: give 1..%d",
                 o->count, n, n);
        return CM_EINVAL;
    }
    return CM_OK;
}

static void finish(cm_spectrum *out, const double *sum, double span)
{
    for (int j = 0; j < out->count; j++)
        out->lambda[j] = sum[j] / span;
    cm_sort_decreasing(out->lambda, out->count);
    out->kaplan_yorke = cm_kaplan_yorke(out->lambda, out->count);
}

/* ---- flows ---- */

/* The state and its k tangent vectors as one GSL system. */
typedef struct variational {
    const cm_model *m;
    int n, k;
} variational;

/* Df(t, x) v by central differences along v; nonzero where the field
 * fails. */
static int field_along(const cm_model *m, int n, double t, const double *x, const double *v,
                       double *out)
{
    double norm = 0, scale = 1;
    for (int d = 0; d < n; d++) {
        norm = fmax(norm, fabs(v[d]));
        scale = fmax(scale, fabs(x[d]));
    }
    if (norm == 0) {
        memset(out, 0, (size_t)n * sizeof *out);
        return 0;
    }
    const double h = 1e-7 * scale / norm;
    double xp[CM_MAX_DIM], xm[CM_MAX_DIM], fp[CM_MAX_DIM], fm[CM_MAX_DIM];
    for (int d = 0; d < n; d++)
        xp[d] = x[d] + h * v[d], xm[d] = x[d] - h * v[d];
    if (m->flow.field(m, t, xp, fp) || m->flow.field(m, t, xm, fm))
        return 1;
    for (int d = 0; d < n; d++)
        out[d] = (fp[d] - fm[d]) / (2 * h);
    return 0;
}

static int variational_field(double t, const double y[], double f[], void *params)
{
    const variational *s = params;
    if (s->m->flow.field(s->m, t, y, f))
        return GSL_EBADFUNC;
    for (int j = 1; j <= s->k; j++)
        if (field_along(s->m, s->n, t, y, y + (size_t)j * s->n, f + (size_t)j * s->n))
            return GSL_EBADFUNC;
    return GSL_SUCCESS; /* a non-finite value is advance_to's to handle */
}

/* The implicit steppers' Jacobian of the augmented system, block-diagonal
 * with Df in every block: the tangents' dependence on the state (second
 * derivatives) is left out, which only slows their Newton iterations. */
static int variational_jacobian(double t, const double y[], double *dfdy, double dfdt[],
                                void *params)
{
    const variational *s = params;
    const int n = s->n, big = n * (s->k + 1);
    double J[CM_MAX_DIM * CM_MAX_DIM];
    if (cm_flow_jacobian_at(s->m, t, y, J) != CM_OK)
        return GSL_EBADFUNC;
    memset(dfdy, 0, (size_t)big * (size_t)big * sizeof *dfdy);
    for (int b = 0; b <= s->k; b++)
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                dfdy[(size_t)(b * n + i) * (size_t)big + (size_t)(b * n + j)] = J[i * n + j];
    double *fp = malloc(2 * (size_t)big * sizeof *fp);
    if (!fp)
        return GSL_ENOMEM;
    double *fm = fp + big;
    const double h = 1e-7 * fmax(1, fabs(t));
    const int rc =
        variational_field(t + h, y, fp, params) || variational_field(t - h, y, fm, params);
    for (int i = 0; i < big && !rc; i++)
        dfdt[i] = (fp[i] - fm[i]) / (2 * h);
    free(fp);
    return rc ? GSL_EBADFUNC : GSL_SUCCESS;
}

static cm_status check_flow_options(const cm_model *m, const cm_spectrum_options *o, int *count,
                                    char *msg, size_t msg_size)
{
    if (!cm_model_is_flow(m)) {
        snprintf(msg, msg_size, "model %s is a map, not a flow: take its map's spectrum", m->name);
        return CM_EINVAL;
    }
    if (!(o->time > 0 && o->renorm > 0 && o->renorm <= o->time && o->transient >= 0 &&
          o->time / o->renorm <= 1e8)) {
        snprintf(msg, msg_size,
                 "the spectrum needs time > 0, 0 < renorm <= time (at most 1e8 renormalisations) "
                 "and transient >= 0");
        return CM_EINVAL;
    }
    return check_count(cm_flow_dim(m), o, count, msg, msg_size);
}

cm_status cm_flow_spectrum(const cm_model *m, const double *x0, const cm_spectrum_options *o,
                           cm_spectrum_trace trace, void *user, cm_spectrum *out, char *msg,
                           size_t msg_size)
{
    memset(out, 0, sizeof *out);
    int k;
    cm_status st = check_flow_options(m, o, &k, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = cm_flow_dim(m);
    variational s = {m, n, k};
    const size_t size = (size_t)(n * (k + 1));
    gsl_odeiv2_system sys = {variational_field, variational_jacobian, size, &s};
    /* The tangents' error per step is held to max(abs_tol, 1e-8) rather
     * than the state's: Df v by differences carries noise near 1e-9 |f|
     * (more where a stiff field is large), which a tighter control cannot
     * step below (it would shrink the steps to nothing), and an error of
     * 1e-8 in a unit vector moves an exponent by 1e-8 / renorm. */
    double *y = malloc(3 * size * sizeof *y);
    gsl_odeiv2_driver *d = NULL;
    if (y) {
        double *scale = y + 2 * size;
        for (size_t i = 0; i < size; i++)
            scale[i] = i < (size_t)n ? 1 : fmax(1, 1e-8 / m->flow.abs_tol);
        d = gsl_odeiv2_driver_alloc_scaled_new(&sys, cm_flow_stepper(m->flow.method),
                                               fmin(1e-3, o->renorm), m->flow.abs_tol,
                                               m->flow.rel_tol, 1, 0, scale);
    }
    if (!d || !y) {
        if (d)
            gsl_odeiv2_driver_free(d);
        free(y);
        snprintf(msg, msg_size, "out of memory for the variational equations");
        return CM_ENOMEM;
    }
    double *saved = y + size;
    memcpy(y, x0, (size_t)n * sizeof *y);
    start_vectors(n, k, y + n);
    out->n = n, out->count = k;
    double t = m->flow.t0, h = fmin(1e-3, o->renorm), sum[CM_MAX_DIM] = {0}, logs[CM_MAX_DIM],
           running[CM_MAX_DIM];
    const double t_start = t + o->transient;
    const long renorms = (long)ceil(o->time / o->renorm - 1e-9);
    /* the transient in renorm steps too, so the vectors stay bounded */
    for (double next = t + o->renorm; st == CM_OK && t < t_start; next += o->renorm)
        if (!cm_ode_advance(d, size, &t, fmin(next, t_start), &h, y, saved) ||
            !cm_gram_schmidt(n, k, y + n, logs))
            st = CM_EMODEL;
    for (long r = 1; st == CM_OK && r <= renorms; r++) {
        const double t1 = t_start + fmin((double)r * o->renorm, o->time);
        if (!cm_ode_advance(d, size, &t, t1, &h, y, saved) || !cm_gram_schmidt(n, k, y + n, logs)) {
            st = CM_EMODEL;
            break;
        }
        for (int j = 0; j < k; j++) {
            sum[j] += logs[j];
            running[j] = sum[j] / (t - t_start);
        }
        if (trace && trace(user, t - t_start, running, k))
            st = CM_ECANCELED;
    }
    if (st == CM_EMODEL)
        snprintf(msg, msg_size,
                 "the orbit or its tangent vectors were lost at t = %.9g (the field failed or "
                 "overflowed): start elsewhere or tighten abs_tol/rel_tol",
                 t);
    else if (st == CM_ECANCELED)
        snprintf(msg, msg_size, "stopped at t = %.9g", t);
    if (st == CM_OK) {
        finish(out, sum, t - t_start);
        out->time = t - t_start;
        memcpy(out->x, y, (size_t)n * sizeof *y);
    }
    gsl_odeiv2_driver_free(d);
    free(y);
    return st;
}

/* ---- maps ---- */

cm_status cm_map_spectrum(const cm_model *m, const double *x0, const cm_spectrum_options *o,
                          cm_spectrum_trace trace, void *user, cm_spectrum *out, char *msg,
                          size_t msg_size)
{
    memset(out, 0, sizeof *out);
    const int n = m->dim;
    int k;
    cm_status st = check_count(n, o, &k, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (!(o->iterations > 0 && o->skip >= 0)) {
        snprintf(msg, msg_size, "the map's spectrum needs iterations > 0 and skip >= 0");
        return CM_EINVAL;
    }
    out->n = n, out->count = k;
    double x[CM_MAX_DIM], y[CM_MAX_DIM], J[CM_MAX_DIM * CM_MAX_DIM], v[CM_MAX_DIM * CM_MAX_DIM],
        w[CM_MAX_DIM * CM_MAX_DIM], logs[CM_MAX_DIM], sum[CM_MAX_DIM] = {0}, running[CM_MAX_DIM];
    memcpy(x, x0, (size_t)n * sizeof *x);
    start_vectors(n, k, v);
    long it = -o->skip;
    for (; st == CM_OK && it < o->iterations; it++) {
        double t_end = 0;
        const int rc = cm_model_is_flow(m) ? cm_flow_map(m, x, y, &t_end, NULL) : m->step(m, x, y);
        if (rc != CM_STEP_OK || cm_map_jacobian(m, 1, x, J) != CM_OK) {
            st = CM_EMODEL;
            break;
        }
        for (int j = 0; j < k; j++)
            cm_mat_vec(n, n, J, v + j * n, w + j * n);
        if (!cm_gram_schmidt(n, k, w, logs)) {
            st = CM_EMODEL;
            break;
        }
        memcpy(v, w, (size_t)(k * n) * sizeof *v);
        memcpy(x, y, (size_t)n * sizeof *x);
        if (it < 0)
            continue;
        out->time += cm_model_is_flow(m) ? t_end - m->flow.t0 : 0;
        for (int j = 0; j < k; j++) {
            sum[j] += logs[j];
            running[j] = sum[j] / (double)(it + 1);
        }
        if (trace && trace(user, (double)(it + 1), running, k))
            st = CM_ECANCELED;
    }
    if (st == CM_EMODEL)
        snprintf(msg, msg_size,
                 "the orbit was lost at iterate %ld (no image, or none near it for the "
                 "Jacobian): start elsewhere",
                 it + o->skip);
    else if (st == CM_ECANCELED)
        snprintf(msg, msg_size, "stopped at iterate %ld", it + o->skip);
    if (st == CM_OK) {
        finish(out, sum, (double)o->iterations);
        memcpy(out->x, x, (size_t)n * sizeof *x);
    }
    return st;
}
