/* models/microchaos_pd.h - analytic results for the 2D micro-chaos map of the
 * PD-controlled inverted pendulum (thesis 4.5, App. C.4; docs/models.md 6).
 * All functions are pure. alpha > 0 is required throughout. */
#ifndef CM_MODELS_MICROCHAOS_PD_H
#define CM_MODELS_MICROCHAOS_PD_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/model.h"

typedef struct cm_pd_coef {
    double alpha, beta, P, D;
    double gamma;              /* sqrt(alpha^2 + beta^2) */
    double A[4];               /* (4.67), row-major */
    double b[2];               /* (4.67) */
    double S[4];               /* A + b [P, D] (4.62) */
    double lambda_u, lambda_s; /* eigenvalues of A: exp(+-gamma - beta) */
    double e_u[2], e_s[2];     /* eigenvectors (4.68), first component 1 */
} cm_pd_coef;

/* Matrices of (4.66)/(4.67) and the eigen-structure of A. */
void cm_pd_coefficients(double alpha, double beta, double P, double D, cm_pd_coef *c);

/* Switching line SW_m (4.70): x' = (m - P x)/D, i.e. slope -P/D and
 * intercept m/D; it crosses x' = 0 at x = m/P. */
void cm_pd_switching_line(double P, double D, int64_t m, double *slope, double *intercept);

/* Stability of the quantisation-free loop (C.43)-(C.47). */
typedef struct cm_pd_stability {
    double p, q;       /* characteristic polynomial mu^2 + p mu + q of S */
    double b0, b1, b2; /* (C.44); stable iff all three are positive */
    double D_b0, D_b1; /* (C.45): stable iff P > alpha^2 and D_b1 < D < D_b0 */
    int stable;
} cm_pd_stability;

void cm_pd_stability_at(double alpha, double beta, double P, double D, cm_pd_stability *s);

/* (C.46): P where D_b0 and D_b1 meet; (C.47): D there. */
double cm_pd_P_max(double alpha, double beta);
double cm_pd_D_at_P_max(double alpha, double beta);

/* The eigen-structure of S inside the stability domain (C.52)-(C.56), as
 * curves D(P): trace S = 0 (D_1), det S = 0 (D_0), and the double
 * eigenvalue D_c- <= D_c+ (NaN for P < alpha^2, where they are complex). */
typedef struct cm_pd_eigen_curves {
    double D_1, D_0, D_c_minus, D_c_plus;
} cm_pd_eigen_curves;

void cm_pd_eigen_curves_at(double alpha, double beta, double P, cm_pd_eigen_curves *out);

/* P_quick: where D_0 = D_1 and both eigenvalues of S vanish (deadbeat). */
double cm_pd_P_quick(double alpha, double beta);

/* The horseshoe at switching line SW_m, m >= 1 (thesis 4.5.3, Fig. 4.15):
 * the parallelogram Q_m between the fixed points x_l* (l = m - 1) and x_r*
 * (r = m) bounded by their stable and unstable manifolds, cut by SW_m into
 * the trapezoids L = (x_l*, RULS, RUSW, LUSW) and R = (LUSW, RUSW, x_r*,
 * LURS); f_l and f_r are the map restricted to level l or r. */
typedef struct cm_pd_horseshoe {
    int64_t m;
    double x_l[2], x_r[2];
    double RULS[2], LURS[2], RUSW[2], LUSW[2]; /* docs/models.md 6.6 */
    /* the four escape conditions: f_l(LUSW), f_l(RUSW) right of W_R^S and
     * f_r(LUSW), f_r(RUSW) left of W_L^S */
    bool escape[4];
    bool stretches;  /* any of them: an image leaves Q_m, a repeller */
    bool full_shift; /* all four: conjugate to a full binary shift */
} cm_pd_horseshoe;

void cm_pd_horseshoe_at(double alpha, double beta, double P, double D, int64_t m,
                        cm_pd_horseshoe *h);

/* The points of Q_m of period n under the two restricted maps: itineraries
 * over {l, r} whose affine fixed point follows them, each iterate in Q_m
 * and in the band of its symbol. 2^n on a full horseshoe. */
uint64_t cm_pd_horseshoe_periodic(double alpha, double beta, double P, double D, int64_t m, int n);

/* (4.75) m_fix,max = Int(alpha^2/(P - alpha^2)), with the border rule of
 * docs/models.md 6.4 (a colliding fixed point is virtual); (4.76) m_max =
 * m_fix,max + 1. Return -1 when P <= alpha^2 (unbounded). */
int64_t cm_pd_m_fix_max(double alpha, double P);
int64_t cm_pd_m_max(double alpha, double P);

/* (4.71): the fixed points x_m* = [m/alpha^2, 0] for levels m0..m1 into
 * out (at most cap); x_m* is regular iff Int(P x_m*) = m (the band test of
 * docs/models.md 6.4). Returns how many were written. */
size_t cm_pd_fixed_points(double alpha2, double P, int64_t m0, int64_t m1, cm_fixed_point *out,
                          size_t cap);

/* Axis names of the pendulum's state: x and x'. */
extern const char *const cm_pd_coord_names[];

/* The overlays of the view lo..hi (docs/models.md 6.4): the switching lines
 * SW_m, the fixed points x_m* (regular or virtual) and, through each regular
 * one, its unstable and stable manifolds (the lines along e_u and e_s) within
 * its band. Shared by microchaos-pd and microchaos-pd-friction. */
void cm_pd_overlays(double alpha2, double beta, double P, double D, const double lo[2],
                    const double hi[2], cm_overlay_list *out);

#endif
