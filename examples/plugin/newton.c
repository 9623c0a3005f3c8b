/* examples/plugin/newton.c - Newton's method for z^3 - 1 as a cellmap
 * plugin, on the complex plane z = x + i y:
 *   z' = z - (z^3 - 1) / (3 z^2) = (2 z^3 + 1) / (3 z^2)
 * Every orbit but those of z = 0 and its preimages converges to one of the
 * three cube roots of 1; the basins' boundaries are fractal.
 * Build: cc -shared -fPIC $(pkg-config --cflags cellmap) -o libnewton.so newton.c -lm
 * Run:   cellmap solve --model-lib ./libnewton.so --model newton --png newton.png */
#include <cellmap/plugin.h>
#include <math.h>
#include <string.h>

static const cm_param_spec newton_params[] = {
    {NULL, NULL, 0, 0, 0, NULL, NULL}, /* none */
};
static const char *const newton_state[] = {"x", "y"};

/* Pure and thread-safe. z = 0 has no image (the derivative vanishes). */
static int newton_step(const cm_model *m, const double *z, double *out)
{
    (void)m;
    const double x = z[0], y = z[1];
    const double x2 = x * x - y * y, y2 = 2 * x * y;          /* z^2 */
    const double x3 = x2 * x - y2 * y, y3 = x2 * y + y2 * x;  /* z^3 */
    const double nx = 2 * x3 + 1, ny = 2 * y3;                /* 2 z^3 + 1 */
    const double dx = 3 * x2, dy = 3 * y2;                    /* 3 z^2 */
    const double d = dx * dx + dy * dy;
    if (!(d > 1e-300))
        return CM_STEP_NO_IMAGE;
    out[0] = (nx * dx + ny * dy) / d;
    out[1] = (ny * dx - nx * dy) / d;
    return isfinite(out[0]) && isfinite(out[1]) ? CM_STEP_OK : CM_STEP_NO_IMAGE;
}

static cm_status newton_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    memset(m, 0, sizeof *m);
    m->name = "newton";
    m->dim = 2;
    m->params = newton_params;
    m->values = *p;
    m->step = newton_step;
    m->coord_names = newton_state;
    m->equal_axes = 1; /* figures draw a square of state space square */
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"newton", "x, y (z = x + i y)", "Newton's method for z^3 - 1", "-2:2,-2:2", newton_params,
     newton_create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
