/* Finite-difference (two-orbit, Benettin) estimate of the largest Lyapunov
 * exponent of a model's map. */
#include "models/map_lyapunov.h"

#include <string.h>

#include "models/ode_flow.h"

/* One iterate of x into y and the time it took. */
static bool iterate(const cm_model *m, const double *x, double *y, double *dt)
{
    if (!cm_model_is_flow(m)) {
        *dt = 1;
        return m->step(m, x, y) == CM_STEP_OK;
    }
    double t_end;
    if (cm_flow_map(m, x, y, &t_end, NULL) != CM_STEP_OK)
        return false;
    *dt = t_end - m->flow.t0;
    return true;
}

bool cm_map_lyapunov(const cm_model *m, const double *x0, double d0, long iterations,
                     double *lambda)
{
    const int dim = m->dim;
    const size_t bytes = (size_t)dim * sizeof(double);
    double x[CM_MAX_DIM], y[CM_MAX_DIM], fx[CM_MAX_DIM], fy[CM_MAX_DIM], dt, unused;
    memcpy(x, x0, bytes);
    for (long k = 0; k < iterations / 10; k++) {
        if (!iterate(m, x, fx, &dt))
            return false;
        memcpy(x, fx, bytes);
    }
    for (int d = 0; d < dim; d++)
        y[d] = x[d] + d0 / sqrt((double)dim);
    double log_sum = 0, time = 0;
    for (long k = 0; k < iterations; k++) {
        if (!iterate(m, x, fx, &dt) || !iterate(m, y, fy, &unused))
            return false;
        double d2 = 0;
        for (int d = 0; d < dim; d++)
            d2 += (fy[d] - fx[d]) * (fy[d] - fx[d]);
        if (d2 == 0) {
            *lambda = -INFINITY;
            return true;
        }
        const double dist = sqrt(d2);
        log_sum += log(dist / d0);
        time += dt;
        for (int d = 0; d < dim; d++)
            y[d] = fx[d] + (fy[d] - fx[d]) * d0 / dist;
        memcpy(x, fx, bytes);
    }
    if (!(time > 0))
        return false;
    *lambda = log_sum / time;
    return true;
}
