/* Twofold quantisation of the PD map (4.84): u = Int(rho (P Int(x/rho) +
 * D Int(x'/rho))), [x, x'] -> A [x, x'] + b u. docs/models.md 7. */
#include <math.h>
#include <string.h>

#include "models/microchaos_pd.h"
#include "models/models.h"
#include "models/params.h"

const cm_param_spec cm_microchaos_pd_twofold_spec[] = {
    {"alpha", "0.078", 1e-12, 1e3, 1, NULL, "alpha = tau sqrt(k/M) > 0 (4.59)"},
    {"beta", "0", -1e3, 1e3, 1, NULL, "beta = d tau/(2M), damping (4.59)"},
    {"P", "0.007", -1e6, 1e6, 1, NULL, "proportional gain (4.59)"},
    {"D", "0.02", -1e6, 1e6, 1, NULL, "derivative gain (4.59)"},
    {"rho", "0.5", 1e-12, 1e12, 1, NULL,
     "input/output resolution ratio rho = r_I/X_O > 0 (4.85); rho -> 0 gives microchaos-pd"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct twofold_map {
    double a11, a12, a21, a22, b1, b2, P, D, rho, alpha2;
} twofold_map;

/* The quantised control of (4.84); false when a quantiser has no level. */
static bool twofold_control(const twofold_map *c, const double *x, double *u)
{
    double qx, qv;
    if (!cm_int_part(x[0] / c->rho, &qx) || !cm_int_part(x[1] / c->rho, &qv))
        return false;
    return cm_int_part(c->rho * (c->P * qx + c->D * qv), u);
}

static int step_twofold(const cm_model *m, const double *x, double *y)
{
    const twofold_map *c = m->ctx;
    double u;
    if (!twofold_control(c, x, &u))
        return CM_STEP_NO_IMAGE;
    y[0] = c->a11 * x[0] + c->a12 * x[1] + c->b1 * u;
    y[1] = c->a21 * x[0] + c->a22 * x[1] + c->b2 * u;
    return CM_STEP_OK;
}

/* docs/models.md 2.4 (twofold): x* = [u/alpha^2, 0] for control value u, regular
 * iff the control law at x* returns u. */
static int fixed_points_twofold(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                                size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const twofold_map *c = m->ctx;
    (void)msg;
    (void)msg_size;
    *count = 0;
    for (int64_t k = m0; k <= m1 && *count < cap; k++) {
        cm_fixed_point *fp = &out[(*count)++];
        double u;
        memset(fp, 0, sizeof *fp);
        fp->level = k;
        fp->x[0] = (double)k / c->alpha2;
        fp->band = twofold_control(c, fp->x, &u) ? (int64_t)u : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return 0;
}

cm_status cm_microchaos_pd_twofold_create(const cm_params *p, cm_model *m, char *msg,
                                          size_t msg_size)
{
    cm_status st =
        cm_model_setup(m, "microchaos-pd-twofold", 2, p, sizeof(twofold_map), msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_pd_coef k;
    cm_pd_coefficients(cm_params_get(p, "alpha"), cm_params_get(p, "beta"), cm_params_get(p, "P"),
                       cm_params_get(p, "D"), &k);
    twofold_map *c = m->ctx;
    *c = (twofold_map){
        k.A[0],           k.A[1], k.A[2], k.A[3], k.b[0], k.b[1], k.P, k.D, cm_params_get(p, "rho"),
        k.alpha * k.alpha};
    m->step = step_twofold;
    m->fixed_points = fixed_points_twofold;
    return CM_OK;
}
