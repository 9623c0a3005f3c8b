/* tests/lattice_plugin.c - a map with an attractor at every point of a
 * sheared lattice, for the colour tests: in u = x - s y, v = y each
 * coordinate follows w' = w - a sin(2 pi w) / (2 pi), so the integers
 * attract (slope 1 - a) and the half-integers repel (1 + a), and the basins
 * are the parallelograms between the half-integer lines: each touches six
 * others. Parameters a (0 < a < 2) and the shear s. */
#include <cellmap/plugin.h>
#include <math.h>
#include <string.h>

static const cm_param_spec lattice_params[] = {
    {"a", "0.6", 0.01, 1.99, 1, NULL, "contraction: slope 1 - a at the attractors"},
    {"s", "0.5", -10, 10, 1, NULL, "shear of the lattice"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};
static const char *const lattice_state[] = {"x", "y"};

static double towards_integer(double w, double a)
{
    const double two_pi = 6.283185307179586;
    return w - a * sin(two_pi * w) / two_pi;
}

static int lattice_step(const cm_model *m, const double *z, double *out)
{
    const double a = m->values.value[0].v[0], s = m->values.value[1].v[0];
    const double u = towards_integer(z[0] - s * z[1], a), v = towards_integer(z[1], a);
    out[0] = u + s * v;
    out[1] = v;
    return CM_STEP_OK;
}

static cm_status lattice_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    memset(m, 0, sizeof *m);
    m->name = "lattice";
    m->dim = 2;
    m->params = lattice_params;
    m->values = *p;
    m->step = lattice_step;
    m->coord_names = lattice_state;
    m->equal_axes = 1;
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"lattice", "x, y", "an attractor at every point of a sheared integer lattice", "0:8,-0.5:4.5",
     lattice_params, lattice_create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
