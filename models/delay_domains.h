/* models/delay_domains.h - the delay micro-chaos map's parameter domains
 * (thesis 4.4, App. C.3; docs/models.md 5.4): in the (a, b) plane of
 * x_(j+1) = a x_j - b Int(x_(j-1)), the domain G where the origin of the
 * quantisation-free map is stable (4.39, Fig. 4.8); the domains '01' and
 * '012' where the attractor lies on the unstable lines U_0, U_1 (and U_2)
 * of the fixed points as whole basic branches (App. C.3.1, Fig. 4.10); and
 * where the partitions of App. C.3.2 are irreducible and primitive
 * (Fig. C.3). Pure functions, any thread. */
#ifndef CM_MODELS_DELAY_DOMAINS_H
#define CM_MODELS_DELAY_DOMAINS_H

#include <stdbool.h>
#include <stdint.h>

/* The boundary curves b(a) the domains are bounded by (App. C.3). */
typedef struct cm_delay_curves {
    double n_sup0, n_inf1, n_sup1; /* (C.20), (C.21): a branch's points jump a fixed point */
    double d0, d1, d2;             /* (C.30), (C.31): U_0, U_1, U_2's branches dashed */
    double g_sup0, g_inf2;         /* (C.25), (C.26): branches stretched over their ends */
    double c_mu, c_sl, c_su, c_ml; /* (C.38), (C.40)-(C.42): primitive partitions */
} cm_delay_curves;

void cm_delay_curves_at(double a, cm_delay_curves *c);

/* Which domains (a, b) lies in. '01' and '012' are inside G; the two
 * primitive-partition domains are inside '01', where the partitions are
 * built: 'mu_sl' where c_m^u <= b <= c_s^l (f_0(B^L) covers two regions of
 * the upper branch, f_1(B^U) one of the lower), 'su_ml' where c_s^u <= b
 * <= c_m^l (one upper, more than one lower). */
typedef struct cm_delay_domains {
    bool stable, d01, d012, mu_sl, su_ml;
} cm_delay_domains;

void cm_delay_domains_at(double a, double b, cm_delay_domains *d);

/* The bands k = Int(x_(j-1)) an orbit from (x_prev, x) visits over n steps
 * after skip steps, as the bit mask of k = 0..30 (the lines U_k the orbit
 * lands on); 0 when the orbit visits a negative band, one beyond 30 or
 * leaves |x| < 1e9. The independent check of the domains of Fig. 4.10. */
uint32_t cm_delay_bands_visited(double a, double b, double x_prev, double x, int skip, int n);

#endif
