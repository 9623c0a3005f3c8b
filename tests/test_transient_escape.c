/* The transient chaos of the 1-D friction micro-chaos map
 * (models/transient_escape) against the thesis' 4.3: the identities of
 * (4.27)-(4.29), the roots of (4.32), a_crit of (4.34), the border state's
 * a/(a - 1) of (4.35), and the exact mean escape number against a fine
 * grid of escape numbers and an ensemble, whose escape rate lies between
 * the bounds from the fractal dimension where the thesis finds them close
 * (Fig. 4.7). */
#include <math.h>

#include "check.h"
#include "models/transient_escape.h"

static cm_te setup_I0(double a, double b, double I0)
{
    cm_te t;
    char why[200];
    CHECK(cm_te_setup(a, b, cm_te_c_of_I0(a, b, I0), &t, why, sizeof why));
    return t;
}

static void test_identities(void)
{
    /* Fig. 4.4: a = 1.5, b = 1.2, |I0| = 0.1 is c = 0.1333... */
    CHECK(fabs(cm_te_c_of_I0(1.5, 1.2, 0.1) - 0.4 / 3) < 1e-15);
    const cm_te t = setup_I0(1.5, 1.3, 0.25);
    CHECK(fabs(t.I0 - 0.25) < 1e-14);
    CHECK(fabs(t.x0 - t.c / (t.a - 1)) < 1e-15 && fabs(t.rep_hi - (t.a - t.c)) < 1e-15);
    CHECK(fabs(t.rep_len - (t.b - t.I0)) < 1e-14);
    const double A = t.b / t.a, I1 = t.I0 / t.a; /* (4.29)'s right-hand forms */
    CHECK(fabs(t.C[0] - t.F / (A - I1)) < 1e-14);
    CHECK(fabs(t.C[1] - t.F / A) < 1e-14);
    /* (4.32) holds at the roots, and C1 > C2 gives the larger dimension */
    for (int i = 0; i < 2; i++) {
        const double D = t.D0[i];
        CHECK(D > 0 && D < 1);
        CHECK(fabs(1 / (1 - pow(t.a, -D)) - pow(t.C[i], -D)) < 1e-12);
        CHECK(fabs(t.kappa[i] - (1 - D) * log(t.a)) < 1e-15);
    }
    CHECK(t.D0[0] > t.D0[1] && t.n_esc[0] > t.n_esc[1]);
    /* (4.34): a_crit ~ 1.238 at b = 1.3, |I0| = 0.25 */
    CHECK(fabs(t.a_crit - 1.3 / 1.05) < 1e-14 && fabs(t.a_crit - 1.238) < 1e-3);
    /* outside 4.3's case: a clear refusal */
    cm_te u;
    char why[200];
    CHECK(!cm_te_setup(3, 1.3, cm_te_c_of_I0(3, 1.3, 0.25), &u, why, sizeof why));
    CHECK(!cm_te_setup(1.5, 1.3, 0, &u, why, sizeof why));
}

/* The border state (a <= a_crit): D0 = 0 and N = a/(a - 1), exactly. */
static void test_border(void)
{
    const double as[3] = {1.2, 1.22, 1.23};
    for (int k = 0; k < 3; k++) {
        const cm_te t = setup_I0(as[k], 1.3, 0.25);
        CHECK(t.border && t.D0[0] == 0 && t.D0[1] == 0);
        const double want = as[k] / (as[k] - 1);
        CHECK(fabs(t.n_esc[0] - want) < 1e-9 * want);
        double exact;
        long partition;
        CHECK(cm_te_exact_mean(&t, 1000000, &exact, &partition));
        CHECK(fabs(exact - want) < 1e-9 * want);
    }
}

/* The exact mean against 10^6 midpoints' escape numbers and an ensemble
 * of 10^6 points; the ensemble's escape rate inside the dimension's bounds
 * (to 0.005) from a = 1.5 on, where Fig. 4.7 shows the estimates close. */
static void test_means(void)
{
    const double as[4] = {1.3, 1.5, 1.8, 2.1};
    for (int k = 0; k < 4; k++) {
        const cm_te t = setup_I0(as[k], 1.3, 0.25);
        double exact;
        long partition;
        CHECK(cm_te_exact_mean(&t, 1000000, &exact, &partition));
        CHECK(partition >= 2);
        const double grid = cm_te_grid_mean(&t, 1000000);
        CHECK(fabs(grid - exact) < 2e-3 * exact);
        cm_te_ensemble e;
        cm_te_ensemble_run(&t, 1000000, 7, &e);
        CHECK(fabs(e.mean - exact) < 0.05); /* about 5 standard errors */
        CHECK(e.fit_to > e.fit_from + 10);
        if (as[k] >= 1.5)
            CHECK(e.kappa > t.kappa[0] - 0.005 && e.kappa < t.kappa[1] + 0.005);
    }
    /* the same numbers from the same seed */
    const cm_te t = setup_I0(1.5, 1.3, 0.25);
    cm_te_ensemble e1, e2;
    cm_te_ensemble_run(&t, 10000, 3, &e1);
    cm_te_ensemble_run(&t, 10000, 3, &e2);
    CHECK(e1.mean == e2.mean);
}

/* Escape numbers by hand: x below x0* has 0; a point of I_rep whose image
 * falls below x0* has 1; nearer the fixed point it takes longer; f maps
 * I_rep into itself. */
static void test_escape_numbers(void)
{
    const cm_te t = setup_I0(1.5, 1.3, 0.25);
    CHECK(cm_te_escape_number(&t, t.x0 - 1e-9, 10) == 0);
    CHECK(cm_te_escape_number(&t, 1.0, 10) == 1); /* f(1) = a - b - c < x0* */
    /* near the unstable fixed point: a distance d from it grows by a per
     * step, until the point leaves the first escape interval's reach */
    CHECK(cm_te_escape_number(&t, t.x0 + 1e-9, 200) > cm_te_escape_number(&t, t.x0 + 1e-3, 200));
    for (int i = 0; i <= 1000; i++) {
        const double x = t.x0 + t.rep_len * i / 1000.0, y = cm_te_map(&t, x);
        CHECK(y <= t.rep_hi + 1e-12);
    }
}

int main(void)
{
    test_identities();
    test_border();
    test_means();
    test_escape_numbers();
    CHECK_DONE();
}
