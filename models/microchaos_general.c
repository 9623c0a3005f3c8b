/* General n-D micro-chaos map with delay (docs/models.md 2.2):
 *   u_j = sum_i K_i X_{j-i},  X = Q_I(x) for input/twofold quantisation,
 *   u^q = Q_O(u) for output/twofold,  x_{j+1} = A x_j + B u^q.
 * State: the history [x_{j-d}, ..., x_j], oldest first, (d+1) n <= 6. */
#include <math.h>
#include <string.h>

#include "models/linalg.h"
#include "models/models.h"
#include "models/params.h"

enum { MODE_NONE, MODE_OUTPUT, MODE_INPUT, MODE_TWOFOLD };

const cm_param_spec cm_microchaos_general_spec[] = {
    {"n", "1", 1, 6, 1, NULL, "number of physical state variables"},
    {"l", "1", 1, 6, 1, NULL, "number of control signals"},
    {"d", "0", 0, 5, 1, NULL, "largest delay in sampling periods; (d+1) n <= 6"},
    {"mode", "output", 0, 0, 1, "none|output|input|twofold", "quantisation (docs/models.md 2.2)"},
    {"A", "3.5", -1e12, 1e12, 36, NULL, "n x n sampled open-loop matrix, row-major, a:b:..."},
    {"B", "-2.8", -1e12, 1e12, 36, NULL, "n x l input matrix, row-major"},
    {"K", "1", -1e12, 1e12, 36, NULL,
     "gains [K_0 K_1 ... K_d], l x (d+1) n row-major; K_i acts on x_{j-i}"},
    {"rO", "1", 1e-300, 1e300, 6, NULL, "output resolutions (l values, or one for all)"},
    {"rI", "1", 1e-300, 1e300, 6, NULL, "input resolutions (n values, or one for all)"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct general_map {
    int n, l, d, mode;
    double A[36], B[36], K[36], rO[6], rI[6];
} general_map;

/* Quantised control u^q from the history h (oldest first). */
static bool general_control(const general_map *g, const double *h, double *uq)
{
    const int n = g->n, N = (g->d + 1) * g->n;
    double X[CM_MAX_DIM];
    for (int k = 0; k < N; k++) {
        X[k] = h[k];
        if (g->mode == MODE_INPUT || g->mode == MODE_TWOFOLD) {
            double q;
            if (!cm_int_part(h[k] / g->rI[k % n], &q))
                return false;
            X[k] = g->rI[k % n] * q;
        }
    }
    for (int r = 0; r < g->l; r++) {
        double u = 0.0;
        /* K_i multiplies x_{j-i}, which sits at history block d - i. */
        for (int i = 0; i <= g->d; i++)
            for (int c = 0; c < n; c++)
                u += g->K[r * N + i * n + c] * X[(g->d - i) * n + c];
        if (g->mode == MODE_OUTPUT || g->mode == MODE_TWOFOLD) {
            double q;
            if (!cm_int_part(u / g->rO[r], &q))
                return false;
            u = g->rO[r] * q;
        }
        uq[r] = u;
    }
    return true;
}

static int step_general(const cm_model *m, const double *x, double *y)
{
    const general_map *g = m->ctx;
    const int n = g->n, d = g->d;
    double uq[CM_MAX_DIM], next[CM_MAX_DIM], Bu[CM_MAX_DIM];
    if (!general_control(g, x, uq))
        return CM_STEP_NO_IMAGE;
    cm_mat_vec(n, n, g->A, x + d * n, next);
    cm_mat_vec(n, g->l, g->B, uq, Bu);
    for (int k = 0; k < d * n; k++)
        y[k] = x[k + n];
    for (int k = 0; k < n; k++)
        y[d * n + k] = next[k] + Bu[k];
    return CM_STEP_OK;
}

/* docs/models.md 2.4 for one control signal: x* = (I - A)^-1 B u*, u* = r_O m;
 * regular iff the quantised law at the constant history returns u*. */
static int fixed_points_general(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                                size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const general_map *g = m->ctx;
    const int n = g->n;
    double IA[36], inv[36];
    *count = 0;
    if (g->l != 1 || g->mode == MODE_INPUT || g->mode == MODE_NONE) {
        cm_fail(CM_EINVAL, msg, msg_size,
                "fixed points are enumerated by level for one control signal (l = 1) with "
                "output or twofold quantisation");
        return -1;
    }
    for (int i = 0; i < n * n; i++)
        IA[i] = (i / n == i % n ? 1.0 : 0.0) - g->A[i];
    if (!cm_mat_inverse(n, IA, inv)) {
        cm_fail(CM_EINVAL, msg, msg_size, "I - A is singular: the fixed points are not isolated");
        return -1;
    }
    for (int64_t k = m0; k <= m1 && *count < cap; k++) {
        cm_fixed_point *fp = &out[(*count)++];
        double Bu[CM_MAX_DIM], xs[CM_MAX_DIM], uq;
        memset(fp, 0, sizeof *fp);
        fp->level = k;
        for (int i = 0; i < n; i++)
            Bu[i] = g->B[i] * g->rO[0] * (double)k;
        cm_mat_vec(n, n, inv, Bu, xs);
        for (int b = 0; b <= g->d; b++)
            memcpy(fp->x + b * n, xs, (size_t)n * sizeof *xs);
        fp->band = general_control(g, fp->x, &uq) ? (int64_t)llround(uq / g->rO[0]) : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return 0;
}

/* Copies a vector parameter that needs `want` values (one value broadcast
 * when `broadcast`). */
static cm_status take(const cm_params *p, const char *name, int want, bool broadcast, double *dst,
                      char *msg, size_t msg_size)
{
    const cm_param_value *v = &p->value[cm_params_find(p, name)];
    if (v->count == want || (broadcast && v->count == 1)) {
        for (int i = 0; i < want; i++)
            dst[i] = v->v[v->count == 1 ? 0 : i];
        return CM_OK;
    }
    return cm_fail(CM_EINVAL, msg, msg_size, "parameter %s needs %d value%s (got %d)", name, want,
                   want == 1 ? "" : "s", v->count);
}

cm_status cm_microchaos_general_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    general_map g;
    memset(&g, 0, sizeof g);
    g.n = (int)cm_params_get(p, "n");
    g.l = (int)cm_params_get(p, "l");
    g.d = (int)cm_params_get(p, "d");
    g.mode = (int)cm_params_get(p, "mode");
    if (g.n != cm_params_get(p, "n") || g.l != cm_params_get(p, "l") ||
        g.d != cm_params_get(p, "d"))
        return cm_fail(CM_EINVAL, msg, msg_size, "n, l and d must be whole numbers");
    const int N = (g.d + 1) * g.n;
    if (N > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "state dimension (d+1) n = %d exceeds %d; lower d or n", N, CM_MAX_DIM);
    cm_status st;
    if ((st = take(p, "A", g.n * g.n, false, g.A, msg, msg_size)) != CM_OK ||
        (st = take(p, "B", g.n * g.l, false, g.B, msg, msg_size)) != CM_OK ||
        (st = take(p, "K", g.l * N, false, g.K, msg, msg_size)) != CM_OK ||
        (st = take(p, "rO", g.l, true, g.rO, msg, msg_size)) != CM_OK ||
        (st = take(p, "rI", g.n, true, g.rI, msg, msg_size)) != CM_OK)
        return st;
    st = cm_model_setup(m, "microchaos-general", N, p, sizeof g, msg, msg_size);
    if (st != CM_OK)
        return st;
    memcpy(m->ctx, &g, sizeof g);
    m->step = step_general;
    m->fixed_points = fixed_points_general;
    return CM_OK;
}
