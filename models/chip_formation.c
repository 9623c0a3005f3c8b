/* Chip formation in orthogonal cutting (thesis Ch. 3, docs/models.md 12):
 * Palmai's autonomous flow of the shear stress and the temperatures of
 * the chip's layers, (3.27)-(3.31), as the Poincare map of a state plane
 * (by default T0 = 0.1 crossed downwards, where the successive tau2 make
 * the thesis' one-dimensional map of Fig. 3.6: the map's state is (tau2,
 * T1, T2) there); and the same cutting on an elastic workpiece,
 * (3.12)-(3.16), as the map of the workpiece's largest deflections (its
 * velocity v = 0 crossed downwards). */
#include <math.h>
#include <string.h>

#include "models/chip_formation.h"
#include "models/models.h"
#include "models/ode_flow.h"
#include "models/params.h"

/* The coefficients both models share: xi, zeta (its default given),
 * eta and the law's p, a, b and T_Phi. */
#define CHIP_SPECS(zeta)                                                                       \
    {"xi", "4.8", -100, 100, 1, NULL, "xi: heat carried away with the chip (3.28)-(3.30)"},    \
        {"zeta", zeta, 0, 1000, 1, NULL, "zeta: heat conduction between the layers"},          \
        {"eta", "4.4", 0, 1000, 1, NULL, "eta: plastic work turned into heat"},                \
        {"p", "1.03", 0, 10, 1, NULL, "p: tau1 = p tau2 + 1 - p (3.6)"},                       \
        {"a", "0.3", 0, 10, 1, NULL, "a: the flow stress' temperature coefficient (3.31)"},    \
        {"b", "0.012", 1e-6, 10, 1, NULL, "b: the strain rate's sensitivity; small is stiff"},   \
        {"T_Phi", "1", -0.99, 100, 1, NULL, "T_Phi: the reference temperature (3.31)"}

