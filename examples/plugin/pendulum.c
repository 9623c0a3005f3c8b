/* examples/plugin/pendulum.c - an ODE as a cellmap plugin: the forced damped
 * pendulum  theta'' + b theta' + sin(theta) = A cos(omega t),  given by its
 * vector field; cellmap integrates it (GSL) into the stroboscopic map over
 * one forcing period. The integrator's settings (method, abs_tol, rel_tol,
 * world) come with CM_FLOW_PARAM_SPECS. The angle is periodic (period 2 pi
 * from -pi): cellmap takes every image's theta into -pi:pi, so a rotation
 * goes round the cylinder instead of leaving the box.
 * Build: cc -shared -fPIC $(pkg-config --cflags cellmap) -o libpendulum.so pendulum.c -lm
 * Run:   cellmap solve --model-lib ./libpendulum.so --model pendulum --png pendulum.png */
#include <cellmap/plugin.h>
#include <math.h>
#include <string.h>

static const cm_param_spec pendulum_params[] = {
    {"b", "0.3", 0, 100, 1, NULL, "damping"},
    {"A", "0.8", 0, 100, 1, NULL, "forcing amplitude"},
    {"omega", "0.9", 0.01, 100, 1, NULL, "forcing frequency; the map's period is 2 pi/omega"},
    CM_FLOW_PARAM_SPECS,
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};
static const char *const pendulum_state[] = {"theta", "v"};

/* The field: pure and thread-safe, like a map's step. */
static int pendulum_field(const cm_model *m, double t, const double *x, double *dxdt)
{
    const cm_params *p = &m->values;
    const double b = p->value[0].v[0], A = p->value[1].v[0], omega = p->value[2].v[0];
    dxdt[0] = x[1];
    dxdt[1] = -b * x[1] - sin(x[0]) + A * cos(omega * t);
    return 0;
}

static cm_status pendulum_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    memset(m, 0, sizeof *m);
    m->name = "pendulum";
    m->dim = 2;
    m->params = pendulum_params;
    m->values = *p;
    m->coord_names = pendulum_state;
    m->flow.field = pendulum_field;
    m->flow.period = 6.283185307179586 / p->value[2].v[0];
    m->period[0] = 6.283185307179586; /* theta, from -pi */
    m->period_lo[0] = -3.141592653589793;
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"pendulum", "theta, v at the forcing phase", "the forced damped pendulum's stroboscopic map",
     "-3.141592653589793:3.141592653589793,-4:4", pendulum_params, pendulum_create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
