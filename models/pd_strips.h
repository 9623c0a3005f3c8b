/* models/pd_strips.h - images and pre-images of the PD map's horseshoe
 * trapezoids (thesis 4.5.3, Fig. 4.18; docs/models.md 6.6). On the
 * parallelogram Q_m of cm_pd_horseshoe, the map is f_l = A x + b (m - 1)
 * on L and f_r = A x + b m on R, both affine and invertible, so images and
 * pre-images of convex pieces are convex polygons: the k-th image of L is
 * f applied to the pieces of the (k-1)-th that lie in Q_m, each split by
 * SW_m into its parts in L and R (the last image is left whole, to show
 * how far it stretches); the k-th pre-image is the set of points of Q_m
 * whose orbit stays in Q_m and lands in L after k steps. On a full
 * horseshoe every piece crosses Q_m: 2^(k-1) images and 2^k pre-images of
 * each trapezoid. Pure functions, any thread. */
#ifndef CM_MODELS_PD_STRIPS_H
#define CM_MODELS_PD_STRIPS_H

#include <stdint.h>

enum { CM_POLYGON_MAX = 32, CM_STRIP_MAX_STEPS = 6 };

typedef struct cm_polygon {
    int n;
    double p[CM_POLYGON_MAX][2];
} cm_polygon;

/* The k-th images (k >= 1) or pre-images (k >= 1) of the trapezoid side
 * (0: L, 1: R) at switching line m >= 1, into out (room for max pieces).
 * Returns the number of pieces, or -1 when there would be more than max
 * or a piece more than CM_POLYGON_MAX corners. Pieces of zero area (below
 * 1e-12 of Q_m's) are left out. */
int cm_pd_strip_images(double alpha, double beta, double P, double D, int64_t m, int side, int k,
                       cm_polygon *out, int max);
int cm_pd_strip_preimages(double alpha, double beta, double P, double D, int64_t m, int side,
                          int k, cm_polygon *out, int max);

/* The signed area of a polygon (positive counter-clockwise). */
double cm_polygon_area(const cm_polygon *p);

#endif
