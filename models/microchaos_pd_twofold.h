/* models/microchaos_pd_twofold.h - the geometry of twofold quantisation
 * (thesis 4.7.2, docs/models.md 7). */
#ifndef CM_MODELS_MICROCHAOS_PD_TWOFOLD_H
#define CM_MODELS_MICROCHAOS_PD_TWOFOLD_H

/* The order n of the switching line collision (SLC) at a corner of four
 * input tiles with control levels a (lower left), b (lower right), c (upper
 * left), d (upper right), or 0 if none. SW_m and SW_m+n collide there when
 * the levels of one diagonal lie one below and one above both levels of the
 * other: the line around the lower tile and the line around the upper one
 * touch at the corner, and the bands between (the other diagonal's levels)
 * are pinched; n is 1 + that diagonal's spread. With P, D > 0, first-order
 * collisions exist for 1/(P + D) < rho < 1/(P - D) ((4.87), (4.89)), order
 * n for n/(P + D) < rho < n/(P - D). NaN levels (no level) give 0. */
int cm_twofold_collision_order(double a, double b, double c, double d);

#endif
