/* The forced Duffing oscillator x'' + delta x' - x + x^3 = gamma cos(omega t)
 * (docs/models.md 11.2), a standard example of coexisting attractors, as the
 * stroboscopic map of its flow over one forcing period. */
#include <math.h>

#include "models/models.h"
#include "models/ode_flow.h"
#include "models/params.h"

#define TWO_PI 6.283185307179586476925286766559

typedef struct duffing {
    double delta, gamma, omega;
} duffing;

const cm_param_spec cm_duffing_spec[] = {
    {"delta", "0.15", 0, 100, 1, NULL, "damping delta"},
    {"gamma", "0.1", 0, 100, 1, NULL, "forcing amplitude gamma"},
    {"omega", "1", 1e-3, 1e3, 1, NULL, "forcing frequency omega; the map's period is 2 pi/omega"},
    {"phase", "0", 0, TWO_PI, 1, NULL, "forcing phase omega t0 of the section"},
    CM_FLOW_PARAM_SPECS,
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

static const char *const duffing_coord_names[] = {"x", "v"};

static int duffing_field(const cm_model *m, double t, const double *x, double *dxdt)
{
    const duffing *d = m->ctx;
    dxdt[0] = x[1];
    dxdt[1] = -d->delta * x[1] + x[0] - x[0] * x[0] * x[0] + d->gamma * cos(d->omega * t);
    return 0;
}

cm_status cm_duffing_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    cm_status st = cm_model_setup(m, "duffing", 2, p, sizeof(duffing), msg, msg_size);
    if (st != CM_OK)
        return st;
    duffing *d = m->ctx;
    d->delta = cm_params_get(p, "delta");
    d->gamma = cm_params_get(p, "gamma");
    d->omega = cm_params_get(p, "omega");
    m->coord_names = duffing_coord_names;
    m->equal_axes = 1; /* figures draw a square of state space square */
    m->flow.field = duffing_field;
    m->flow.period = TWO_PI / d->omega;
    m->flow.t0 = cm_params_get(p, "phase") / d->omega;
    st = cm_flow_attach(m, msg, msg_size);
    if (st != CM_OK)
        cm_model_release(m);
    return st;
}
