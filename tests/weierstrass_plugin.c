/* tests/weierstrass_plugin.c - a map whose basin boundary is known
 * exactly (McDonald, Grebogi, Ott and Yorke, "Fractal basin boundaries",
 * Physica D 17, 125-153, 1985, eq. (3.1)):
 *   x' = 3 x mod 1,  y' = lambda y + c cos(2 pi x)
 * Orbits go to y = +inf or -inf; the boundary between the two basins is
 * the Weierstrass curve y = -c sum_j lambda^-(j+1) cos(2 pi 3^j x), of box
 * dimension 2 - ln(lambda)/ln(3) for 1 < lambda < 3 and c != 0 (the
 * uncertainty exponent alpha = ln(lambda)/ln(3): 0.369 at lambda = 1.5),
 * and the straight line y = 0 for c = 0 (alpha = 1). Here an orbit that
 * reaches |y| >= 4 (it never comes back: lambda 4 - |c| >= 4) is sent to
 * the fixed point (0, +-4), so that the two fates are two attractors of
 * the region 0:1 x -4.5:4.5. */
#include <cellmap/plugin.h>
#include <math.h>
#include <string.h>

#define TWO_PI 6.283185307179586476925286766559
#define ESCAPED 4.0

static const cm_param_spec params[] = {
    {"lambda", "1.5", 1.0000001, 2.9999999, 1, NULL, "the stretching in y, 1 < lambda < 3"},
    {"c", "1", -1, 1, 1, NULL, "the amplitude of the forcing, |c| <= 1"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};
static const char *const state[] = {"x", "y"};

static int step(const cm_model *m, const double *z, double *out)
{
    const double lambda = m->values.value[0].v[0], c = m->values.value[1].v[0];
    const double y = fabs(z[1]) >= ESCAPED ? z[1] : lambda * z[1] + c * cos(TWO_PI * z[0]);
    const int escaped = fabs(y) >= ESCAPED;
    out[0] = escaped ? 0 : fmod(3 * z[0], 1.0);
    out[1] = escaped ? (y > 0 ? ESCAPED : -ESCAPED) : y;
    return CM_STEP_OK;
}

static cm_status create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    memset(m, 0, sizeof *m);
    m->name = "weierstrass";
    m->dim = 2;
    m->params = params;
    m->values = *p;
    m->step = step;
    m->coord_names = state;
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"weierstrass", "x, y", "a map whose basin boundary is a Weierstrass curve", "0:1,-4.5:4.5",
     params, create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
