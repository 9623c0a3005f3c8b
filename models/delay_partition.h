/* models/delay_partition.h - the delay micro-chaos map's proof of chaos
 * (thesis 4.4.2, App. C.3; docs/models.md 5.3): in the parameter domain
 * '01', where the attractor of f([x_{j-1}, x_j]) = [x_j, a x_j - b
 * Int(x_{j-1})] is two truncated basic branches, on U_0 (upper) and U_1
 * (lower), the partition of Fig. 4.11 and its transition matrix (4.52).
 *
 * A point of branch k is (s, a s - b k), s = x_{j-1}; f takes it to branch
 * Int(s) at a s - b k. The basic regions are B^L = (a - b, 1) on the lower
 * branch and B^U = (1, a) on the upper. The lower branch is cut, from the
 * right, into the pre-images f_1^-j(B^L) (the last merged with what is
 * left up to x_r = a^2); the upper branch into the pre-images f_0^-j(B^U)
 * down to the first that f(B^L) covers, and one region left of it. Pure
 * functions. */
#ifndef CM_MODELS_DELAY_PARTITION_H
#define CM_MODELS_DELAY_PARTITION_H

#include <stdbool.h>
#include <stddef.h>

enum { CM_DELAY_MAX_REGIONS = 48 };

typedef struct cm_delay_partition {
    double a, b;
    int m_min, m_max;                   /* (4.46) */
    double x_l, x_r;                    /* the attractor's ends in x_{j-1} (4.44)-(4.45) */
    int r;                              /* regions I_1..I_r, numbered as Fig. 4.11 */
    int branch[CM_DELAY_MAX_REGIONS];   /* 1: lower (U_1), 0: upper (U_0) */
    double lo[CM_DELAY_MAX_REGIONS], hi[CM_DELAY_MAX_REGIONS]; /* in x_{j-1} */
    unsigned char P[CM_DELAY_MAX_REGIONS][CM_DELAY_MAX_REGIONS]; /* (4.52): closure f(I_i) covers I_j */
    bool irreducible;
    int primitive_index; /* the smallest N with P^N > 0; 0: none (not primitive) */
} cm_delay_partition;

/* The partition at a, b; false, with the reason in why, outside domain
 * '01' (m_min = 1, m_max = 0) or where it would need more regions. */
bool cm_delay_partition_01(double a, double b, cm_delay_partition *out, char *why,
                           size_t why_size);

#endif
