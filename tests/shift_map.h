/* tests/shift_map.h - a map whose exits' orbits land in other regions: x
 * moves 5 right until 40, where a fixed point waits at 45.5; y stays. The
 * tests of a view's exits (test_store, test_view_keep) solve regions of it
 * apart, so that a region's orbits land only once a later one is solved. */
#ifndef CM_TESTS_SHIFT_MAP_H
#define CM_TESTS_SHIFT_MAP_H

#include "cellmap/model.h"

static int shift_step(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = x[0] < 40 ? x[0] + 5 : 45.5;
    y[1] = x[1];
    return CM_STEP_OK;
}

#endif
