/* 2D micro-chaos map with delay (4.37): [x_{j-1}, x_j] ->
 * [x_j, a x_j - b Int(x_{j-1})]. docs/models.md 5. */
#include <math.h>
#include <string.h>

#include "models/models.h"
#include "models/params.h"

const cm_param_spec cm_microchaos_delay_spec[] = {
    {"a", "1.5", -1e6, 1e6, 1, NULL, "slope; stability domain G: a > 1, b < 1, b > a - 1"},
    {"b", "0.6", -1e6, 1e6, 1, NULL, "control step; Fig. 4.9 uses a = 1.5, b = 0.6"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct delay_map {
    double a, b;
} delay_map;

static int step_delay(const cm_model *m, const double *x, double *y)
{
    const delay_map *c = m->ctx;
    double level;
    if (!cm_int_part(x[0], &level))
        return CM_STEP_NO_IMAGE;
    y[0] = x[1];
    y[1] = c->a * x[1] - c->b * level;
    return CM_STEP_OK;
}

CM_VECTOR_LOOP
static void step_n_delay(const cm_model *m, size_t n, const double *const *x, double *const *y,
                         int *rc)
{
    const delay_map *c = m->ctx;
    const double a = c->a, b = c->b;
    const double *restrict x0 = x[0], *restrict x1 = x[1];
    double *restrict y0 = y[0], *restrict y1 = y[1];
    for (size_t i = 0; i < n; i++) {
        y0[i] = x1[i];
        y1[i] = a * x1[i] - b * cm_int_part_value(x0[i]);
    }
    for (size_t i = 0; i < n; i++)
        rc[i] = cm_int_part_status(x0[i]);
}

/* (4.40): y_m* = [x, x], x = m b/(a-1), regular iff Int(x) = m. */
static int fixed_points_delay(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                              size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const delay_map *c = m->ctx;
    *count = 0;
    if (c->a == 1.0) {
        cm_fail(CM_EINVAL, msg, msg_size, "a = 1: the fixed points are not isolated");
        return -1;
    }
    for (int64_t k = m0; k <= m1 && *count < cap; k++) {
        cm_fixed_point *fp = &out[(*count)++];
        double band;
        memset(fp, 0, sizeof *fp);
        fp->level = k;
        fp->x[0] = fp->x[1] = (double)k * c->b / (c->a - 1.0);
        fp->band = cm_int_part(fp->x[0], &band) ? (int64_t)band : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return 0;
}

/* The overlays of the view (thesis Fig. 4.9): the band borders x_{j-1} = m
 * (switching lines: Int(x_{j-1}) changes there), the lines U_m, x_j = a
 * x_{j-1} - b m, onto which band m maps in one step (the unstable
 * manifolds of y_m*, the attractor's branches lie on them), and the fixed
 * points y_m* (regular or virtual). */
static void overlays_delay(const cm_model *m, const double lo[2], const double hi[2],
                           cm_overlay_list *out)
{
    const delay_map *c = m->ctx;
    const double k0 = floor(lo[0]), k1 = ceil(hi[0]);
    if (!(k1 - k0 <= 2000)) /* too many lines to draw: none */
        return;
    const double up[2] = {0, 1}, along[2] = {1, c->a};
    for (double k = k0; k <= k1; k++) {
        const double border[2] = {k, 0}, on_u[2] = {0, -c->b * k};
        if (k != 0)
            cm_overlay_add_line(out, CM_OVERLAY_SWITCHING_LINE, border, up, lo, hi, NULL, 0, 0);
        cm_overlay_add_line(out, CM_OVERLAY_UNSTABLE_MANIFOLD, on_u, along, lo, hi, NULL, 0, 0);
    }
    if (c->a == 1.0)
        return;
    /* fixed points whose x = m b/(a - 1) lies in the view */
    const double per = c->b / (c->a - 1.0);
    if (per == 0 || !isfinite(per))
        return;
    double m0 = ceil(fmin(lo[0] / per, hi[0] / per)), m1 = floor(fmax(lo[0] / per, hi[0] / per));
    if (m1 - m0 > 2000)
        return;
    for (double k = m0; k <= m1; k++) {
        const double x = k * per, p[2] = {x, x};
        double band;
        const bool regular = cm_int_part(x, &band) && band == k;
        if (cm_overlay_in_view(p, lo, hi))
            cm_overlay_add(out, regular ? CM_OVERLAY_FIXED_REGULAR : CM_OVERLAY_FIXED_VIRTUAL, p,
                           p);
    }
}

cm_status cm_microchaos_delay_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    cm_status st = cm_model_setup(m, "microchaos-delay", 2, p, sizeof(delay_map), msg, msg_size);
    if (st != CM_OK)
        return st;
    delay_map *c = m->ctx;
    c->a = cm_params_get(p, "a");
    c->b = cm_params_get(p, "b");
    m->step = step_delay;
    m->step_n = step_n_delay;
    m->fixed_points = fixed_points_delay;
    m->overlays = overlays_delay;
    return CM_OK;
}
