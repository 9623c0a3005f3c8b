/* models/delay_partition.c - the delay micro-chaos map's partition and
 * transition matrix (thesis 4.4.2, App. C.3). docs/models.md 5.3. */
#include "models/delay_partition.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Closed intervals contain one another up to rounding. */
#define SLACK 1e-12

static bool add_region(cm_delay_partition *p, int branch, double lo, double hi)
{
    if (p->r == CM_DELAY_MAX_REGIONS)
        return false;
    p->branch[p->r] = branch;
    p->lo[p->r] = lo;
    p->hi[p->r] = hi;
    p->r++;
    return true;
}

/* The transition matrix of the regions: the image of region i is the
 * interval (a lo - b k, a hi - b k) on branch Int(s) of its points (a
 * region lies on one side of s = 1). */
static void transitions(cm_delay_partition *p)
{
    for (int i = 0; i < p->r; i++) {
        const int to = p->lo[i] >= 1 ? 1 : 0, k = p->branch[i];
        const double lo = p->a * p->lo[i] - p->b * k, hi = p->a * p->hi[i] - p->b * k;
        for (int j = 0; j < p->r; j++)
            p->P[i][j] = p->branch[j] == to && lo <= p->lo[j] + SLACK && hi >= p->hi[j] - SLACK;
    }
}

/* Irreducibility (every region reaches every other) and the primitivity
 * index, by boolean powers of P up to the bound (r - 1)^2 + 1 of
 * Wielandt. */
static void primitivity(cm_delay_partition *p)
{
    const int r = p->r;
    typedef unsigned char matrix[CM_DELAY_MAX_REGIONS][CM_DELAY_MAX_REGIONS];
    matrix Q, R, reach;
    memcpy(Q, p->P, sizeof Q);
    memcpy(reach, p->P, sizeof reach);
    p->primitive_index = 0;
    for (int n = 1; n <= (r - 1) * (r - 1) + 1; n++) {
        bool all = true;
        for (int i = 0; i < r; i++)
            for (int j = 0; j < r; j++) {
                all = all && Q[i][j];
                reach[i][j] |= Q[i][j];
            }
        if (all) {
            p->primitive_index = n;
            break;
        }
        for (int i = 0; i < r; i++) /* R = Q P */
            for (int j = 0; j < r; j++) {
                unsigned char v = 0;
                for (int k = 0; k < r && !v; k++)
                    v = Q[i][k] && p->P[k][j];
                R[i][j] = v;
            }
        memcpy(Q, R, sizeof Q);
    }
    p->irreducible = true;
    for (int i = 0; i < r; i++)
        for (int j = 0; j < r; j++)
            p->irreducible = p->irreducible && reach[i][j];
}

bool cm_delay_partition_01(double a, double b, cm_delay_partition *p, char *why, size_t why_size)
{
    memset(p, 0, sizeof *p);
    p->a = a, p->b = b;
    const double den = a * a * (b + 1 - a);
    if (!(a > 1 && b > a - 1 && b < 1)) {
        snprintf(why, why_size, "a = %g, b = %g: outside the stability domain G (a > 1, "
                                "a - 1 < b < 1; 4.39)", a, b);
        return false;
    }
    p->m_min = (int)floor(b / den);
    p->m_max = (int)floor(b * (a * a - 1) / den);
    if (p->m_min != 1 || p->m_max != 0) {
        snprintf(why, why_size, "m_min = %d, m_max = %d (4.46): the construction takes domain "
                                "'01' (m_min = 1, m_max = 0), two truncated branches",
                 p->m_min, p->m_max);
        return false;
    }
    p->x_l = (a * (a - b) - b) * p->m_min;         /* (4.45) */
    p->x_r = (a * (a - b) - b) * p->m_max + a * a; /* (4.44) */
    /* the lower branch, (a - b, x_r): B^L and its pre-images under
     * s -> (s + b)/a up to the first that would stretch over x_r, whose
     * predecessor takes the rest of the branch */
    double cut[CM_DELAY_MAX_REGIONS + 1];
    int nl = 0;
    cut[nl++] = a - b;
    cut[nl++] = 1;
    while ((cut[nl - 1] + b) / a < p->x_r) {
        if (nl == CM_DELAY_MAX_REGIONS / 2) {
            snprintf(why, why_size, "more than %d regions on the lower branch",
                     CM_DELAY_MAX_REGIONS / 2);
            return false;
        }
        cut[nl] = (cut[nl - 1] + b) / a;
        nl++;
    }
    cut[nl - 1] = p->x_r; /* the last pre-image and the rest: I_1 */
    for (int i = nl - 1; i >= 1; i--) /* right to left: I_1 .. B^L */
        add_region(p, 1, cut[i - 1], cut[i]);
    /* the upper branch, (x_l, a): B^U and its pre-images under s -> s/a
     * down to the first that f(B^L) = (x_l, a - b) covers, and the rest
     * left of it */
    int nu = 0;
    double up[CM_DELAY_MAX_REGIONS + 1];
    up[nu++] = a;
    up[nu++] = 1;
    while (up[nu - 2] / a > a - b + SLACK) { /* the last pre-image not yet inside f(B^L) */
        if (nu == CM_DELAY_MAX_REGIONS / 2) {
            snprintf(why, why_size, "more than %d regions on the upper branch",
                     CM_DELAY_MAX_REGIONS / 2);
            return false;
        }
        up[nu] = up[nu - 1] / a;
        nu++;
    }
    up[nu] = up[nu - 1] / a; /* the pre-image inside f(B^L) ends here */
    if (!(up[nu] > p->x_l)) {
        snprintf(why, why_size, "the pre-image of B^U that f(B^L) covers reaches beyond the "
                                "branch's end x_l = %g", p->x_l);
        return false;
    }
    add_region(p, 0, p->x_l, up[nu]); /* the rest: a single region */
    for (int i = nu; i >= 1; i--)    /* left to right: .. B^U */
        add_region(p, 0, up[i], up[i - 1]);
    transitions(p);
    primitivity(p);
    return true;
}