const cm_param_spec cm_chip_4d_spec[] = {
    CHIP_SPECS("21"),
    CM_FLOW_PLANE_PARAM_SPECS("tau2|T0|T1|T2", "T0", "0.1", "down"),
    {"t_max", "50", 1e-6, 1e12, 1, NULL,
     "the longest flight to the section (else no image; about 90 returns at the defaults)"},
    {"event_tol", "1e-12", 1e-15, 1, 1, NULL, "the section's crossing time to this"},
    CM_FLOW_PARAM_SPECS,
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

const cm_param_spec cm_chip_workpiece_spec[] = {
    CHIP_SPECS("3.4"),
    {"A", "0.383", 0, 1000, 1, NULL, "A: the workpiece's dimensionless stiffness (3.16)"},
    {"V0", "8.07", 1e-6, 1e6, 1, NULL, "V0: the dimensionless reference speed (3.17)"},
    {"f", "1", 1e-6, 100, 1, NULL, "f: the cutting speed over the reference speed v0 = 3.6 m/s"},
    CM_FLOW_PLANE_PARAM_SPECS("tau2|T0|T1|T2|z|v", "v", "0", "down"),
    {"t_max", "100", 1e-6, 1e12, 1, NULL,
     "the longest flight to the section (else no image; about 10 periods of the workpiece)"},
    {"event_tol", "1e-12", 1e-15, 1, 1, NULL, "the section's crossing time to this"},
    CM_FLOW_PARAM_SPECS,
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

static const char *const chip_coord_names[] = {"tau2", "T0", "T1", "T2", "z", "v"};

void cm_chip_rates(const cm_chip *c, double tau2, double T1, double T2, double *F1, double *F2)
{
    *F1 = (T1 + 1) / (c->T_Phi + 1) *
          exp((c->p * tau2 - c->p + c->a * (T1 - c->T_Phi)) / (c->b * (T1 + 1)));
    *F2 = (T2 + 1) / (c->T_Phi + 1) * exp((tau2 - 1 + c->a * (T2 - c->T_Phi)) / (c->b * (T2 + 1)));
}

/* (3.27)-(3.30); defined where the layers are above absolute zero of the
 * law's scale (T > -1). */
static int chip_field(const cm_model *m, double t, const double *z, double *f)
{
    (void)t;
    const cm_chip *c = m->ctx;
    const double tau2 = z[0], T0 = z[1], T1 = z[2], T2 = z[3];
    if (!(T1 > -1 && T2 > -1))
        return 1;
    double F1, F2;
    cm_chip_rates(c, tau2, T1, T2, &F1, &F2);
    f[0] = 1 - (F1 + F2);
    f[1] = c->zeta * (T1 - 2 * T0) - c->xi * T0;
    f[2] = c->eta * (c->p * tau2 + 1 - c->p) * F1 - c->zeta * (2 * T1 - T2 - T0) -
           c->xi * (T1 - T0);
    f[3] = c->eta * tau2 * F2 - (c->xi + c->zeta) * (T2 - T1);
    return 0;
}

/* (3.12)-(3.16): the 4-D flow at the effective speed ratio
 * g = f (1 - v/(V0 f)), driving the workpiece z'' = tau2 - A z. */
static int workpiece_field(const cm_model *m, double t, const double *y, double *f)
{
    (void)t;
    const cm_chip *c = m->ctx;
    const double tau2 = y[0], T0 = y[1], T1 = y[2], T2 = y[3], z = y[4], v = y[5];
    if (!(T1 > -1 && T2 > -1))
        return 1;
    const double g = c->f - v / c->V0;
    double F1, F2;
    cm_chip_rates(c, tau2, T1, T2, &F1, &F2);
    f[0] = g * (1 - (F1 + F2));
    f[1] = c->zeta * (T1 - 2 * T0) - g * c->xi * T0;
    f[2] = g * (c->eta * (c->p * tau2 + 1 - c->p) * F1 - c->xi * (T1 - T0)) -
           c->zeta * (2 * T1 - T2 - T0);
    f[3] = c->eta * g * tau2 * F2 - (g * c->xi + c->zeta) * (T2 - T1);
    f[4] = v;
    f[5] = tau2 - c->A * z;
    return 0;
}

/* A chip model of flow dimension n (its map one fewer, on the section's
 * plane) with field. */
static cm_status chip_create(const char *name, int n,
                             int (*field)(const cm_model *, double, const double *, double *),
                             const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    cm_status st = cm_model_setup(m, name, n - 1, p, sizeof(cm_chip), msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_chip *c = m->ctx;
    c->xi = cm_params_get(p, "xi");
    c->zeta = cm_params_get(p, "zeta");
    c->eta = cm_params_get(p, "eta");
    c->p = cm_params_get(p, "p");
    c->a = cm_params_get(p, "a");
    c->b = cm_params_get(p, "b");
    c->T_Phi = cm_params_get(p, "T_Phi");
    if (n == 6) {
        c->A = cm_params_get(p, "A");
        c->V0 = cm_params_get(p, "V0");
        c->f = cm_params_get(p, "f");
    }
    m->coord_names = chip_coord_names;
    m->flow.field = field;
    st = cm_flow_attach(m, msg, msg_size);
    if (st != CM_OK)
        cm_model_release(m);
    return st;
}

cm_status cm_chip_4d_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    return chip_create("chip-4d", 4, chip_field, p, m, msg, msg_size);
}

cm_status cm_chip_workpiece_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    return chip_create("chip-workpiece", 6, workpiece_field, p, m, msg, msg_size);
}

/* ---- the built-up-edge delay model ---- */

#define TWO_PI 6.283185307179586476925286766559

cm_chip_bue cm_chip_bue_defaults(void)
{
    return (cm_chip_bue){.a = 0.3, .b = 0.012, .n = 0.2, .T_Phi = 1.2, .eps = 2.44, .dt = 0.4,
                         .eta = 4, .zeta = 30, .H = 0.1, .Omega = 0.18};
}

double cm_chip_bue_rate(const cm_chip_bue *c, double T, double tau, double gamma)
{
    const double en = pow(c->eps, c->n);
    const double hardening = (1 + en * (gamma > 0 ? pow(gamma, c->n) : 0)) / (1 + en);
    return (T + 1) / (c->T_Phi + 1) *
           exp((tau - hardening + c->a * (T - c->T_Phi)) / (c->b * (T + 1)));
}

/* The state's coordinates. */
enum { BUE_T0, BUE_T, BUE_GAMMA, BUE_TAU };

static int bue_field(const void *ctx, double t, const double *x, const double *xd, double *f)
{
    const cm_chip_bue *c = ctx;
    if (!(x[BUE_T] > -1 && xd[BUE_T] > -1))
        return 1;
    const double F = cm_chip_bue_rate(c, x[BUE_T], x[BUE_TAU], x[BUE_GAMMA]);
    /* the saw tooth of the cut layer (3.24)-(3.26) */
    const double period = TWO_PI / c->Omega, rate = c->H * c->Omega / (TWO_PI);
    const double grown = 1 + rate * fmod(t, period);
    f[BUE_TAU] = (1 - F) / (grown * grown) - 2 * x[BUE_TAU] * rate / grown;
    if (t < c->dt) { /* the start-up: the band forms, nothing else moves */
        f[BUE_T0] = f[BUE_T] = f[BUE_GAMMA] = 0;
        return !isfinite(f[BUE_TAU]);
    }
    const double Fd = cm_chip_bue_rate(c, xd[BUE_T], xd[BUE_TAU], xd[BUE_GAMMA]);
    f[BUE_T0] = c->zeta * (x[BUE_T] - 2 * x[BUE_T0]) - x[BUE_T0] / c->dt;
    f[BUE_T] = c->eta * x[BUE_TAU] * F - c->zeta * (x[BUE_T] - x[BUE_T0]) -
               (x[BUE_T] - xd[BUE_T0]) / c->dt;
    f[BUE_GAMMA] = (F - Fd) / c->dt;
    return !(isfinite(f[BUE_T0]) && isfinite(f[BUE_T]) && isfinite(f[BUE_GAMMA]) &&
             isfinite(f[BUE_TAU]));
}

static void bue_history(const void *ctx, double t, double *x)
{
    (void)ctx, (void)t;
    x[BUE_T0] = x[BUE_T] = x[BUE_GAMMA] = x[BUE_TAU] = 0;
}

/* The saw tooth's drops and the start-up's end. */
static double bue_next_break(const void *ctx, double t)
{
    const cm_chip_bue *c = ctx;
    const double period = TWO_PI / c->Omega;
    const double drop = (floor(t / period + 1e-12) + 1) * period;
    return t < c->dt ? fmin(c->dt, drop) : drop;
}

void cm_chip_bue_dde(const cm_chip_bue *c, cm_dde *d)
{
    *d = (cm_dde){.dim = 4, .delay = c->dt, .field = bue_field, .history = bue_history,
                  .next_break = bue_next_break, .ctx = c, .method = CM_FLOW_RK8PD,
                  .abs_tol = 1e-9, .rel_tol = 1e-9};
}

const cm_param_spec cm_chip_bue_spec[] = {
    {"a", "0.3", 0, 10, 1, NULL, "a: the flow stress' temperature coefficient (3.22)"},
    {"b", "0.012", 1e-6, 10, 1, NULL, "b: the strain rate's sensitivity; small is stiff"},
    {"n", "0.2", 0, 10, 1, NULL, "n: strain hardening (3.22, B.36)"},
    {"T_Phi", "1.2", -0.99, 100, 1, NULL, "T_Phi: the reference temperature"},
    {"eps", "2.44", 0, 100, 1, NULL, "eps: the reference strain eps_Phi"},
    {"dt", "0.4", 1e-6, 1e6, 1, NULL, "dt: the delay, the time across the shear band"},
    {"eta", "4", 0, 1000, 1, NULL, "eta: plastic work turned into heat (3.21)"},
    {"zeta", "30", 0, 1000, 1, NULL, "zeta: heat conduction between the layers (3.21)"},
    {"H", "0.1", 0, 100, 1, NULL, "H: the built-up edge's thickening of the cut layer (3.24)"},
    {"Omega", "0.18", 1e-6, 1e6, 1, NULL, "Omega: the built-up edge's frequency (3.25)"},
    {"method", "rk8pd", 0, CM_FLOW_RK4, 1, "rk8pd|rkf45|rkck|rk4",
     "integrator: GSL's explicit Runge-Kutta steppers"},
    {"abs_tol", "1e-9", 1e-15, 1e-2, 1, NULL, "absolute error per integration step"},
    {"rel_tol", "1e-9", 0, 1e-2, 1, NULL, "relative error per integration step"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

const char *const cm_chip_bue_coords[4] = {"T0", "T", "gamma", "tau"};

void cm_chip_bue_of(const cm_params *p, cm_chip_bue *c, cm_dde *d)
{
    *c = (cm_chip_bue){
        .a = cm_params_get(p, "a"), .b = cm_params_get(p, "b"), .n = cm_params_get(p, "n"),
        .T_Phi = cm_params_get(p, "T_Phi"), .eps = cm_params_get(p, "eps"),
        .dt = cm_params_get(p, "dt"), .eta = cm_params_get(p, "eta"),
        .zeta = cm_params_get(p, "zeta"), .H = cm_params_get(p, "H"),
        .Omega = cm_params_get(p, "Omega")};
    cm_chip_bue_dde(c, d);
    d->method = (int)cm_params_get(p, "method");
    d->abs_tol = cm_params_get(p, "abs_tol");
    d->rel_tol = cm_params_get(p, "rel_tol");
}

cm_status cm_chip_bue_params(const char *const *texts, int n_texts, cm_params *p, char *msg,
                             size_t msg_size)
{
    cm_status st = cm_params_defaults(cm_chip_bue_spec, p, msg, msg_size);
    for (int i = 0; i < n_texts && st == CM_OK; i++)
        st = cm_params_set(p, texts[i], msg, msg_size);
    return st == CM_OK ? CM_OK : CM_EINVAL; /* msg names the parameter and its range */
}

void cm_chip_bue_describe(const cm_params *p, cm_model *m)
{
    memset(m, 0, sizeof *m);
    m->name = "chip-bue";
    m->dim = 4;
    m->values = *p;
    m->coord_names = cm_chip_bue_coords;
}
