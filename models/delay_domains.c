/* models/delay_domains.c - the delay micro-chaos map's parameter domains
 * (thesis 4.4, App. C.3). docs/models.md 5.4. */
#include "models/delay_domains.h"

#include <math.h>

void cm_delay_curves_at(double a, cm_delay_curves *c)
{
    const double a2 = a * a, a3 = a2 * a, a4 = a2 * a2;
    c->n_sup0 = a2 * (a - 1);                  /* n_sup,+^0 */
    c->n_inf1 = a2 / (a + 1);                  /* n_inf,+^1 = g_inf,+^1 */
    c->n_sup1 = 2 * a2 * (a - 1) / (a2 + 1);   /* n_sup,+^1 */
    c->d0 = a * (a2 - 1) / (a2 + a - 1);       /* (C.31) */
    c->d1 = a * (a2 - 1);                      /* (C.30), m = 1 */
    c->d2 = 2 * a * (a2 - 1) / (a2 + a + 1);   /* (C.30), m = 2 */
    c->g_sup0 = 2 * a - a2;                    /* (C.25) */
    c->g_inf2 = (2 * a2 - a) / (2 * a + 1);    /* (C.26), m = 2 */
    c->c_mu = a * (a4 - 1) / (a4 + a3 - 1);    /* (C.38) */
    c->c_sl = (a4 - a) / (a + 1);              /* (C.40) */
    c->c_su = (a4 - a) / (a3 + a2 - 1);        /* (C.41) */
    c->c_ml = a * (a4 - 1) / (1 + a + a2);     /* (C.42) */
}

void cm_delay_domains_at(double a, double b, cm_delay_domains *d)
{
    cm_delay_curves c;
    cm_delay_curves_at(a, &c);
    d->stable = a > 1 && b < 1 && b > a - 1; /* (4.39) */
    /* '01': branch 0 cannot jump over y_1* (b >= n_sup,+^0), branch 1 not
     * below y_0* into negative values (b <= n_inf,+^1), neither dashed */
    d->d01 = d->stable && b >= c.n_sup0 && b <= c.n_inf1 && b <= c.d1 && b >= c.d0;
    /* '012': branch 1 cannot jump over y_2* (b >= n_sup,+^1), U_0 and U_2
     * not dashed, the ends of U_1's branch p_inf^1, p_sup^1 */
    d->d012 = d->stable && b >= c.d0 && b <= c.d2 && b >= c.n_sup1 && b <= c.g_sup0 &&
              b <= c.g_inf2;
    d->mu_sl = d->d01 && b >= c.c_mu && b <= c.c_sl;
    d->su_ml = d->d01 && b >= c.c_su && b <= c.c_ml;
}

uint32_t cm_delay_bands_visited(double a, double b, double x_prev, double x, int skip, int n)
{
    uint32_t seen = 0;
    for (int i = 0; i < skip + n; i++) {
        const double k = floor(x_prev);
        if (!(fabs(x) < 1e9) || (i >= skip && (k < 0 || k > 30)))
            return 0;
        if (i >= skip)
            seen |= UINT32_C(1) << (int)k;
        x_prev = x;
        x = a * x - b * k;
    }
    return seen;
}
