/* examples/plugin/henon.c - the Henon map as a cellmap plugin:
 *   x' = 1 - a x^2 + y,   y' = b x
 * Build: cc -shared -fPIC $(pkg-config --cflags cellmap) -o libhenon.so henon.c -lm
 * Run:   cellmap solve --model-lib ./libhenon.so --model henon --png henon.png */
#include <cellmap/plugin.h>
#include <math.h>
#include <string.h>

static const cm_param_spec henon_params[] = {
    /* name, default, min, max, values, choices, meaning */
    {"a", "1.4", -10, 10, 1, NULL, "x' = 1 - a x^2 + y"},
    {"b", "0.3", -10, 10, 1, NULL, "y' = b x"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};
static const char *const henon_state[] = {"x", "y"};

/* Pure and thread-safe: cellmap calls it on every thread at once. */
static int henon_step(const cm_model *m, const double *x, double *y)
{
    const double a = m->values.value[0].v[0], b = m->values.value[1].v[0];
    y[0] = 1 - a * x[0] * x[0] + x[1];
    y[1] = b * x[0];
    return fabs(y[0]) < 1e100 ? CM_STEP_OK : CM_STEP_NO_IMAGE; /* escaped: the sink */
}

static cm_status henon_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size; /* nothing can fail here */
    memset(m, 0, sizeof *m);
    m->name = "henon";
    m->dim = 2;
    m->params = henon_params;
    m->values = *p;
    m->step = henon_step;
    m->coord_names = henon_state;
    m->equal_axes = 1; /* figures draw a square of state space square */
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"henon", "x, y", "the Henon map x' = 1 - a x^2 + y, y' = b x", "-1.5:1.5,-0.45:0.45",
     henon_params, henon_create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
