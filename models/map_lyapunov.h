/* models/map_lyapunov.h - the largest Lyapunov exponent of any model's map
 * by finite differences (two orbits, renormalised every iterate). */
#ifndef CM_MODELS_MAP_LYAPUNOV_H
#define CM_MODELS_MAP_LYAPUNOV_H

#include "cellmap/model.h"

/* The exponent of the orbit of x0 (dim entries): after iterations / 10
 * iterates of transient, a second orbit d0 away (along (1, ..., 1)) is
 * renormalised to d0 after each of `iterations` iterates; *lambda gets the
 * mean log growth per unit of time: per iterate for a map, per unit of the
 * flow's time for a flow model (a stroboscopic map's iterate lasts one
 * period; a Poincare map's the flight to the section). false when an orbit
 * has no image (then *lambda is untouched); -inf when the two orbits meet. */
bool cm_map_lyapunov(const cm_model *m, const double *x0, double d0, long iterations,
                     double *lambda);

#endif
