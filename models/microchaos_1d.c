/* 1D micro-chaos map (4.1): x_{j+1} = a x_j - b Int(x_j). docs/models.md 3. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "models/models.h"
#include "models/params.h"

const cm_param_spec cm_microchaos_1d_spec[] = {
    {"a", "3.5", -1e6, 1e6, 1, NULL, "slope (a > 1: locally unstable); Fig. 4.2 uses 3.5"},
    {"b", "2.8", -1e6, 1e6, 1, NULL, "control step (|a - b| < 1: globally attracting)"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct map1d {
    double a, b;
} map1d;

static int step_1d(const cm_model *m, const double *x, double *y)
{
    const map1d *c = m->ctx;
    double level;
    if (!cm_int_part(x[0], &level))
        return CM_STEP_NO_IMAGE;
    y[0] = c->a * x[0] - c->b * level;
    return CM_STEP_OK;
}

CM_VECTOR_LOOP
static void step_n_1d(const cm_model *m, size_t n, const double *const *x, double *const *y,
                      int *rc)
{
    const map1d *c = m->ctx;
    const double a = c->a, b = c->b;
    const double *restrict x0 = x[0];
    double *restrict y0 = y[0];
    for (size_t i = 0; i < n; i++)
        y0[i] = a * x0[i] - b * cm_int_part_value(x0[i]);
    for (size_t i = 0; i < n; i++)
        rc[i] = cm_int_part_status(x0[i]);
}

/* (4.2): x_m* = b m/(a-1), regular iff Int(x_m*) = m. */
static int fixed_points_1d(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                           size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const map1d *c = m->ctx;
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
        fp->x[0] = c->b * (double)k / (c->a - 1.0);
        fp->band = cm_int_part(fp->x[0], &band) ? (int64_t)band : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return 0;
}

/* The fixed points in view, on the diagonal of the graph plane. */
static void overlays_1d(const cm_model *m, const double lo[2], const double hi[2],
                        cm_overlay_list *out)
{
    const map1d *c = m->ctx;
    if (c->a == 1.0 || c->b == 0.0)
        return;
    const double s = (c->a - 1.0) / c->b; /* level of the fixed point at x: x s */
    double m0 = lo[0] * s, m1 = hi[0] * s;
    if (m0 > m1) {
        const double t = m0;
        m0 = m1;
        m1 = t;
    }
    if (!(m0 > -4e18 && m1 < 4e18))
        return;
    for (int64_t k = (int64_t)ceil(m0); k <= (int64_t)floor(m1) && !out->truncated; k++) {
        cm_fixed_point fp;
        size_t n = 0;
        fixed_points_1d(m, k, k, &fp, 1, &n, NULL, 0);
        const double p[2] = {fp.x[0], fp.x[0]};
        if (cm_overlay_in_view(p, lo, hi))
            cm_overlay_add(out, fp.regular ? CM_OVERLAY_FIXED_REGULAR : CM_OVERLAY_FIXED_VIRTUAL, p,
                           NULL);
    }
}

cm_status cm_microchaos_1d_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    cm_status st = cm_model_setup(m, "microchaos-1d", 1, p, sizeof(map1d), msg, msg_size);
    if (st != CM_OK)
        return st;
    map1d *c = m->ctx;
    c->a = cm_params_get(p, "a");
    c->b = cm_params_get(p, "b");
    m->step = step_1d;
    m->step_n = step_n_1d;
    m->fixed_points = fixed_points_1d;
    m->overlays = overlays_1d;
    return CM_OK;
}
