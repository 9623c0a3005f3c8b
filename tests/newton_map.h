/* tests/newton_map.h - Newton's method for z^3 - 1 on z = x + i y, the map
 * of examples/plugin/newton.c, for the tests and benchmarks that build it
 * in-process: z' = (2 z^3 + 1) / (3 z^2); z = 0 has no image. */
#ifndef CM_TESTS_NEWTON_MAP_H
#define CM_TESTS_NEWTON_MAP_H

#include <math.h>

#include "cellmap/model.h"

static int newton_step(const cm_model *m, const double *z, double *out)
{
    (void)m;
    const double x = z[0], y = z[1];
    const double x2 = x * x - y * y, y2 = 2 * x * y;
    const double x3 = x2 * x - y2 * y, y3 = x2 * y + y2 * x;
    const double nx = 2 * x3 + 1, ny = 2 * y3, dx = 3 * x2, dy = 3 * y2;
    const double d = dx * dx + dy * dy;
    if (!(d > 1e-300))
        return CM_STEP_NO_IMAGE;
    out[0] = (nx * dx + ny * dy) / d;
    out[1] = (ny * dx - nx * dy) / d;
    return isfinite(out[0]) && isfinite(out[1]) ? CM_STEP_OK : CM_STEP_NO_IMAGE;
}

#endif
